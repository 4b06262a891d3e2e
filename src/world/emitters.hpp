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

}  // namespace soak
