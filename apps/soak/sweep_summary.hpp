// soak sweep's summary: DIR/summary.json and DIR/summary.csv, one row per variant (docs/sweeps.md)
#pragma once
#include <soak/sweep.hpp>

#include <string>

namespace soak::cli {

// the line a variant's log gets before each resume: its error is what follows the last one
inline constexpr const char* kResumeMark = "--- soak sweep: resumed from the checkpoint ---";

struct SweepTotals {
  int complete = 0, failed = 0, interrupted = 0, pending = 0;  // pending: not started, or running
};

// measures every variant's folder (summarizeRun) and writes the two tables atomically; prints the
// counts unless quiet
SweepTotals writeSweepSummary(const SweepSpec& spec, const std::string& dir, bool quiet);

}  // namespace soak::cli
