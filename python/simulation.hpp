// the Python module's simulation (module.cpp binds it): a scene with its workspace, stepped by a
// script that may move pinned particles and colliders between steps, and written as `soak run` writes
// a run. Built on the public API (include/soak/) only; knows nothing of Python.
#pragma once
#include <soak/error.hpp>
#include <soak/output.hpp>
#include <soak/scene.hpp>
#include <soak/step.hpp>

#include <nlohmann/json.hpp>

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

namespace soak::python {

// a run that stopped because the state diverged (checkState); the diverged frame was written
class DivergedError : public Error {
 public:
  using Error::Error;
};

class Simulation {
 public:
  // sceneText: the scene's JSON as run (sceneAsRun for a file), written to a run's scene.json
  Simulation(Scene scene, std::string sceneText);

  const Scene& scene() const { return scene_; }
  const Model& model() const { return scene_.model; }
  State& state() { return scene_.state; }

  // `steps` steps of solver.dt; their statistics add up for the next frame's stats line
  void step(int steps);

  // puts pinned cloth particles indices[k] at positions[k] (x and x*); they stay there until moved
  // again. Throws soak::Error when an index is not a pinned particle
  void movePinned(std::span<const int64_t> indices, std::span<const Vec3> positions);

  // the collider called `name`; throws soak::Error listing the colliders when there is none
  int colliderIndex(const std::string& name) const;
  // collider c's pose now (time: the state's)
  Keyframe colliderPose(int c) const;
  // collider c moves from where it is now to `translation` / `rotation` over the next step (with that
  // step's velocity, which friction and restitution see), then stays there until moved again
  void setColliderPose(int c, const Vec3& translation, const Quat& rotation);

  // writes the frame files of `frame` into dir (as `soak run`); returns its stats line, over the steps
  // since the last frame written
  nlohmann::ordered_json writeFrame(const std::string& dir, int frame);

  // frames 0 (the state now) to `frames`, stepsPerFrame steps apart, into dir as `soak run` writes
  // them: frame files, stats.jsonl, scene.json. dir must be empty or new unless overwrite (then
  // soak's files in it are overwritten, nothing is removed). progress(frame, frames) after each frame
  // written; returning false stops the run there. Throws DivergedError after writing a diverged frame
  // (marked "error" in stats.jsonl). Returns the last frame's stats line
  nlohmann::ordered_json run(const std::string& dir, int frames, bool overwrite,
                             const std::function<bool(int, int)>& progress);

 private:
  void checkCollider(int c) const;

  Scene scene_;
  std::string sceneText_;
  WorkspacePtr ws_;
  FrameStats pending_;                            // the steps since the last frame written
  std::vector<std::vector<Keyframe>> colliderKeys_;  // per collider: empty (its own keys) or the script's
};

}  // namespace soak::python
