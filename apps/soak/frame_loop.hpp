// the frame loop of `soak run` and `soak resume`: steps, frame files, stats lines, run.json after
// every frame, checkpoints, and a clean stop on SIGINT / SIGTERM
#pragma once
#include <soak/output.hpp>
#include <soak/scene.hpp>
#include <soak/stats.hpp>

#include <nlohmann/json.hpp>

#include <chrono>
#include <filesystem>
#include <string>

namespace soak::cli {

using Clock = std::chrono::steady_clock;

inline constexpr const char* kCheckpointFile = "checkpoint.soak";

std::string isoTimeNow();
double secondsSince(Clock::time_point t);

// run.json: the run's settings, rewritten after every frame with its status, the frames written so
// far, the times, the state's hash, the water's ledger and the last checkpoint. Written atomically.
struct RunRecord {
  nlohmann::ordered_json run;
  std::string path;
  Clock::time_point wallStart;
  double earlierWallSeconds = 0.0;  // wall time of the run's earlier processes (before a resume)

  void write(const std::string& status, int framesWritten, const State& state);
};

struct FrameLoop {
  int firstFrame = 0;      // the frame the loop completes first (0: a new run, which writes frame 0 as it is)
  int lastFrame = 0;       // the last frame it writes
  int stepsDone = 0;       // steps of firstFrame already taken (a run resumed inside a frame)
  FrameStats frameSoFar;   // their statistics
  int checkpointEvery = 0; // frames between checkpoints; 0: only when interrupted
  uint64_t sceneHash = 0;  // textHash of the run folder's scene.json, kept in each checkpoint
  bool quiet = false;
};

// how the frame loop ended, for the summary
struct FrameLoopResult {
  int exitCode = 0;
  StageTimes ms;            // summed over this loop, for the summary's wetting line
  double simSeconds = 0.0;  // wall time from the first step to the last frame written
  uint64_t steps = 0;       // steps this loop took
  GarmentStats garment;     // the implicit garments' statistics summed over this loop, for the summary
};

// a file `soak run` writes into its folder (frames, stats.jsonl, scene.json, run.json,
// checkpoint.soak, and their .part temporaries): --overwrite removes only these
bool isSoakOutput(const std::string& name);

// the summary on stdout: the frames written, the steps' time (the wetting's stages apart, as Table 2
// of Shao 2017) and where the emitted water went
void printRunSummary(const Scene& scene, const std::string& outDir, int firstFrame, int lastFrame,
                     const FrameLoopResult& r);

// frames loop.firstFrame..loop.lastFrame, each written with its line of stats.jsonl (stats) and
// run.json (record). Stops at the first diverged frame (written too, marked "error": exit 2) and,
// on SIGINT or SIGTERM, after the step under way, with a checkpoint and run.json's status
// "interrupted" (exit 128 + the signal). A checkpoint (DIR/checkpoint.soak) is also written every
// loop.checkpointEvery frames and after the last one.
FrameLoopResult simulateFrames(Scene& scene, const FrameLoop& loop, const std::filesystem::path& dir,
                               JsonLinesWriter& stats, RunRecord& record);

}  // namespace soak::cli
