#include "simulation.hpp"

#include <algorithm>
#include <filesystem>
#include <utility>

namespace soak::python {

namespace fs = std::filesystem;

Simulation::Simulation(Scene scene, std::string sceneText)
    : scene_(std::move(scene)),
      sceneText_(std::move(sceneText)),
      ws_(makeWorkspace()),
      colliderKeys_(scene_.model.colliders.size()) {}

void Simulation::step(int steps) {
  const float dt = scene_.model.solver.dt;
  for (int s = 0; s < steps; ++s) {
    StepStats stats;
    soak::step(scene_.model, scene_.state, *ws_, dt, stats, colliderKeys_);
    pending_.add(stats);
    // a scripted move spans one step: afterwards the collider stays where it went
    for (std::vector<Keyframe>& keys : colliderKeys_)
      if (keys.size() > 1) keys = {keys.back()};
  }
}

void Simulation::movePinned(std::span<const int64_t> indices, std::span<const Vec3> positions) {
  if (indices.size() != positions.size())
    throw Error("move_pinned: " + std::to_string(indices.size()) + " indices but " +
                std::to_string(positions.size()) + " positions");
  const Model& m = scene_.model;
  for (int64_t i : indices)  // all checked before any is moved
    if (i < 0 || i >= m.numCloth || !m.clothPinned[static_cast<size_t>(i)])
      throw Error("move_pinned: particle " + std::to_string(i) + " is not a pinned cloth particle (the scene's " +
                  "\"pin\" entries make them; cloth particles are 0.." + std::to_string(m.numCloth - 1) + ")");
  Particles& p = scene_.state.particles;
  for (size_t k = 0; k < indices.size(); ++k) {
    const size_t i = static_cast<size_t>(indices[k]);
    p.x[i] = positions[k];
    p.xPred[i] = positions[k];
  }
}

void Simulation::checkCollider(int c) const {
  if (c < 0 || c >= static_cast<int>(scene_.model.colliders.size()))
    throw Error("collider " + std::to_string(c) + " does not exist (the scene has " +
                std::to_string(scene_.model.colliders.size()) + ")");
}

int Simulation::colliderIndex(const std::string& name) const {
  std::string names;
  for (size_t c = 0; c < scene_.model.colliders.size(); ++c) {
    if (scene_.model.colliders[c].name == name) return static_cast<int>(c);
    names += (names.empty() ? "\"" : ", \"") + scene_.model.colliders[c].name + "\"";
  }
  throw Error("no collider is called \"" + name + "\" (the scene has " + (names.empty() ? "none" : names) + ")");
}

Keyframe Simulation::colliderPose(int c) const {
  checkCollider(c);
  const std::vector<Keyframe>& own = scene_.model.colliders[static_cast<size_t>(c)].keys;
  const std::vector<Keyframe>& scripted = colliderKeys_[static_cast<size_t>(c)];
  return poseAt(scripted.empty() ? own : scripted, scene_.state.time);
}

void Simulation::setColliderPose(int c, const Vec3& translation, const Quat& rotation) {
  const Keyframe from = colliderPose(c);
  const Keyframe to{from.time + scene_.model.solver.dt, translation, rotation.normalized()};
  colliderKeys_[static_cast<size_t>(c)] = {from, to};
}

nlohmann::ordered_json Simulation::writeFrame(const std::string& dir, int frame) {
  soak::writeFrame(dir, scene_.model, scene_.state, scene_.output, frame);
  nlohmann::ordered_json line = frameStatsJson(scene_.model, scene_.state, frame, pending_);
  pending_ = FrameStats{};
  return line;
}

namespace {

// a new or empty directory, or with overwrite any existing one
void prepareDir(const std::string& dir, bool overwrite) {
  std::error_code ec;
  if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec)) throw Error(dir + ": output path exists and is not a directory");
    if (!overwrite && !fs::is_empty(dir, ec))
      throw Error(dir + ": output directory is not empty; pass overwrite=True to write over soak's files in it, "
                        "or choose another directory");
    return;
  }
  fs::create_directories(dir, ec);
  if (ec) throw Error(dir + ": cannot create the output directory: " + ec.message());
}

}  // namespace

nlohmann::ordered_json Simulation::run(const std::string& dir, int frames, bool overwrite,
                                       const std::function<bool(int, int)>& progress) {
  prepareDir(dir, overwrite);
  writeTextFile((fs::path(dir) / "scene.json").string(), sceneText_);
  JsonLinesWriter stats((fs::path(dir) / "stats.jsonl").string());
  const int stepsPerFrame = std::max(1, scene_.output.stepsPerFrame);
  pending_ = FrameStats{};  // frame 0 is the state now, after no step of this run
  nlohmann::ordered_json line;
  for (int frame = 0; frame <= frames; ++frame) {
    if (frame > 0) step(stepsPerFrame);
    const std::string bad = checkState(scene_.model, scene_.state);
    line = writeFrame(dir, frame);  // a diverged frame too: it shows where the blow-up started
    if (!bad.empty()) line["error"] = bad;
    stats.write(line);
    if (!bad.empty())
      throw DivergedError(dir + ": the simulation diverged at frame " + std::to_string(frame) + " (t = " +
                          std::to_string(scene_.state.time) + " s): " + bad + "; the frame was written and marked " +
                          "\"error\" in stats.jsonl");
    if (progress && !progress(frame, frames)) break;
  }
  return line;
}

}  // namespace soak::python
