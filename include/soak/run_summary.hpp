// what one run's output folder measured, read back from its run.json, stats.jsonl and last frame
// (soak sweep's summary table; docs/sweeps.md). Part of soak_render, which reads run folders.
#pragma once
#include <limits>
#include <string>

namespace soak {

struct RunSummary {
  static constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  std::string status = "missing";  // run.json's: "ok", "running", "interrupted", "diverged", "error"; "missing": none
  int framesWritten = 0;           // run.json's count (frames 0 .. framesWritten - 1 are complete)
  int frame = -1;                  // the frame measured below: the last one written (-1: none)
  double msPerStep = kNone;        // wall ms per step, over every step in stats.jsonl
  double heldWaterKg = kNone;      // water held and buffered in the cloth at `frame` (its stats line)
  double wetAreaFraction = kNone;  // share of the cloth's rest area with S >= 0.1 S^MAX at `frame` (no wetting: none)
  double maxClothStrain = kNone;   // max over the cloth's triangle edges of length / rest length - 1 at `frame`
};

// reads DIR/run.json, DIR/stats.jsonl and the last complete frame's cloth file. A folder without
// run.json gives status "missing" and nothing measured; a damaged file throws soak::Error naming it.
RunSummary summarizeRun(const std::string& dir);

// only run.json's status and framesWritten (nothing measured): what a sweep needs to know whether a
// variant is complete, without loading its scene
RunSummary runStatus(const std::string& dir);

}  // namespace soak
