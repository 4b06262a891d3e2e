// `soak run` and `soak validate`: load a scene, simulate it frame by frame and write the frames
#include "commands.hpp"

#include <soak/error.hpp>
#include <soak/output.hpp>
#include <soak/scene.hpp>
#include <soak/step.hpp>
#include <soak/threads.hpp>

#include "progress.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <ctime>
#include <filesystem>
#include <regex>

namespace soak::cli {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

std::string isoTimeNow() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return buf;
}

double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// the files a run writes; --overwrite removes only these, never anything else in the directory
bool isSoakOutput(const std::string& name) {
  static const std::regex frameFile(R"((cloth|water)_\d{4,}\.(obj|ply))");
  return name == "stats.jsonl" || name == "scene.json" || name == "run.json" || std::regex_match(name, frameFile);
}

void prepareOutputDir(const std::string& dir, bool overwrite) {
  std::error_code ec;
  if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec)) throw Error(dir + ": output path exists and is not a directory");
    if (!fs::is_empty(dir, ec)) {
      if (!overwrite)
        throw Error(dir + ": output directory is not empty; pass --overwrite to replace soak's files in it, or "
                          "choose another directory");
      for (const auto& entry : fs::directory_iterator(dir))
        if (entry.is_regular_file() && isSoakOutput(entry.path().filename().string())) fs::remove(entry.path());
    }
    return;
  }
  fs::create_directories(dir, ec);
  if (ec) throw Error(dir + ": cannot create the output directory: " + ec.message());
}

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

std::string outputList(const Model& model, const OutputSettings& out) {
  std::string s;
  if (model.numCloth > 0 && out.clothObj) s += "cloth_NNNN.obj, ";
  if (model.numCloth > 0 && out.clothPly) s += "cloth_NNNN.ply, ";
  if (out.water) s += "water_NNNN.ply, ";
  return s + "stats.jsonl";
}

// run.json: the run's settings, rewritten with its status, the frames written so far, the times, the
// state's hash and the water's ledger
struct RunRecord {
  nlohmann::ordered_json run;
  std::string path;
  Clock::time_point wallStart;

  void write(const std::string& status, int framesWritten, const State& state) {
    run["status"] = status;
    run["framesWritten"] = framesWritten;
    run["wallSeconds"] = secondsSince(wallStart);
    run["steps"] = state.stepCount;
    run["simulatedSeconds"] = state.time;
    run["stateHash"] = fmt::format("{:016x}", stateHash(state));
    run["water"] = waterJson(waterMass(state), state);
    writeTextFile(path, run.dump(2) + "\n");
  }
};

// how the frame loop ended, for the summary
struct FrameLoopResult {
  int exitCode = kExitOk;
  StageTimes ms;            // summed over the run, for the summary's wetting line
  double simSeconds = 0.0;  // wall time from the first step to the last frame written
};

// frames 0 (the initial state) to `frames`, each written with its line of stats.jsonl; stops at the
// first diverged frame (written too, marked "error"). run.json follows the status
FrameLoopResult simulateFrames(Scene& scene, const RunOptions& o, const fs::path& dir, int frames, RunRecord& record) {
  const Model& model = scene.model;
  State& state = scene.state;
  const OutputSettings& out = scene.output;
  const int stepsPerFrame = std::max(1, out.stepsPerFrame);
  const float dt = model.solver.dt;
  JsonLinesWriter stats((dir / "stats.jsonl").string());
  WorkspacePtr ws = makeWorkspace();
  Progress progress(frames, !o.quiet);
  const Clock::time_point simStart = Clock::now();
  int written = 0;
  FrameLoopResult result;
  try {
    for (int frame = 0; frame <= frames; ++frame) {
      FrameStats fs;
      for (int s = 0; frame > 0 && s < stepsPerFrame; ++s) {
        StepStats st;
        step(model, state, *ws, dt, st);
        fs.add(st);
      }
      result.ms += fs.ms;
      const std::string bad = checkState(model, state);
      writeFrame(dir.string(), model, state, out, frame);  // a diverged frame too: it shows where the blow-up started
      nlohmann::ordered_json line = frameStatsJson(model, state, frame, fs);
      if (!bad.empty()) line["error"] = bad;
      stats.write(line);
      ++written;
      if (!bad.empty()) {
        progress.finish();
        record.write("diverged", written, state);
        std::fprintf(stderr,
                     "soak: simulation diverged at frame %d (t = %.4f s, step %llu): %s\n"
                     "soak: frame %d was written to %s and marked \"error\" in stats.jsonl; the last good frame is "
                     "%d\n",
                     frame, state.time, static_cast<unsigned long long>(state.stepCount), bad.c_str(), frame,
                     o.outDir.c_str(), frame - 1);
        result.exitCode = kExitDiverged;
        return result;
      }
      if (frame > 0) progress.update(frame, state.time, fs.ms.total / std::max(1, fs.steps));
    }
  } catch (const Error&) {
    progress.finish();
    record.write("error", written, state);
    throw;
  }
  progress.finish();
  record.write("ok", written, state);
  result.simSeconds = secondsSince(simStart);
  return result;
}

