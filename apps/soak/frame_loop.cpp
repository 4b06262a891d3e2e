#include "frame_loop.hpp"
#include "stop_signals.hpp"

#include "commands.hpp"
#include "progress.hpp"

#include <soak/checkpoint.hpp>
#include <soak/error.hpp>
#include <soak/step.hpp>
#include <soak/threads.hpp>

#include <fmt/format.h>

#include <csignal>
#include <regex>
#include <ctime>

namespace soak::cli {

namespace {

namespace fs = std::filesystem;

nlohmann::ordered_json waterJson(const WaterMass& w, const State& s) {
  return {{"freeKg", w.free},
          {"heldInClothKg", w.heldInCloth},
          {"inBuffersKg", w.inBuffers},
          {"emittedKg", w.emitted},
          {"removedAtBoundsKg", w.removedAtBounds},
          {"particlesRemovedAtBounds", s.ledger.particlesRemovedAtBounds},
          {"takenByClothKg", w.takenByCloth},
          {"unaccountedKg", w.emitted - w.total}};
}

// writes DIR/checkpoint.soak and records it in run.json's "checkpoint"
void checkpoint(const fs::path& dir, const FrameLoop& loop, int frame, int stepsIntoFrame, const FrameStats& soFar,
                const State& state, RunRecord& record) {
  const CheckpointInfo info{kVersion, loop.sceneHash, frame, stepsIntoFrame, soFar};
  writeCheckpoint((dir / kCheckpointFile).string(), info, state);
  record.run["checkpoint"] = {{"file", kCheckpointFile},
                              {"frame", frame},
                              {"stepsIntoFrame", stepsIntoFrame},
                              {"time", state.time},
                              {"stateHash", fmt::format("{:016x}", stateHash(state))}};
}

// the interrupted loop's last words: a checkpoint after the step under way, run.json "interrupted"
int stopOnSignal(const fs::path& dir, const FrameLoop& loop, int frame, int stepsIntoFrame, const FrameStats& soFar,
                 const State& state, RunRecord& record) {
  const int sig = gStopSignal;
  checkpoint(dir, loop, frame - 1, stepsIntoFrame, soFar, state, record);
  record.run["signal"] = sig == SIGINT ? "SIGINT" : "SIGTERM";
  record.write("interrupted", frame, state);
  std::fprintf(stderr,
               "soak: %s: stopped at t = %.4f s (step %llu) after frame %d; checkpoint written to %s\n"
               "soak: continue with: soak resume %s\n",
               sig == SIGINT ? "SIGINT" : "SIGTERM", state.time, static_cast<unsigned long long>(state.stepCount),
               frame - 1, (dir / kCheckpointFile).c_str(), dir.c_str());
  return 128 + sig;
}

void reportDivergence(const fs::path& dir, int frame, const State& state, const std::string& bad) {
  std::fprintf(stderr,
               "soak: simulation diverged at frame %d (t = %.4f s, step %llu): %s\n"
               "soak: frame %d was written to %s and marked \"error\" in stats.jsonl; the last good frame is %d\n",
               frame, state.time, static_cast<unsigned long long>(state.stepCount), bad.c_str(), frame, dir.c_str(),
               frame - 1);
}

std::string outputList(const Model& model, const OutputSettings& out) {
  std::string s;
  if (model.numCloth > 0 && out.clothObj) s += "cloth_NNNN.obj, ";
  if (model.numCloth > 0 && out.clothPly) s += "cloth_NNNN.ply, ";
  if (out.water) s += "water_NNNN.ply, ";
  return s + "stats.jsonl";
}

}  // namespace

bool isSoakOutput(const std::string& name) {
  static const std::regex soakFile(R"(((cloth|water)_\d{4,}\.(obj|ply))|stats\.jsonl|scene\.json|run\.json|checkpoint\.soak)");
  static const std::regex partFile(R"(.*\.part)");
  return std::regex_match(name, soakFile) || (std::regex_match(name, partFile) && isSoakOutput(name.substr(0, name.size() - 5)));
}

void printRunSummary(const Scene& scene, const std::string& outDir, int firstFrame, int lastFrame, const FrameLoopResult& r) {
  const Model& model = scene.model;
  const State& state = scene.state;
  const float dt = model.solver.dt;
  const WaterMass w = waterMass(state);
  std::printf("soak: wrote frames %d..%d of %s to %s (%s, scene.json, run.json)\n", firstFrame, lastFrame,
              scene.name.c_str(), outDir.c_str(), outputList(model, scene.output).c_str());
  std::printf("soak: %llu steps of %g s in %s (%.2f ms/step) on %d threads\n", static_cast<unsigned long long>(r.steps),
              static_cast<double>(dt), Progress::formatDuration(r.simSeconds).c_str(),
              r.steps > 0 ? 1e3 * r.simSeconds / static_cast<double>(r.steps) : 0.0, threadCount());
  if (model.wetting.enabled && r.steps > 0) {
    // Table 2 of Shao 2017 gives the wetting's time apart from the step's: the same split, stage by stage
    const double steps = static_cast<double>(r.steps);
    std::string parts;
    for (int k = static_cast<int>(StagePart::wettingPorosity); k <= static_cast<int>(StagePart::wettingFinish); ++k) {
      const std::string name = kStagePartNames[k];  // "wetting.porosity": the stage's name after the dot
      parts += fmt::format("{}{} {:.2f}", parts.empty() ? "" : ", ", name.substr(name.find('.') + 1), r.ms.parts[k] / steps);
    }
    std::printf("soak: solver %.2f ms a step (frames not written), of which wetting %.2f (%s)\n", r.ms.total / steps,
                r.ms.wetting / steps, parts.c_str());
  }
  if (model.hasImplicitCloth() && r.garment.solves > 0) {
    const GarmentStats& g = r.garment;
    std::printf("soak: garments: %llu implicit steps, %.1f CG iterations a step, %llu stopped at the iteration cap, "
                "%llu redone in shorter steps (a vertex past solver.maxSpeed)\n",
                static_cast<unsigned long long>(g.solves), static_cast<double>(g.cgIterations) / g.solves,
                static_cast<unsigned long long>(g.unconverged), static_cast<unsigned long long>(g.halvedSteps));
  }
  std::printf("soak: water: emitted %.6g kg = free %.6g kg + held by the cloth %.6g kg + in buffers %.6g kg + "
              "removed at bounds %.6g kg (%llu particles) + taken in by garments %.6g kg; unaccounted %.3g kg\n",
              w.emitted, w.free, w.heldInCloth, w.inBuffers, w.removedAtBounds,
              static_cast<unsigned long long>(state.ledger.particlesRemovedAtBounds), w.takenByCloth,
              w.emitted - w.total);
}

std::string isoTimeNow() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return buf;
}

