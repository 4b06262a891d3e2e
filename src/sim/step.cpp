// the simulation loop of Algorithm 1 (Shao et al. 2017): one line per stage, each stage in its own file
#include <soak/step.hpp>

#include "core/parallel.hpp"
#include "core/lap_clock.hpp"
#include "garment/stage.hpp"
#include "pbd/integrate.hpp"
#include "sim/diagnostics.hpp"
#include "sim/workspace.hpp"
#include "world/emitters.hpp"

#include <algorithm>

namespace soak {

namespace {

constexpr uint64_t kSortEverySteps = 10;  // the water moves less than a cell in 10 steps

// the wall time of the stages: each call of lap adds the ms since the last one to a stage (and to
// one of its parts)
struct StageClock {
  StageTimes& ms;
  LapClock clock;
  void lap(double& stage) { stage += clock.lap(); }
  void lap(double& stage, StagePart part) {
    const double t = clock.lap();
    stage += t;
    ms.part(part) += t;
  }
  // a lap of which `inner` ms (timed by the stage itself) belong to part b, the rest to part a
  void lap(double& stage, StagePart a, StagePart b, double inner) {
    const double t = clock.lap();
    stage += t;
    ms.part(a) += t - inner;
    ms.part(b) += inner;
  }
};

// x* of every particle: new water, gravity, the colliders' poses at the substep's end, and the
// implicit garments' own step (Chen 2012: Eq. 1-5, 15-19, section 3.5)
void predict(const Model& model, State& state, Workspace& ws, float h, std::span<const std::vector<Keyframe>> colliderKeys,
             StepStats& stats, StageClock& clock) {
  stats.emittedParticles += emitWater(model, state, state.time, h);                 // Fig. 1 jet, Fig. 3 block
  clock.lap(stats.ms.emit);
  pbdParticles(model, state.particles.size(), ws.pbdParticles);                     // water and PBD cloth
  predictPositions(model, ws.pbdParticles, state.particles, h);                    // v += dt g, x* = x + dt v
  updateColliderPoses(model, state.time + h, colliderKeys, ws.poses);
  clock.lap(stats.ms.predict);
  solveGarments(model, state, ws.garment, ws.poses, colliderKeys, h, stats);
  clock.lap(stats.ms.garment);
}

// the colliders' poses at the end of each of the PBD cloth's small steps of the substep that starts at
// t. A moving mesh sequence would build its surface's tree in every small step: it keeps the substep's
// end pose and each small step meets it ahead by its surface's velocity (kPosedAhead). Nothing without
// small steps or with solver.clothCollidersInSmallSteps false
const SmallStepColliders* smallStepColliders(const Model& model, Workspace& ws, double t, float h,
                                             std::span<const std::vector<Keyframe>> colliderKeys) {
  const int steps = model.solver.clothSubsteps;
  SmallStepColliders& c = ws.clothColliders;
  c.cloth.clear();
  for (const IndexRange& r : ws.pbdParticles)
    if (r.begin < model.numCloth) c.cloth.push_back({r.begin, std::min<int64_t>(r.end, model.numCloth)});
  if (steps <= 1 || c.cloth.empty() || model.colliders.empty() || !model.solver.clothCollidersInSmallSteps)
    return nullptr;
  const size_t count = model.colliders.size();
  c.include.assign(count, 1);
  c.poses.resize(static_cast<size_t>(steps));
  for (int s = 0; s < steps; ++s) c.poses[s] = ws.poses;  // a still collider: its pose at the substep's end
  for (size_t k = 0; k < count; ++k) {
    if (!ws.poses[k].moving()) continue;
    if (model.colliders[k].shape == ColliderShape::MeshSequence) {
      c.include[k] = kPosedAhead;  // posed at the substep's end, met ahead of each small step's end
      continue;
    }
    const bool given = k < colliderKeys.size() && !colliderKeys[k].empty();
    const std::span<const Keyframe> keys = given ? colliderKeys[k] : model.colliders[k].keys;
    for (int s = 0; s + 1 < steps; ++s)
      c.poses[s][k] = colliderPose(model.colliders[k], keys, t + h * static_cast<double>(s + 1) / steps);
  }
  return &c;
}

// the constraints on x*: water (Eq. 6-7) with the cloth as its boundary, cloth (Eq. 8-9), colliders
// and the water-cloth coupling (Eq. 21-22)
void project(const Model& model, State& state, Workspace& ws, float h,
             std::span<const std::vector<Keyframe>> colliderKeys, StepStats& stats, StageClock& clock) {
  Particles& p = state.particles;
  StageTimes& ms = stats.ms;
  buildGrid(p.xPred, neighborCellSize(model, p), ws.grid);                         // neighbours of x*
  clock.lap(ms.neighbors, StagePart::neighborsGrid);
  buildNeighborLists(p.xPred, p.radius, ws.grid, ws.neighbors, static_cast<uint32_t>(model.numCloth));
  clock.lap(ms.neighbors, StagePart::neighborsLists);
  computeBoundaryPsi(model, p, ws.neighbors, ws.fluid);                              // cloth as Akinci boundary
  scaleBoundaryByPermeability(model, state, ws.fluid.psi);                          // Eq. 22: wet cloth, thinner wall
  const int its = solveFluid(model, ws.poses, p, ws.neighbors, ws.fluid, model.solver.fluidIterations,
                             model.solver.fluidMaxIterations, state.fluidIterations);  // PBF, Eq. 6-7
  if (its > 0) state.fluidIterations = its;                                         // no water: keep the count
  stats.fluidIterations += static_cast<uint64_t>(its);
  stats.fluidIterationsMax = std::max(stats.fluidIterationsMax, its);
  clock.lap(ms.water);
  stepCloth(model, p, ws.neighbors, ws.cloth, h,                                    // small steps: tethers, Eq. 8, Eq. 9,
            smallStepColliders(model, ws, state.time, h, colliderKeys));              // self-collision, colliders
  stats.colliderPutBack += ws.cloth.colliderPutBack;
  clock.lap(ms.cloth, StagePart::clothSolve, StagePart::clothSelfCollision, ws.cloth.selfCollisionMs);
  stats.colliderPutBack += projectColliders(model, ws.poses, p, ws.pbdParticles, h, ws.contactNormal,
                                            ws.colliderBound);                       // Coulomb friction
  clock.lap(ms.colliders);
  updateCouplingStiffness(model, state, ws.coupling.triangleStiffness);             // Eq. 22: wetter cloth lets water through
  findCouplingCandidates(model, p, ws.coupling);                                    // triangles near each water particle's path
  clock.lap(ms.coupling, StagePart::couplingSearch);
  for (int it = 0; it < model.solver.couplingIterations; ++it)                     // water-cloth, Eq. 21-22
    stats.couplingContacts += solveCoupling(model, p, ws.coupling, false);
  solveCoupling(model, p, ws.coupling, true);                                       // no water crosses the cloth
  clock.lap(ms.coupling, StagePart::couplingPasses);
}

// v from x* - x, then x = x*
void updateVelocitiesAndCommit(const Model& model, Workspace& ws, Particles& p, float h, StepStats& stats,
                               StageClock& clock) {
  updateVelocities(model, ws.pbdParticles, p, h, ws.cloth.velocityOffset);          // v = (x* - x) / dt, damping
  addCouplingVelocity(model, p, ws.garment, h);                                     // implicit cloth pushed by water
  applyColliderRestitution(model, ws.poses, ws.contactNormal, p);
  clock.lap(stats.ms.velocities);
  fluidVelocityPass(model, p, ws.neighbors, ws.fluid, h, true);                     // XSPH, vorticity
  clock.lap(stats.ms.velocities, StagePart::velocitiesXsph);
  stats.meanDensityRatio = meanDensityRatio(model, p, ws.fluid);
  commitPositions(p);                                                               // x = x*
  clock.lap(stats.ms.velocities);
}

// the wetting stages of Shao 2017 section 4 over wetDt
void wet(const Model& model, State& state, Workspace& ws, float wetDt, StageClock& clock) {
  const auto lap = [&](StagePart part) { clock.lap(clock.ms.wetting, part); };
  updatePorosity(model, state, ws.neighbors, ws.wetting);                           // V_i, S_i, wet mass (Eq. 10)
  lap(StagePart::wettingPorosity);
  absorbWater(model, state, ws.neighbors, ws.wetting, wetDt);                       // water soaks in (Eq. 11)
  lap(StagePart::wettingAbsorption);
  diffuseWater(model, state, ws.neighbors, ws.wetting, wetDt);                      // spreads in the cloth (Eq. 12-17)
  lap(StagePart::wettingDiffusion);
  emitExcessWater(model, state, ws.neighbors, ws.grid, ws.poses, ws.wetting, wetDt);  // excess runs down, drips (Eq. 18)
  lap(StagePart::wettingEmission);
  applyDripAttraction(model, state, ws.neighbors, ws.wetting, wetDt);               // cloth holds its drips (Eq. 19)
  lap(StagePart::wettingAttraction);
  applySticking(model, state, ws.neighbors, ws.wetting, wetDt);                     // wet cloth sticks (Eq. 20)
  lap(StagePart::wettingSticking);
  finishWetting(model, state, ws.wetting);                                          // absorbed water leaves; ledger
  lap(StagePart::wettingFinish);
}

// one substep of Algorithm 1. wetDt: the time the wetting stages cover, 0 to skip them (the step's
// dt after its last substep, or the substep's h after each with wetting.everySubstep)
void substep(const Model& model, State& state, Workspace& ws, float h, float wetDt,
             std::span<const std::vector<Keyframe>> colliderKeys, StepStats& stats) {
  StageClock clock{stats.ms, LapClock{}};
  predict(model, state, ws, h, colliderKeys, stats, clock);                         // x* = x + dt v
  project(model, state, ws, h, colliderKeys, stats, clock);                         // neighbours, constraints
  updateVelocitiesAndCommit(model, ws, state.particles, h, stats, clock);           // v, then x = x*
  if (wetDt > 0.0f) wet(model, state, ws, wetDt, clock);                            // absorb, diffuse, drip, stick
  clock.lap(stats.ms.wetting);
  const DropCandidates paths{ws.coupling.candidateStart, ws.coupling.candidates};  // the coupling's, this substep
  stats.garment.dropsTaken += wetClothByContact(model, state, ws.neighbors, paths, ws.garment, ws.keep, state.time + h);
  clock.lap(stats.ms.garment, StagePart::garmentDrops);                             // Chen 2012: wet by contact
  stats.removedParticles += removeOutsideDomain(model, state, ws.keep);             // counted in the ledger
  clock.lap(stats.ms.velocities);
  state.time += h;
}

}  // namespace

void WorkspaceDeleter::operator()(Workspace* w) const { delete w; }
WorkspacePtr makeWorkspace() { return WorkspacePtr(new Workspace()); }

void step(const Model& model, State& state, Workspace& ws, float dt, StepStats& stats,
          std::span<const std::vector<Keyframe>> colliderKeys) {
  LapClock total;
  const int n = std::max(1, model.solver.substeps);
  const float h = dt / static_cast<float>(n);
  if (state.stepCount % kSortEverySteps == 0)                                       // water in cell order:
    sortParticlesByCell(state.particles, model.numCloth, model.water.supportRadius, ws.reorder);  // neighbours close in memory
  // Algorithm 1's wetting once a step at its dt; the substeps refine the dynamics only (departure: docs/models.md)
  const bool every = model.wetting.everySubstep;
  for (int s = 0; s < n; ++s)
    substep(model, state, ws, h, every ? h : (s + 1 == n ? dt : 0.0f), colliderKeys, stats);
  stats.substeps += n;
  stats.maxSpeed = maxSpeed(state.particles);
  ++state.stepCount;
  stats.ms.total += total.lap();
}

Keyframe poseAt(std::span<const Keyframe> keys, double t) {
  const ColliderPose pose = keyframedPose(keys, t);
  return {static_cast<float>(t), pose.translation, pose.rotation};
}

}  // namespace soak