// the summary on stdout: what was written, the steps' time (the wetting's stages apart, as Table 2 of
// Shao 2017) and where the emitted water went
void printRunSummary(const Scene& scene, const RunOptions& o, int frames, const FrameLoopResult& r) {
  const Model& model = scene.model;
  const State& state = scene.state;
  const float dt = model.solver.dt;
  const WaterMass w = waterMass(state);
  std::printf("soak: wrote frames 0..%d of %s to %s (%s, scene.json, run.json)\n", frames, scene.name.c_str(),
              o.outDir.c_str(), outputList(model, scene.output).c_str());
  std::printf("soak: %llu steps of %g s in %s (%.2f ms/step) on %d threads\n",
              static_cast<unsigned long long>(state.stepCount), static_cast<double>(dt),
              Progress::formatDuration(r.simSeconds).c_str(),
              state.stepCount > 0 ? 1e3 * r.simSeconds / static_cast<double>(state.stepCount) : 0.0, threadCount());
  if (model.wetting.enabled && state.stepCount > 0) {
    // Table 2 of Shao 2017 gives the wetting's time apart from the step's: the same split, stage by stage
    const double steps = static_cast<double>(state.stepCount);
    std::string parts;
    for (int k = static_cast<int>(StagePart::wettingPorosity); k <= static_cast<int>(StagePart::wettingFinish); ++k) {
      const std::string name = kStagePartNames[k];  // "wetting.porosity": the stage's name after the dot
      parts += fmt::format("{}{} {:.2f}", parts.empty() ? "" : ", ", name.substr(name.find('.') + 1), r.ms.parts[k] / steps);
    }
    std::printf("soak: solver %.2f ms a step (frames not written), of which wetting %.2f (%s)\n", r.ms.total / steps,
                r.ms.wetting / steps, parts.c_str());
  }
  std::printf("soak: water: emitted %.6g kg = free %.6g kg + held by the cloth %.6g kg + in buffers %.6g kg + "
              "removed at bounds %.6g kg (%llu particles) + taken in by garments %.6g kg; unaccounted %.3g kg\n",
              w.emitted, w.free, w.heldInCloth, w.inBuffers, w.removedAtBounds,
              static_cast<unsigned long long>(state.ledger.particlesRemovedAtBounds), w.takenByCloth,
              w.emitted - w.total);
}

}  // namespace

std::string joinCommandLine(const std::vector<std::string>& args) {
  std::string s;
  for (const std::string& a : args) {
    if (!s.empty()) s += ' ';
    const bool plain = !a.empty() && a.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                                         "0123456789-_./=:,+@%") == std::string::npos;
    if (plain) {
      s += a;
      continue;
    }
    s += '\'';
    for (char c : a) s += c == '\'' ? std::string("'\\''") : std::string(1, c);
    s += '\'';
  }
  return s;
}

int runCommand(const RunOptions& o) {
  const Clock::time_point wallStart = Clock::now();
  const std::string startTime = isoTimeNow();
  // everything that can be wrong with the input fails here, before any output exists
  Scene scene = loadScene(o.scene, o.overrides);
  if (o.threads > 0) setThreadCount(o.threads);
  if (!o.quiet) std::fputs(busyMachineHint(threadCount()).c_str(), stderr);
  const int frames = o.frames >= 0 ? o.frames : scene.output.frames;
  const int stepsPerFrame = std::max(1, scene.output.stepsPerFrame);
  const float dt = scene.model.solver.dt;

  prepareOutputDir(o.outDir, o.overwrite);
  const fs::path dir(o.outDir);
  writeTextFile((dir / "scene.json").string(), sceneAsRun(o.scene, o.overrides));
  nlohmann::ordered_json run = {{"soak", kVersion},
                        {"threads", threadCount()},
                        {"commandLine", joinCommandLine(o.commandLine)},
                        {"scene", fs::absolute(o.scene).lexically_normal().string()},
                        {"overrides", o.overrides},
                        {"frames", frames},
                        {"stepsPerFrame", stepsPerFrame},
                        {"dt", std::stod(fmt::format("{}", dt))},
                        {"startTime", startTime},
                        {"status", "running"}};
  RunRecord record{std::move(run), (dir / "run.json").string(), wallStart};
  record.write("running", 0, scene.state);

  const FrameLoopResult result = simulateFrames(scene, o, dir, frames, record);
  if (result.exitCode != kExitOk) return result.exitCode;
  if (!o.quiet) printRunSummary(scene, o, frames, result);
  return kExitOk;
}