double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

void RunRecord::write(const std::string& status, int framesWritten, const State& state) {
  run["status"] = status;
  run["framesWritten"] = framesWritten;
  run["wallSeconds"] = earlierWallSeconds + secondsSince(wallStart);
  run["steps"] = state.stepCount;
  run["simulatedSeconds"] = state.time;
  run["stateHash"] = fmt::format("{:016x}", stateHash(state));
  run["water"] = waterJson(waterMass(state), state);
  writeTextFile(path, run.dump(2) + "\n");
}

FrameLoopResult simulateFrames(Scene& scene, const FrameLoop& loop, const fs::path& dir, JsonLinesWriter& stats,
                               RunRecord& record) {
  const Model& model = scene.model;
  State& state = scene.state;
  const int stepsPerFrame = std::max(1, scene.output.stepsPerFrame);
  WorkspacePtr ws = makeWorkspace();
  Progress progress(loop.lastFrame, !loop.quiet, std::max(0, loop.firstFrame - 1));
  const StopSignals signals;
  const Clock::time_point simStart = Clock::now();
  FrameLoopResult result;
  try {
    for (int frame = loop.firstFrame; frame <= loop.lastFrame; ++frame) {
      const bool resumed = frame == loop.firstFrame && loop.stepsDone > 0;
      FrameStats fs = resumed ? loop.frameSoFar : FrameStats{};
      for (int s = resumed ? loop.stepsDone : 0; frame > 0 && s < stepsPerFrame; ++s) {
        if (gStopSignal != 0) {
          progress.finish();
          result.exitCode = stopOnSignal(dir, loop, frame, s, fs, state, record);
          return result;
        }
        StepStats st;
        step(model, state, *ws, model.solver.dt, st);
        fs.add(st);
        result.ms += st.ms;
        result.garment += st.garment;
        ++result.steps;
      }
      const std::string bad = checkState(model, state);
      writeFrame(dir.string(), model, state, scene.output, frame);  // a diverged frame too: it shows where the blow-up started
      nlohmann::ordered_json line = frameStatsJson(model, state, frame, fs);
      if (!bad.empty()) line["error"] = bad;
      stats.write(line);
      if (!bad.empty()) {
        progress.finish();
        record.write("diverged", frame + 1, state);
        reportDivergence(dir, frame, state, bad);
        if (fs.garment.halvedSteps > 0)
          std::fprintf(stderr, "soak: the frame's implicit garment steps were redone in shorter steps %llu times first "
                               "(docs/garment.md, departure 4)\n",
                       static_cast<unsigned long long>(fs.garment.halvedSteps));
        result.exitCode = kExitDiverged;
        return result;
      }
      const bool last = frame == loop.lastFrame;
      if (loop.checkpointEvery > 0 && frame > 0 && (frame % loop.checkpointEvery == 0 || last))
        checkpoint(dir, loop, frame, 0, FrameStats{}, state, record);
      if (!last) record.write("running", frame + 1, state);
      if (frame > 0) progress.update(frame, state.time, fs.ms.total / std::max(1, fs.steps));
    }
  } catch (const Error&) {
    progress.finish();
    record.write("error", static_cast<int>(record.run.value("framesWritten", 0)), state);
    throw;
  }
  progress.finish();
  record.write("ok", loop.lastFrame + 1, state);
  result.simSeconds = secondsSince(simStart);
  return result;
}

}  // namespace soak::cli
