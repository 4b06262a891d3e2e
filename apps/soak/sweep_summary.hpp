// soak sweep's summary: DIR/summary.json and DIR/summary.csv, one row per variant (docs/sweeps.md)
#pragma once
#include <soak/run_summary.hpp>
#include <soak/sweep.hpp>

#include <string>

namespace soak::cli {

// the line a variant's log gets before each resume: its error is what follows the last one
inline constexpr const char* kResumeMark = "--- soak sweep: resumed from the checkpoint ---";

// a variant's run is complete: run.json says ok, with the frames the sweep asks for (frames < 0: the
// scene's own, whatever run.json counts)
bool runComplete(const RunSummary& s, int frames);

struct SweepTotals {
  int complete = 0, failed = 0, interrupted = 0, pending = 0;  // pending: not started, or running
};

// measures every variant's folder (summarizeRun) and writes the two tables atomically; prints the
// counts unless quiet
SweepTotals writeSweepSummary(const SweepSpec& spec, const std::string& dir, bool quiet);

// DIR/contact_sheet.png: each complete variant's spec.sheet.frame drawn by soak render (all with the
// camera the first one chose), its folder and values under it; variants not complete get a blank
// tile saying why. Returns the file's path; throws soak::Error (a missing povray or ffmpeg, ...)
std::string writeSweepSheet(const SweepSpec& spec, const std::string& dir, bool quiet);

}  // namespace soak::cli
