// one simulation step of the unified position-based engine (Algorithm 1 of Shao et al. 2017)
#pragma once
#include <soak/model.hpp>
#include <soak/state.hpp>
#include <soak/stats.hpp>

#include <memory>
#include <span>
#include <string>
#include <vector>

namespace soak {

struct Workspace;  // scratch buffers (grid, neighbour lists, lambdas); reused step after step

struct WorkspaceDeleter {
  void operator()(Workspace* w) const;
};
using WorkspacePtr = std::unique_ptr<Workspace, WorkspaceDeleter>;
WorkspacePtr makeWorkspace();

// advances state by dt (split into model.solver.substeps substeps). Does not throw; a diverged
// state is reported by checkState. colliderKeys: collider motion a caller sets between steps in place
// of the scene's (a script moving a collider, python/): collider c follows colliderKeys[c] during the
// step, as it would its own Collider::keys, when that is not empty; the Model stays as loaded.
void step(const Model& model, State& state, Workspace& ws, float dt, StepStats& stats,
          std::span<const std::vector<Keyframe>> colliderKeys = {});

// where keyframes put a collider at time t (s): translation linear and rotation slerped between
// keys, the ends held; for a caller's colliderKeys, the pose of model.colliders[c] is
// poseAt(model.colliders[c].keys, t)
Keyframe poseAt(std::span<const Keyframe> keys, double t);

// returns an empty string when every particle is finite and below model.solver.maxSpeed, else a
// message naming the first bad particle
std::string checkState(const Model& model, const State& state);

// 64-bit FNV-1a hash of every array and counter of the State (particles, ledger, emitters, the
// cloth's held water, buffers, saturation, drips and wet start times, the last PBF iteration count):
// equal states hash equal
uint64_t stateHash(const State& state);

}  // namespace soak
