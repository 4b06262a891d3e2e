// `soak run` and `soak validate`: load a scene, simulate it frame by frame and write the frames
#include "commands.hpp"

#include <soak/checkpoint.hpp>
#include <soak/error.hpp>
#include <soak/output.hpp>
#include <soak/scene.hpp>
#include <soak/step.hpp>
#include <soak/threads.hpp>

#include "frame_loop.hpp"
#include "progress.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>

namespace soak::cli {

namespace {

namespace fs = std::filesystem;

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
  const std::string sceneText = sceneAsRun(o.scene, o.overrides);
  writeTextFile((dir / "scene.json").string(), sceneText);
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
  if (o.checkpointEvery > 0) run["checkpointEvery"] = o.checkpointEvery;
  RunRecord record{std::move(run), (dir / "run.json").string(), wallStart};
  record.write("running", 0, scene.state);

  JsonLinesWriter stats((dir / "stats.jsonl").string());
  FrameLoop loop;
  loop.lastFrame = frames;
  loop.checkpointEvery = o.checkpointEvery;
  loop.sceneHash = textHash(sceneText);
  loop.quiet = o.quiet;
  const FrameLoopResult result = simulateFrames(scene, loop, dir, stats, record);
  if (result.exitCode != kExitOk) return result.exitCode;
  if (!o.quiet) printRunSummary(scene, o.outDir, 0, frames, result);
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
  for (const ClothPiece& p : m.pieces) {
    double mass = 0.0, area = 0.0;  // dry, on the rest mesh
    for (int i = p.firstParticle; i < p.firstParticle + p.particleCount; ++i) {
      mass += m.clothDryMass[size_t(i)];
      area += m.clothRestArea[size_t(i)];
    }
    std::printf("    %-12s %d particles, %d triangles, %s solver%s\n", p.name.c_str(), p.particleCount, p.triangleCount,
                p.solver == ClothSolver::Implicit ? "implicit (Chen 2012)" : "PBD",
                p.garment.saturationMass ? ", saturation mass (Eq. 15-19)" : "");
    std::printf("    %-12s %.4g m^2, %.4g kg dry (%.4g kg/m^2)\n", "", area, mass, area > 0.0 ? mass / area : 0.0);
  }
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
  const bool pbdCloth = std::any_of(m.pieces.begin(), m.pieces.end(),
                                    [](const ClothPiece& p) { return p.solver == ClothSolver::Pbd; });
  if (pbdCloth)  // the PBD cloth's convergence settings (docs/models.md, Eq. 8)
    std::printf("  PBD cloth:   %d small steps a substep, %d coarse levels, %d passes within %d edges of a pin%s\n",
                s.clothSubsteps, s.clothHierarchy, s.clothPinPasses, s.clothPinRings,
                s.clothGlobalStretch ? ", global stretch step" : "");
  if (m.wetting.enabled)
    std::printf("  wetting:     Shao 2017, %s\n", m.wetting.everySubstep ? "after every substep" : "once a step (Algorithm 1)");
  std::printf("  output:      %d frames of %d steps (%g s simulated)\n", scene.output.frames,
              scene.output.stepsPerFrame,
              static_cast<double>(s.dt) * scene.output.stepsPerFrame * scene.output.frames);
  return kExitOk;
}

}  // namespace soak::cli
