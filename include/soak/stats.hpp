// statistics of one step (summed over its substeps), written once per frame as a JSON line
#pragma once
#include <cstdint>

namespace soak {

// parts of the stages below (ms), named "stage.part": the wetting stages one by one (Table 2 of Shao
// 2017 gives the wetting's time apart from the total), and the parts of the neighbour search, cloth,
// coupling, velocity and implicit garment stages (`soak bench --stages`; docs/performance.md on
// finding serial work)
enum class StagePart : int {
  neighborsGrid, neighborsLists, clothSolve, clothSelfCollision, couplingSearch, couplingPasses, velocitiesXsph,
  wettingPorosity, wettingAbsorption, wettingDiffusion, wettingEmission, wettingAttraction, wettingSticking,
  wettingFinish, garmentAssemble, garmentCg, garmentIntegrate, garmentSelfContact, garmentDrops, count
};
inline constexpr int kStagePartCount = static_cast<int>(StagePart::count);
inline constexpr const char* kStagePartNames[kStagePartCount] = {
    "neighbors.grid",     "neighbors.lists",    "cloth.solve",        "cloth.selfCollision", "coupling.search",
    "coupling.passes",    "velocities.xsph",    "wetting.porosity",   "wetting.absorption",  "wetting.diffusion",
    "wetting.emission",   "wetting.attraction", "wetting.sticking",   "wetting.finish",      "garment.assemble",
    "garment.cg",         "garment.integrate",  "garment.selfContact", "garment.drops"};

struct StageTimes {         // ms of wall time per stage
  double emit = 0, predict = 0, neighbors = 0, water = 0, cloth = 0, coupling = 0, colliders = 0,
         velocities = 0, wetting = 0, garment = 0, total = 0;
  double parts[kStagePartCount] = {};  // each within its stage's time (StagePart)
  double& part(StagePart k) { return parts[static_cast<int>(k)]; }
  StageTimes& operator+=(const StageTimes& o) {
    emit += o.emit; predict += o.predict; neighbors += o.neighbors; water += o.water; cloth += o.cloth;
    coupling += o.coupling; colliders += o.colliders; velocities += o.velocities; wetting += o.wetting;
    garment += o.garment; total += o.total;
    for (int k = 0; k < kStagePartCount; ++k) parts[k] += o.parts[k];
    return *this;
  }
};

// the implicit garment solves of Chen 2012 (src/garment), summed over substeps and pieces
struct GarmentStats {
  uint64_t solves = 0;          // implicit steps taken (pieces x substeps; each part of a halved step)
  uint64_t cgIterations = 0;    // summed over the solves
  int cgIterationsMax = 0;
  double maxResidual = 0.0;     // largest relative CG residual at exit
  uint64_t unconverged = 0;     // solves whose CG stopped at garment.cg.maxIterations (the step still ran)
  uint64_t breakdowns = 0;      // solves whose system was not positive definite
  uint64_t factorFailures = 0;  // solves whose Cholesky or multigrid factor failed (block Jacobi used)
  uint64_t contacts = 0;        // vertex-collider contacts
  uint64_t contactRows = 0;     // of them, vertices held on a collider by the solve (contact rows)
  uint64_t stickingRows = 0;    // of those, sticking to it (static friction); the others slide
  uint64_t edgeContacts = 0;    // edge-collider contacts (an edge's midpoint pushed out)
  uint64_t selfContacts = 0;    // vertex-triangle pushes of an implicit piece's self-collision
  uint64_t selfEdgeContacts = 0;  // and its edge-edge pushes
  uint64_t selfReverted = 0;    // vertices its fail-safe moved into impact zones (docs/garment.md, "Self-collision")
  uint64_t disturbances = 0;    // wrinkle constraints applied (section 3.5)
  uint64_t dropsTaken = 0;      // water particles that wetted a piece and vanished into it
  float maxStrain = 0.0f;       // largest stretch-spring strain at the start of a solve (Eq. 11's eps)
  uint64_t strainLimited = 0;   // springs the strain limiting shortened to Eq. 11's pole (docs/garment.md, departure 2)
  uint64_t halvedSteps = 0;     // implicit steps redone as smaller steps: a vertex was faster than solver.maxSpeed
  GarmentStats& operator+=(const GarmentStats& o) {
    solves += o.solves; cgIterations += o.cgIterations; cgIterationsMax = cgIterationsMax > o.cgIterationsMax ? cgIterationsMax : o.cgIterationsMax;
    maxResidual = maxResidual > o.maxResidual ? maxResidual : o.maxResidual; unconverged += o.unconverged;
    breakdowns += o.breakdowns; factorFailures += o.factorFailures; contacts += o.contacts; contactRows += o.contactRows; stickingRows += o.stickingRows; edgeContacts += o.edgeContacts; selfContacts += o.selfContacts; selfEdgeContacts += o.selfEdgeContacts; selfReverted += o.selfReverted; strainLimited += o.strainLimited; halvedSteps += o.halvedSteps; disturbances += o.disturbances; dropsTaken += o.dropsTaken;
    maxStrain = maxStrain > o.maxStrain ? maxStrain : o.maxStrain;
    return *this;
  }
};

struct StepStats {
  StageTimes ms;
  int substeps = 0;                 // substeps used by this step
  uint64_t couplingContacts = 0;    // water-triangle contacts resolved (Eq. 21)
  uint64_t emittedParticles = 0;    // water particles created this step
  uint64_t removedParticles = 0;    // water particles that left the domain this step
  uint64_t colliderPutBack = 0;     // particles put back out of a collider they were in or went through
  float meanDensityRatio = 0.0f;    // mean rho_i / rho_0 over water particles after the solve
  uint64_t fluidIterations = 0;     // PBF iterations, summed over the substeps
  int fluidIterationsMax = 0;       // the most one substep took
  float maxSpeed = 0.0f;            // m/s over all particles
  GarmentStats garment;
};

}  // namespace soak
