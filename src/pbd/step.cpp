// the simulation loop of Algorithm 1 (Shao et al. 2017): one line per stage, each stage in its own file
#include <soak/step.hpp>

#include "core/parallel.hpp"
#include "garment/stage.hpp"
#include "pbd/integrate.hpp"
#include "pbd/tethers.hpp"
#include "pbd/workspace.hpp"
#include "world/emitters.hpp"

#include <algorithm>
#include <chrono>

namespace soak {

namespace {

constexpr uint64_t kSortEverySteps = 10;  // the water moves less than a cell in 10 steps

struct StageClock {
  std::chrono::steady_clock::time_point t = std::chrono::steady_clock::now();
  double lap() {  // ms since the last lap
    const auto now = std::chrono::steady_clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - t).count();
    t = now;
    return ms;
  }
  double lap(double& part) {  // the same, also added to one of the stage's parts
    const double ms = lap();
    part += ms;
    return ms;
  }
};

// wetDt: the time the wetting stages cover, 0 to skip them (the step's dt after its last substep, or
// the substep's h after each with wetting.everySubstep)
void substep(const Model& model, State& state, Workspace& ws, float h, float wetDt, StepStats& stats) {
  Particles& p = state.particles;
  StageTimes& ms = stats.ms;
  StageClock clock;
  stats.emittedParticles += emitWater(model, state, state.time, h);                 // new water (Fig. 1 jet, Fig. 3 block)
  ms.emit += clock.lap();
  predictPositions(model, state.time + h, p, h);                                    // v += dt g, x* = x + dt v
  updateColliderPoses(model, state.time + h, ws.poses);
  ms.predict += clock.lap();
  solveGarments(model, state, ws.garment, ws.poses, h, stats);                      // Chen 2012: Eq. 1-5, 15-19, 3.5
  ms.garment += clock.lap();
  buildGrid(p.xPred, neighborCellSize(model, p), ws.grid);                         // neighbours of x*
  ms.neighbors += clock.lap(ms.part(StagePart::neighborsGrid));
  buildNeighborLists(p.xPred, p.radius, ws.grid, ws.neighbors, static_cast<uint32_t>(model.numCloth));
  ms.neighbors += clock.lap(ms.part(StagePart::neighborsLists));
  computeBoundaryPsi(model, p, ws.neighbors, ws.fluid);                              // cloth as Akinci boundary
  scaleBoundaryByPermeability(model, state, ws.fluid.psi);                          // Eq. 22: wet cloth, thinner wall
  solveFluid(model, ws.poses, p, ws.neighbors, ws.fluid, model.solver.fluidIterations);  // PBF, Eq. 6-7
  ms.water += clock.lap();
  solveTethers(model, p);                                                           // long range attachments first,
  solveCloth(model, p, ws.cloth, h, model.solver.clothIterations);                  // then stretch Eq. 8, bend Eq. 9
  ms.cloth += clock.lap(ms.part(StagePart::clothSolve));
  clothSelfCollision(model, p, ws.neighbors, ws.cloth);
  ms.cloth += clock.lap(ms.part(StagePart::clothSelfCollision));
  projectColliders(model, ws.poses, p, h, ws.contactNormal, ws.colliderBound);      // rigid bodies, friction
  ms.colliders += clock.lap();
  updateCouplingStiffness(model, state, ws.coupling.triangleStiffness);             // Eq. 22: wetter cloth lets water through
  findCouplingCandidates(model, p, ws.coupling);                                    // triangles near each water particle's path
  ms.coupling += clock.lap(ms.part(StagePart::couplingSearch));
  for (int it = 0; it < model.solver.couplingIterations; ++it)                     // water-cloth, Eq. 21-22
    stats.couplingContacts += solveCoupling(model, p, ws.coupling, false);
  solveCoupling(model, p, ws.coupling, true);                                       // no water crosses the cloth
  ms.coupling += clock.lap(ms.part(StagePart::couplingPasses));
  updateVelocities(model, p, h);                                                    // v = (x* - x) / dt, damping
  addCouplingVelocity(model, p, ws.garment, h);                                     // implicit cloth pushed by water
  applyColliderRestitution(model, ws.poses, ws.contactNormal, p);
  ms.velocities += clock.lap();
  fluidVelocityPass(model, p, ws.neighbors, ws.fluid, h);                           // XSPH, vorticity
  ms.velocities += clock.lap(ms.part(StagePart::velocitiesXsph));
  stats.meanDensityRatio = meanDensityRatio(model, p, ws.fluid);
  commitPositions(p);                                                               // x = x*
  ms.velocities += clock.lap();
  if (wetDt > 0.0f) {
    const auto wetLap = [&](StagePart k) { ms.wetting += clock.lap(ms.part(k)); };
    updatePorosity(model, state, ws.neighbors, ws.wetting);                         // V_i, S_i, wet mass (Eq. 10)
    wetLap(StagePart::wettingPorosity);
    absorbWater(model, state, ws.neighbors, ws.wetting, wetDt);                     // water soaks in (Eq. 11)
    wetLap(StagePart::wettingAbsorption);
    diffuseWater(model, state, ws.neighbors, ws.wetting, wetDt);                    // spreads in the cloth (Eq. 12-17)
    wetLap(StagePart::wettingDiffusion);
    emitExcessWater(model, state, ws.neighbors, ws.grid, ws.poses, ws.wetting, wetDt);  // excess runs down, drips (Eq. 18)
    wetLap(StagePart::wettingEmission);
    applyDripAttraction(model, state, ws.neighbors, ws.wetting, wetDt);             // cloth holds its drips (Eq. 19)
    wetLap(StagePart::wettingAttraction);
    applySticking(model, state, ws.neighbors, ws.wetting, wetDt);                   // wet cloth sticks (Eq. 20)
    wetLap(StagePart::wettingSticking);
    finishWetting(model, state, ws.wetting);                                        // absorbed water leaves; ledger
    wetLap(StagePart::wettingFinish);
  }
  ms.wetting += clock.lap();
  stats.garment.dropsTaken += wetClothByContact(model, state, ws.neighbors, ws.garment, ws.keep, state.time + h);
  ms.garment += clock.lap();
  stats.removedParticles += removeOutsideDomain(model, state, ws.keep);             // counted in the ledger
  ms.velocities += clock.lap();
  state.time += h;
}

}  // namespace

void WorkspaceDeleter::operator()(Workspace* w) const { delete w; }
WorkspacePtr makeWorkspace() { return WorkspacePtr(new Workspace()); }

void step(const Model& model, State& state, Workspace& ws, float dt, StepStats& stats) {
  const auto start = std::chrono::steady_clock::now();
  const int n = std::max(1, model.solver.substeps);
  const float h = dt / static_cast<float>(n);
  if (state.stepCount % kSortEverySteps == 0)                                       // water in cell order:
    sortParticlesByCell(state.particles, model.numCloth, model.water.supportRadius, ws.reorder);  // neighbours close in memory
  // Algorithm 1's wetting once a step at its dt; the substeps refine the dynamics only (departure: docs/models.md)
  const bool every = model.wetting.everySubstep;
  for (int s = 0; s < n; ++s) substep(model, state, ws, h, every ? h : (s + 1 == n ? dt : 0.0f), stats);
  stats.substeps += n;
  stats.maxSpeed = maxSpeed(state.particles);
  ++state.stepCount;
  stats.ms.total += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace soak
