// water emitters: a block of water (Fig. 3) and a nozzle jet (Fig. 1)
#pragma once
#include <soak/model.hpp>
#include <soak/state.hpp>

namespace soak {

// creates the water particles due in (t, t + dt]: a block when its start time falls in it, the jet's
// discs every water spacing travelled while t is inside [start, end). New particles get ids from
// state.nextId, mass model.water.particleMass and radius model.water.supportRadius; state.ledger.emitted
// grows by their mass. Stops quietly at model.solver.maxParticles. Returns the number created.
size_t emitWater(const Model& model, State& state, double t, float dt);

// the SPH density (poly6, the particle itself included) of an endless cubic lattice of water particles
// at this spacing, kg/m^3
float latticeDensity(const WaterParams& w, float spacing);

// the spacing at which that lattice has the rest density: where a block of water is laid out (Table 1's
// 0.0082 kg at 0.02 m with h = 0.04 m sums to about 1035 kg/m^3, 3.5% compressed)
float restLatticeSpacing(const WaterParams& w);

}  // namespace soak
