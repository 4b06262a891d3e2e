// soak command-line program: run, validate and bench scenes, render and mesh their output (docs/cli.md)
#include "commands.hpp"
#include "sweep_slurm.hpp"

#include <soak/error.hpp>
#include <soak/sweep.hpp>
#include <soak/threads.hpp>

#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <string>

namespace {

using namespace soak::cli;

// "key=value" for --set: the key must be non-empty
std::string checkOverride(const std::string& s) {
  const size_t eq = s.find('=');
  if (eq == std::string::npos || eq == 0) return "expected key=value (e.g. solver.substeps=3), got '" + s + "'";
  return {};
}

// `soak run`'s arguments and options
CLI::App* addRunCommand(CLI::App& app, RunOptions& run) {
  CLI::App* runCmd = app.add_subcommand("run", "simulate a scene and write its frames");
  runCmd->add_option("scene", run.scene, "scene file (JSON)")->required();
  runCmd->add_option("-o,--out", run.outDir, "output directory (created; must be empty unless --overwrite)")
      ->required();
  runCmd->add_option("--frames", run.frames, "frames to write after frame 0 (default: the scene's output.frames)")
      ->check(CLI::NonNegativeNumber);
  runCmd->add_option("--threads", run.threads, "worker threads (default: all cores)")
      ->check(CLI::Range(1, soak::kMaxThreads));
  runCmd->add_option("--set", run.overrides, "override a scene value, key=value (repeatable)")
      ->check(checkOverride)
      ->allow_extra_args(false)
      ->take_all();
  runCmd->add_option("--checkpoint-every", run.checkpointEvery,
                     "write DIR/checkpoint.soak every N frames and after the last (SIGINT / SIGTERM always write one)")
      ->check(CLI::Range(1, 1000000));
  runCmd->add_flag("--overwrite", run.overwrite, "write into a non-empty output directory, replacing soak's files");
  runCmd->add_flag("-q,--quiet", run.quiet, "no progress and no summary");
  return runCmd;
}

// `soak resume`'s arguments and options
CLI::App* addResumeCommand(CLI::App& app, ResumeOptions& resume) {
  CLI::App* resumeCmd = app.add_subcommand("resume", "continue a run from its checkpoint (DIR/checkpoint.soak)");
  resumeCmd->add_option("dir", resume.dir, "the run's output directory")->required();
  resumeCmd->add_option("--frames", resume.frames, "last frame to write (default: run.json's frames; larger extends the run)")
      ->check(CLI::Range(1, 100000000));
  resumeCmd->add_option("--threads", resume.threads, "worker threads (default: all cores)")->check(CLI::Range(1, soak::kMaxThreads));
  resumeCmd->add_option("--checkpoint-every", resume.checkpointEvery, "frames between checkpoints (default: the run's)")
      ->check(CLI::Range(0, 1000000));
  resumeCmd->add_flag("-q,--quiet", resume.quiet, "no progress and no summary");
  return resumeCmd;
}

// `soak sweep`'s arguments and options
CLI::App* addSweepCommand(CLI::App& app, SweepOptions& sweep) {
  CLI::App* cmd = app.add_subcommand("sweep", "run every variant of a SWEEP.json (a wedge of scene values)");
  cmd->add_option("sweep", sweep.sweep, "sweep file (JSON: scene, set, frames, axes or variants)")->required();
  cmd->add_option("-o,--out", sweep.outDir, "the sweep's folder (DIR/vNNN per variant; reused to resume)")->required();
  cmd->add_option("-j,--jobs", sweep.jobs, "variants at a time (default 1)")->check(CLI::Range(1, soak::kMaxThreads));
  cmd->add_option("--threads", sweep.threads, "threads for the whole sweep, shared out among the jobs (default: all cores)")
      ->check(CLI::Range(1, soak::kMaxThreads));
  cmd->add_option("--frames", sweep.frames, "frames per variant (default: the sweep's frames, else the scene's)")
      ->check(CLI::Range(0, 100000000));
  CLI::Option* only = cmd->add_option("--only", sweep.only, "run only variant I (0-based; a Slurm array task)")
                          ->check(CLI::Range(0, soak::kMaxSweepVariants - 1));
  CLI::Option* collect = cmd->add_flag("--collect", sweep.collect,
                                       "run nothing: measure the variants' folders and write the summary")
                             ->excludes(only);
  cmd->add_flag("--dry-run", sweep.dryRun, "check the variants, list them and stop (with --slurm: write the script only)");
  cmd->add_flag("-q,--quiet", sweep.quiet, "no progress lines");
  cmd->add_flag("!--no-contact-sheet", sweep.sheet, "write the summary without drawing DIR/contact_sheet.png");
  CLI::Option* slurm = cmd->add_flag("--slurm", sweep.slurm,
                                     "submit a Slurm job array (sbatch), one task per variant still to run, instead "
                                     "of running here; DIR must be on a file system the nodes share")
                           ->excludes(only)
                           ->excludes(collect);
  const auto sbatchValue = [](const std::string& v) { return soak::cli::sbatchValueProblem(v); };
  cmd->add_option("--partition", sweep.partition, "with --slurm: the partition (default: the cluster's)")
      ->check(sbatchValue)
      ->needs(slurm);
  cmd->add_option("--time", sweep.time, "with --slurm: each task's time limit, as sbatch takes it (e.g. 2:00:00)")
      ->check(sbatchValue)
      ->needs(slurm);
  cmd->add_option("--cpus-per-task", sweep.cpusPerTask, "with --slurm: each task's CPUs, its threads (default 1)")
      ->check(CLI::Range(1, soak::kMaxThreads))
      ->needs(slurm);
  cmd->add_flag("--wait", sweep.wait, "with --slurm: wait until the job array is done, then write the summary")
      ->needs(slurm);
  return cmd;
}

int realMain(int argc, char** argv) {
  CLI::App app{"soak: cloth getting wet (position-based water and porous cloth)", "soak"};
  app.set_version_flag("--version", std::string("soak ") + kVersion);
  app.require_subcommand(1);
  app.failure_message(CLI::FailureMessage::help);

  RunOptions run;
  for (int i = 0; i < argc; ++i) run.commandLine.emplace_back(argv[i]);
  CLI::App* runCmd = addRunCommand(app, run);
  ResumeOptions resume;
  resume.commandLine = run.commandLine;
  CLI::App* resumeCmd = addResumeCommand(app, resume);

  ValidateOptions val;
  CLI::App* valCmd = app.add_subcommand("validate", "load and check a scene, print a summary");
  valCmd->add_option("scene", val.scene, "scene file (JSON)")->required();
  valCmd->add_option("--set", val.overrides, "override a scene value, key=value (repeatable)")
      ->check(checkOverride)
      ->allow_extra_args(false)
      ->take_all();

  BenchOptions bench;
  CLI::App* benchCmd = app.add_subcommand("bench", "time the solver stages on benchmark scenes");
  benchCmd->add_option("--scene", bench.scenes, "scene file or bench/benchmarks.json entry name (repeatable)")
      ->allow_extra_args(false)
      ->take_all();
  CLI::Option* stepsOpt = benchCmd->add_option("--steps", bench.steps, "timed steps per scene (default 20 or the manifest's)")
      ->check(CLI::PositiveNumber);
  CLI::Option* warmupOpt = benchCmd->add_option("--warmup", bench.warmup, "untimed steps first (default 5 or the manifest's)")
      ->check(CLI::NonNegativeNumber);
  benchCmd->add_flag("--whole-run", bench.wholeRun,
                     "time every step of each scene's own duration (output.frames x stepsPerFrame), no warm-up; "
                     "targets then compare the mean step, as Table 2 of Shao 2017 averages")
      ->excludes(stepsOpt)
      ->excludes(warmupOpt);
  benchCmd->add_option("--threads", bench.threads, "worker threads (default: all cores)")
      ->check(CLI::Range(1, soak::kMaxThreads));
  benchCmd->add_option("--json", bench.json, "also write the results to this JSON file");
  benchCmd->add_option("--manifest", bench.manifest, "benchmark list (default: bench/benchmarks.json)");
  benchCmd->add_option("--set", bench.overrides, "override a value in every scene, key=value (repeatable)")
      ->check(checkOverride)
      ->allow_extra_args(false)
      ->take_all();
  benchCmd->add_flag("--in-process", bench.inProcess,
                     "run every scene in this process (peak memory is then shared between scenes)");
  benchCmd->add_flag("--stages", bench.stages,
                     "also print the parts of the stages per scene: the wetting stages one by one, the neighbour "
                     "grid and lists, the cloth solve and self-collision, the coupling search and passes, XSPH");
  benchCmd->add_flag("-q,--quiet", bench.quiet, "print no table (with --json)");

  SweepOptions sweep;
  CLI::App* sweepCmd = addSweepCommand(app, sweep);

  RenderCliOptions render;
  CLI::App* renderCmd = addRenderCommand(app, render);
  SurfaceCliOptions surface;
  CLI::App* surfaceCmd = addSurfaceCommand(app, surface);
  ExportBodyCliOptions exportBodyOpts;
  CLI::App* exportBodyCmd = addExportBodyCommand(app, exportBodyOpts);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitError;
  }
  if (*runCmd) return runCommand(run);
  if (*resumeCmd) return resumeCommand(resume);
  if (*valCmd) return validateCommand(val);
  if (*renderCmd) return renderCommand(render);
  if (*surfaceCmd) return surfaceCommand(surface);
  if (*exportBodyCmd) return exportBodyCommand(exportBodyOpts);
  if (*sweepCmd) return sweepCommand(sweep);
  return benchCommand(bench);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return realMain(argc, argv);
  } catch (const soak::Error& e) {
    std::fprintf(stderr, "soak: error: %s\n", e.what());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "soak: error: %s\n", e.what());
  }
  return kExitError;
}
