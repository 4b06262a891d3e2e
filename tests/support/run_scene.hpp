// helpers for tests that run whole scenes
#pragma once
#include <soak/scene.hpp>
#include <soak/step.hpp>

#include "core/parallel.hpp"

#include <array>
#include <cstdint>
#include <string>

namespace soak::testing {

inline Scene sceneFromJson(const std::string& json, const std::vector<std::string>& overrides = {}) {
  return loadSceneFromString(json, "<test>", SOAK_SOURCE_DIR, overrides);
}

inline Scene sceneFromFile(const std::string& relative, const std::vector<std::string>& overrides = {}) {
  return loadScene(std::string(SOAK_SOURCE_DIR) + "/" + relative, overrides);
}

// runs `steps` steps of the scene's dt; returns the summed statistics
inline StepStats runSteps(Scene& scene, int steps) {
  WorkspacePtr ws = makeWorkspace();
  StepStats total;
  for (int s = 0; s < steps; ++s) step(scene.model, scene.state, *ws, scene.model.solver.dt, total);
  return total;
}

// the state hash after `steps` steps of the scene that make() loads, on 1, 2 and 3 threads (the thread
// count is set back to 2); check(scene) runs on each loaded scene first
template <class Make, class Check>
std::array<uint64_t, 3> hashesOnOneTwoThreeThreads(Make make, int steps, Check check) {
  std::array<uint64_t, 3> hashes{};
  for (int threads : {1, 2, 3}) {
    setThreadCount(threads);
    Scene scene = make();
    check(scene);
    runSteps(scene, steps);
    hashes[static_cast<size_t>(threads - 1)] = stateHash(scene.state);
  }
  setThreadCount(2);
  return hashes;
}

inline double totalWaterMass(const Scene& scene) {
  double m = 0.0;
  const Particles& p = scene.state.particles;
  for (size_t i = static_cast<size_t>(scene.model.numCloth); i < p.size(); ++i) m += p.mass[i];
  return m;
}

}  // namespace soak::testing