namespace {

std::string fmtPoint(const Vec3& v) { return fmt::format("[{:g}, {:g}, {:g}]", v.x(), v.y(), v.z()); }

// one emitter by its kind: "block of [..] to [..] m at t = 0 s", "jet of radius ...", "rain of ..."
std::string emitterSummary(const Emitter& e) {
  const auto span = [&] {
    return e.end < 1e29f ? fmt::format("t = {:g}..{:g} s", e.start, e.end) : fmt::format("from t = {:g} s", e.start);
  };
  switch (e.kind) {
    case EmitterKind::Block:
      return fmt::format("block of {} to {} m at t = {:g} s", fmtPoint(e.boxMin), fmtPoint(e.boxMax), e.start);
    case EmitterKind::Jet:
      return fmt::format("jet of radius {:g} m at {:g} m/s, {}", e.radius, e.speed, span());
    case EmitterKind::Rain:
      return fmt::format("rain of {:g} drops/(s m^2) over {:g} x {:g} m at {:g} m/s, {}", e.rate,
                         2.0f * e.halfExtents.x(), 2.0f * e.halfExtents.z(), e.dropSpeed, span());
  }
  return "emitter";
}

}  // namespace

int validateCommand(const ValidateOptions& o) {
  const Scene scene = loadScene(o.scene, o.overrides);
  const Model& m = scene.model;
  const SolverParams& s = m.solver;
  size_t water = 0;
  for (int32_t ph : scene.state.particles.phase) water += isWater(ph) ? 1 : 0;
  size_t pinned = 0;
  for (uint8_t p : m.clothPinned) pinned += p;
  std::printf("%s: valid\n", o.scene.c_str());
  std::printf("  name:        %s\n", scene.name.c_str());
  std::printf("  particles:   %d cloth, %zu water at start, %zu water from blocks\n", m.numCloth, water,
              blockParticleCount(m));
  std::printf("  cloth:       %zu pieces, %zu triangles, %zu pinned particles\n", m.pieces.size(), m.triangles.size(),
              pinned);
  for (const ClothPiece& p : m.pieces)
    std::printf("    %-12s %d particles, %d triangles, %s solver%s\n", p.name.c_str(), p.particleCount, p.triangleCount,
                p.solver == ClothSolver::Implicit ? "implicit (Chen 2012)" : "PBD",
                p.garment.saturationMass ? ", saturation mass (Eq. 15-19)" : "");
  std::printf("  colliders:   %zu\n", m.colliders.size());
  for (const Collider& c : m.colliders) std::printf("    %s\n", c.name.c_str());
  std::printf("  emitters:    %zu\n", m.emitters.size());
  for (const Emitter& e : m.emitters) std::printf("    %-12s %s\n", e.name.c_str(), emitterSummary(e).c_str());
  std::printf("  dt:          %g s, %d substeps\n", static_cast<double>(s.dt), s.substeps);
  const std::string upTo = s.fluidMaxIterations > s.fluidIterations
                               ? fmt::format(" (up to {} to a {:g} mean compression)", s.fluidMaxIterations, s.fluidTolerance)
                               : std::string();
  std::printf("  iterations:  fluid %d%s, cloth %d, coupling %d\n", s.fluidIterations, upTo.c_str(), s.clothIterations,
              s.couplingIterations);
  if (m.wetting.enabled)
    std::printf("  wetting:     Shao 2017, %s\n", m.wetting.everySubstep ? "after every substep" : "once a step (Algorithm 1)");
  std::printf("  output:      %d frames of %d steps (%g s simulated)\n", scene.output.frames,
              scene.output.stepsPerFrame,
              static_cast<double>(s.dt) * scene.output.stepsPerFrame * scene.output.frames);
  return kExitOk;
}

}  // namespace soak::cli
