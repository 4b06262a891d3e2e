// the PBD cloth's substep as small steps (Macklin, Storey, Lu, Terdiman, Chentanez, Jeschke, Müller
// 2019, "Small steps in physics simulation"): the stretch error that a few Gauss-Seidel iterations
// leave grows with the step squared, so m steps of h/m with one iteration each end far closer to
// inextensible than one step of h with m iterations, at about the same cost (docs/models.md, Eq. 8)
#include "core/lap_clock.hpp"
#include "core/parallel.hpp"
#include "pbd/cloth.hpp"
#include "pbd/tethers.hpp"

#include <limits>

namespace soak {

namespace {

// the free PBD cloth particles that may meet a collider in the substep of h: a lower bound of their
// distance at its start (to the colliders at its end) within twice their margin plus how far they may
// travel, (|v| + |g| h) h, and how far a moving collider may come, its speed bound times h. A particle
// that goes farther (pulled by its constraints) meets the colliders once, after the small steps
void findColliderCandidates(const Model& model, const SmallStepColliders& colliders, const Particles& p, float h,
                            ClothScratch& scratch) {
  const int n = model.numCloth;
  const std::vector<ColliderPose>& poses = colliders.poses.back();
  scratch.colliderBound.assign(static_cast<size_t>(n), std::numeric_limits<float>::max());
  for (size_t c = 0; c < model.colliders.size() && c < poses.size(); ++c)
    if (colliders.include[c])
      colliderDistanceBounds(model.colliders[c], poses[c], p.x[0].data(), n, scratch.colliderBound.data());
  const float fall = model.solver.gravity.norm() * h;
  scratch.colliderCandidates.clear();
  for (const IndexRange& r : colliders.cloth)
    for (int64_t i = r.begin; i < r.end; ++i) {
      if (!(p.invMass[i] > 0.0f) || model.clothPinned[i]) continue;
      const float carried = colliderCarry(model, poses, colliders.include, p.x[i], h);
      const float reach = 2.0f * contactMargin(model, p.phase[i]) + (p.v[i].norm() + fall) * h + carried;
      if (scratch.colliderBound[i] < reach) scratch.colliderCandidates.push_back(static_cast<int>(i));
    }
}


// stepCloth's clothSubsteps small steps of the substep h, each a prediction from the last, the tethers,
// the coarse levels, the constraints, the global step, the self-collision pairs and the colliders;
// leaves x* at the last small step's end and each particle's velocity there in scratch.stepVelocity.
// The small steps move d = x* - x from the substep's start x, not x* itself: a small step's move
// (g h_s^2 = 1.7e-7 m at 64 small steps of 1/120 s) is about a float's resolution at 1 m, and the
// velocities taken from x* so rounded heated a resting cloth (docs/models.md, "Single precision and
// the small steps"); the tethers move d too, and x* = x + d is rounded only where the global step,
// the self-collision and the colliders read it, their moves taken back into d exactly
void smallSteps(const Model& model, Particles& p, ClothScratch& scratch, float h, const SmallStepColliders* colliders,
                LapClock& clock) {
  const int n = model.numCloth;
  const int steps = std::max(1, model.solver.clothSubsteps);
  const float hs = h / static_cast<float>(steps);
  const Vec3 g = model.solver.gravity;
  const auto moves = [&](int64_t i) { return pbdClothMoves(model, i); };
  // the colliders in each small step too: met only after them, a resting cloth's small steps slid and
  // sank freely and the substep's friction took the slip back from x*, leaving the last small step's
  // velocity stored in the contact (docs/models.md, "Colliders")
  const bool contact = colliders && static_cast<int>(colliders->poses.size()) == steps;
  if (contact) {
    scratch.stepStart.resize(n);
    findColliderCandidates(model, *colliders, p, h, scratch);
  }
  scratch.displacement.resize(n);
  scratch.stepDisplacement.resize(n);
  scratch.stepVelocity.resize(n);
  Vec3* d = scratch.displacement.data();
  Vec3* y = scratch.stepDisplacement.data();
  Vec3* u = scratch.stepVelocity.data();
  const Vec3* x = p.x.data();
  // the substep's start: d = 0 and the velocity before predictPositions added h g (a particle that
  // does not move keeps its x*)
  parallelFor(n, [&](int64_t i) {
    d[i] = moves(i) ? Vec3::Zero() : Vec3(p.xPred[i] - x[i]);
    y[i] = d[i];
    u[i] = moves(i) ? Vec3(p.v[i] - h * g) : Vec3::Zero();
  });
  // y holds each small step's prediction: the velocity changes by the constraints' move over h_s, so a
  // particle they leave alone keeps v + t g exactly
  for (int s = 0; s < steps; ++s) {
    parallelFor(n, [&](int64_t i) {
      if (!moves(i)) return;
      u[i] += hs * g;
      if (contact) scratch.stepStart[i] = x[i] + y[i];
      d[i] = y[i] + hs * u[i];
      y[i] = d[i];
    });
    solveTethersFrom(model, x, d);
    solveHierarchyFrom(model, x, d, p.invMass.data(), scratch);
    solveClothFrom(model, x, d, p.invMass.data(), scratch, hs, model.solver.clothIterations);
    parallelFor(n, [&](int64_t i) {  // x* = x + d for the stages that read x*
      if (moves(i)) p.xPred[i] = x[i] + d[i];
    });
    globalStretchStep(model, p, scratch);
    clock.lap();
    collideSelfCollisionPairs(model, p, scratch);
    scratch.selfCollisionMs += clock.lap();
    if (contact)
      scratch.colliderPutBack += projectColliders(model, colliders->poses[s], p, scratch.colliderCandidates,
                                                  scratch.stepStart.data(), colliders->include, hs,
                                                  static_cast<float>(steps - 1 - s) * hs);
    parallelFor(n, [&](int64_t i) {
      if (!moves(i)) return;
      const Vec3 put = x[i] + d[i];  // d takes what those stages moved x* by, exactly
      if (p.xPred[i] != put) d[i] += p.xPred[i] - put;
      u[i] += (d[i] - y[i]) / hs;
      y[i] = d[i];
    });
  }
}

}  // namespace

void stepCloth(const Model& model, Particles& p, const NeighborLists& neighbors, ClothScratch& scratch, float h,
               const SmallStepColliders* colliders) {
  const int n = model.numCloth;
  scratch.colliderPutBack = 0;
  const int steps = std::max(1, model.solver.clothSubsteps);
  scratch.selfCollisionMs = 0.0;
  LapClock clock;
  if (steps == 1 || n == 0 || h <= 0.0f) {
    scratch.velocityOffset.clear();  // v = (x* - x)/h as it is
    solveTethers(model, p);  // long range attachments first, the iterations smooth what they moved
    solveCloth(model, p, scratch, h, model.solver.clothIterations);
    globalStretchStep(model, p, scratch);
    clock.lap();
    clothSelfCollision(model, p, neighbors, scratch);
    scratch.selfCollisionMs += clock.lap();
    return;
  }
  scratch.velocityOffset.assign(static_cast<size_t>(n), Vec3::Zero());
  // the self-collision in each small step, with its constraints: pushed apart only once a substep, a
  // crumpled fold's layers were pulled back by the small steps' constraints at 1/h_s and jittered at
  // metres a second (docs/models.md, "Cloth self-collision in the small steps")
  clock.lap();
  findSelfCollisionPairs(model, p, neighbors, h, scratch);
  scratch.selfCollisionMs += clock.lap();
  smallSteps(model, p, scratch, h, colliders, clock);
  // updateVelocities takes v = (x* - x)/h, the mean over the substep; the offset turns it into the last
  // small step's velocity plus what the later stages (collisions, coupling) add to x*, over h
  const Vec3* u = scratch.stepVelocity.data();
  Vec3* offset = scratch.velocityOffset.data();
  parallelFor(n, [&](int64_t i) {
    if (pbdClothMoves(model, i)) offset[i] = u[i] - (p.xPred[i] - p.x[i]) / h;
  });
}

}  // namespace soak
