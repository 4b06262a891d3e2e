// the plain stages of the step: prediction, velocity update, commit, domain bounds, checks
#pragma once
#include <soak/model.hpp>
#include <soak/state.hpp>

#include "pbd/fluid.hpp"
#include "world/colliders.hpp"

#include <vector>

namespace soak {

// v += dt g; x* = x + dt v for free particles; pinned cloth follows its rest position
void predictPositions(const Model& model, double time, Particles& p, float dt);

// v = (x* - x) / dt, with the cloth's velocity damping
void updateVelocities(const Model& model, Particles& p, float dt);

// x = x*
void commitPositions(Particles& p);

// removes water particles outside the domain box, adding their mass to the ledger; returns how many
size_t removeOutsideDomain(const Model& model, State& state, std::vector<uint8_t>& keep);

void updateColliderPoses(const Model& model, double time, std::vector<ColliderPose>& poses);
float maxSupportRadius(const Particles& p);
float maxSpeed(const Particles& p);
float meanDensityRatio(const Model& model, const Particles& p, const FluidScratch& s);

}  // namespace soak
