// the Chen 2012 garment stages of the step (docs/garment.md, "Calls from the step"): the implicit
// solve of every piece with "solver": "implicit", the saturation mass of Eq. 15-19 for any piece
// that asks for it, and the water that reaches the cloth: each vertex's held water
// (State::clothWater) and saturation (State::clothSaturation), which the saturation mass, the wet
// friction of Fig. 5 and the wrinkle disturbances read.
#pragma once
#include <soak/model.hpp>
#include <soak/state.hpp>
#include <soak/stats.hpp>

#include "garment/implicit.hpp"
#include "grid/grid.hpp"
#include "world/colliders.hpp"

#include <span>
#include <vector>

namespace soak {

// builds ClothPiece::implicit of every piece with "solver": "implicit" (springs, system pattern, and
// the wrinkle subdomains: the garment's panels where it has them, else patches); the scene loader
// calls it once the pieces are complete
void buildGarmentPieces(Model& model);

struct GarmentScratch {
  std::vector<ImplicitScratch> scratch;  // per cloth piece (used by the implicit ones)
  std::vector<Vec3> solved;              // xPred of the implicit cloth particles right after their solve
  std::vector<int32_t> touch;            // per particle: the cloth vertex a water particle wets, or -1
  std::vector<float> fraction;           // a piece's S / S^MAX when Shao's wetting is on
  std::vector<int> soakOrder;            // the vertices a drop soaks into, nearest first
  std::vector<uint8_t> soakSeen;         // per cloth particle, during one drop's soak
  std::vector<Vec3> startX, startV, startDv;  // a piece's x (once halving), v and last dv at its step's start
  std::vector<ColliderPose> partPoses;        // the colliders at the end of a halved step's part
  std::vector<ImplicitStats> steps;           // the statistics of the piece's steps at the last halving
};

// the cloth triangles near each water particle's path this substep (the coupling's candidates,
// CouplingScratch): start[j - numCloth] .. start[j - numCloth + 1] in triangles. Empty: none searched
struct DropCandidates {
  std::span<const uint32_t> start, triangles;
};

// before the PBD stages, after predictPositions (which moves only water and PBD cloth): advances the
// saturation of the pieces with wetByContact to state.time + h (updateSaturation; with Shao's wetting
// on its S / S^MAX is used instead), sets the Eq. 15-19 mass of every piece with
// garment.saturationMass, then steps every implicit piece (stepPiece: garmentSubstep, Eq. 1-5,
// wrinkles, contact with wet friction), writing its xPred and v. poses are the colliders at
// state.time + h; colliderKeys override their keys, as in step() (empty: the model's).
void solveGarments(const Model& model, State& state, GarmentScratch& s, const std::vector<ColliderPose>& poses,
                   std::span<const std::vector<Keyframe>> colliderKeys, float h, StepStats& stats);

// the halvings of an implicit step that left a vertex faster than solver.maxSpeed: redone as 2, then
// 4, then 8 steps (stepPiece)
constexpr int kMaxHalvings = 3;

// what stepPiece needs of the substep: the piece's saturation and warm-start dv (piece-local), the
// colliders at its end and their keys (the poses of a halved step's parts)
struct PieceStepInputs {
  std::span<const float> saturation;
  std::span<Vec3> velocityChange;
  const std::vector<ColliderPose>& poses;
  std::span<const std::vector<Keyframe>> colliderKeys;
};

// implicit piece k's step of h from state.time (garmentSubstep), its statistics added to stats. A step
// that leaves one of its vertices faster than solver.maxSpeed (the run would end as diverged) is done
// again from its start as 2, 4, then up to 2^kMaxHalvings steps, each with the colliders at its own
// end, until none is (GarmentStats::halvedSteps). The steps dropped count in the CG iterations and the
// times only; the frame's other statistics are the kept steps' (solves: each of them)
void stepPiece(const Model& model, State& state, GarmentScratch& s, size_t k, const PieceStepInputs& in, float h,
               StepStats& stats);

// after the water coupling (Eq. 21), which may have moved implicit cloth: adds that displacement over
// h to its velocity (updateVelocities moves only water and PBD cloth). A piece whose drops vanish (no Shao
// wetting) is not moved by the water: the displacement is undone (one-way coupling)
void addCouplingVelocity(const Model& model, Particles& p, const GarmentScratch& s, float h);

// after commitPositions: the water that reaches the pieces with wetByContact, and the first wet time
// of their vertices. With Shao's wetting on, a vertex is wet once it holds water (State::clothWater >
// 0) and nothing else happens here. Without it, a water particle within touchDistance(piece) of a
// vertex that still takes water, or of the surface of one of its candidate triangles (at that
// triangle's nearest vertex that takes water), soaks into the fabric from there: into its
// clothWater up to delta m_dry, the rest into its mesh neighbours with room, nearest rings first
// (every vertex that gets water is wet). Rain on fabric with no room for it stays water and runs off.
// A piece with saturation.unlimitedSupply (Chen as printed) instead is wet wherever a particle
// reaches (and at the vertex it touched), and the particle vanishes when the piece has dropsVanish
// (WaterLedger::takenByCloth).
// time is the end of the substep. Returns the number of water particles taken.
size_t wetClothByContact(const Model& model, State& state, const NeighborLists& nb, const DropCandidates& candidates,
                         GarmentScratch& s, std::vector<uint8_t>& keep, double time);

// per cloth particle, how wet it is in [0, 1]: the saturation s = Q / delta (Eq. 18) of the pieces
// with wetByContact (S / S^MAX with Shao's wetting on), 0 elsewhere (the "wetness" attribute of the
// cloth PLY)
std::vector<float> clothWetness(const Model& model, const State& state);

// how a garment sits, for the statistics: over the vertices of the pieces solved implicitly or
// wetted by contact, the lowest and the mean height (m), the mean distance to the nearest collider's
// surface (m; 0 without colliders) and the mean saturation in [0, 1] (clothWetness)
struct GarmentShape {
  int vertices = 0;
  double lowest = 0.0, meanHeight = 0.0, meanColliderDistance = 0.0, meanSaturation = 0.0;
};
GarmentShape garmentShape(const Model& model, const State& state);

// the distance within which a water particle wets a cloth vertex: the piece's thickness (the
// distance Eq. 21 keeps water from a triangle) plus one water spacing (m)
float touchDistance(const Model& model, const ClothPiece& piece);

}  // namespace soak
