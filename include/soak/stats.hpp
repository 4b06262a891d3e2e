// statistics of one step (summed over its substeps), written once per frame as a JSON line
#pragma once
#include <cstdint>

namespace soak {

struct StageTimes {         // ms of wall time per stage
  double emit = 0, predict = 0, neighbors = 0, water = 0, cloth = 0, coupling = 0, colliders = 0,
         velocities = 0, wetting = 0, total = 0;
  StageTimes& operator+=(const StageTimes& o) {
    emit += o.emit; predict += o.predict; neighbors += o.neighbors; water += o.water; cloth += o.cloth;
    coupling += o.coupling; colliders += o.colliders; velocities += o.velocities; wetting += o.wetting;
    total += o.total;
    return *this;
  }
};

struct StepStats {
  StageTimes ms;
  int substeps = 0;                 // substeps used by this step
  uint64_t couplingContacts = 0;    // water-triangle contacts resolved (Eq. 21)
  uint64_t emittedParticles = 0;    // water particles created this step
  uint64_t removedParticles = 0;    // water particles that left the domain this step
  float meanDensityRatio = 0.0f;    // mean rho_i / rho_0 over water particles after the solve
  float maxSpeed = 0.0f;            // m/s over all particles
};

}  // namespace soak
