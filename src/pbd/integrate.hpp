// the plain stages of the step: prediction, velocity update, commit, domain bounds, checks
#pragma once
#include <soak/model.hpp>
#include <soak/state.hpp>

#include "core/parallel.hpp"
#include "pbd/fluid.hpp"
#include "world/colliders.hpp"

#include <span>
#include <vector>

namespace soak {

// the particles the PBD stages move, as ranges: the PBD cloth pieces' and the water (of n particles);
// the implicit pieces' are moved by src/garment
void pbdParticles(const Model& model, size_t n, std::vector<IndexRange>& ranges);

// v += dt g; x* = x + dt v for the particles in `moved`; pinned cloth stays at x with v = 0 (where the
// scene put it, or where a caller moved it between steps)
void predictPositions(const Model& model, const std::vector<IndexRange>& moved, Particles& p, float dt);

// v = (x* - x) / dt for the particles in `moved`, plus cloth particle i's clothVelocityOffset[i] where
// given (stepCloth's small steps), with the cloth's velocity damping
void updateVelocities(const Model& model, const std::vector<IndexRange>& moved, Particles& p, float dt,
                      std::span<const Vec3> clothVelocityOffset = {});

// x = x*
void commitPositions(Particles& p);

// removes water particles outside the domain box, adding their mass to the ledger; returns how many
size_t removeOutsideDomain(const Model& model, State& state, std::vector<uint8_t>& keep);

// every collider's pose at `time`: from colliderKeys[c] where the caller gave collider c keyframes
// (not empty), else from its own (Collider::keys)
void updateColliderPoses(const Model& model, double time, std::span<const std::vector<Keyframe>> colliderKeys,
                         std::vector<ColliderPose>& poses);
float maxSupportRadius(const Particles& p);

// the neighbour grid's cell size: the largest support radius of the cloth particles and of water as
// emitted (water.supportRadius). The few particles above it (drips that grew while they hung, up to
// 3 times as wide in Fig. 9) are searched wider by buildNeighborLists instead of making every cell
// their size; when more than an eighth of the particles are above it (heavy rain drops), the largest
// radius of all
float neighborCellSize(const Model& model, const Particles& p);
float meanDensityRatio(const Model& model, const Particles& p, const FluidScratch& s);

}  // namespace soak
