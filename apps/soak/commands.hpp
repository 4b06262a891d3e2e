// the subcommands of the soak program; each returns the process exit code
#pragma once
#include <soak/body_export.hpp>
#include <soak/render.hpp>

#include <string>
#include <vector>

namespace CLI {
class App;
class Option;
}

namespace soak::cli {

inline constexpr const char* kVersion = SOAK_VERSION;  // project(soak VERSION ...) in CMakeLists.txt

// exit codes: 0 success, 1 bad input or I/O error (nothing or little was done), 2 the simulation
// diverged (checkState failed; the bad frame was written), 128 + the signal when SIGINT or SIGTERM
// stopped a run (a checkpoint was written)
inline constexpr int kExitOk = 0;
inline constexpr int kExitError = 1;
inline constexpr int kExitDiverged = 2;

struct RunOptions {
  std::string scene;
  std::string outDir;
  int frames = -1;                     // -1: the scene's output.frames
  int threads = 0;                     // 0: OpenMP default
  std::vector<std::string> overrides;  // --set key=value
  int checkpointEvery = 0;             // frames between checkpoints; 0: only on SIGINT / SIGTERM
  bool overwrite = false;
  bool quiet = false;
  std::vector<std::string> commandLine;
};

struct ResumeOptions {
  std::string dir;                     // a run's output folder
  int frames = -1;                     // -1: run.json's frames (a larger value extends the run)
  int threads = 0;
  int checkpointEvery = -1;            // -1: run.json's checkpointEvery
  bool quiet = false;
  std::vector<std::string> commandLine;
};

struct ValidateOptions {
  std::string scene;
  std::vector<std::string> overrides;
};

struct BenchOptions {
  std::vector<std::string> scenes;     // files or manifest names; empty: every manifest entry
  int steps = -1;                      // -1: the manifest's, else 20
  int warmup = -1;                     // -1: the manifest's, else 5
  int threads = 0;
  std::string json;                    // write results here as JSON
  std::string manifest;                // empty: bench/benchmarks.json of the source tree
  std::vector<std::string> overrides;  // --set, applied to every scene
  bool inProcess = false;              // run the scenes in this process (no re-exec per scene)
  bool wholeRun = false;               // time every step of the scene's own duration, no warm-up
  bool stages = false;                 // also print the stages' parts (StagePart) per scene
  bool quiet = false;
};

// `soak sweep` (apps/soak/sweep.cpp, docs/sweeps.md)
struct SweepOptions {
  std::string sweep;    // SWEEP.json
  std::string outDir;   // the sweep's folder: DIR/vNNN per variant, DIR/summary.{csv,json}
  int jobs = 1;         // variants at a time
  int threads = 0;      // threads for the whole sweep, shared out (0: all cores)
  int frames = -1;      // -1: the sweep's "frames", else the scene's
  int only = -1;        // run only this variant (a Slurm array task); -1: every one
  bool collect = false; // run nothing: measure the folders and write the summary
  bool dryRun = false;  // list the variants and stop; with slurm: write the script, submit nothing
  bool sheet = true;    // draw the contact sheet after the summary
  bool quiet = false;
  // --slurm: an sbatch job array, one task per variant to run, instead of running here
  bool slurm = false;
  std::string partition;  // empty: the cluster's default
  std::string time;       // a task's time limit in sbatch's format; empty: the partition's
  int cpusPerTask = 1;    // each task's CPUs (its soak run threads)
  bool wait = false;      // wait for the job array, then write the summary (as --collect would)
};

int runCommand(const RunOptions& o);
int sweepCommand(const SweepOptions& o);
int resumeCommand(const ResumeOptions& o);
int validateCommand(const ValidateOptions& o);
int benchCommand(const BenchOptions& o);

// `soak render` and `soak surface` (apps/soak/render.cpp, docs/rendering.md): each adds its
// subcommand and options to the parser
struct RenderCliOptions {
  RenderOptions options;
  bool surface = false, particles = false;  // water style flags
  std::string camera, lookAt;               // "X,Y,Z"
  // the camera options given on the command line (they win over the scene's "view")
  CLI::Option *fovOpt = nullptr, *azimuthOpt = nullptr, *elevationOpt = nullptr, *zoomOpt = nullptr;
  bool quiet = false;
};
// `soak export-body` (apps/soak/render.cpp): the scene's mannequin as an OBJ sequence
struct ExportBodyCliOptions {
  BodyExportOptions options;
  bool quiet = false;
};
CLI::App* addExportBodyCommand(CLI::App& app, ExportBodyCliOptions& o);
int exportBodyCommand(const ExportBodyCliOptions& o);

struct SurfaceCliOptions {
  SurfaceOptions options;
  bool quiet = false;
};
CLI::App* addRenderCommand(CLI::App& app, RenderCliOptions& o);
CLI::App* addSurfaceCommand(CLI::App& app, SurfaceCliOptions& o);
int renderCommand(RenderCliOptions& o);
int surfaceCommand(SurfaceCliOptions& o);

// "a b 'c d'": argv joined with shell quoting where needed
std::string joinCommandLine(const std::vector<std::string>& args);

}  // namespace soak::cli
