// State: everything the step changes. Particle data is a struct of arrays, float32, indexed by
// particle; cloth particles are [0, model.numCloth), water particles follow.
#pragma once
#include <soak/math.hpp>

#include <cstdint>
#include <vector>

namespace soak {

struct Particles {
  std::vector<int32_t> phase;     // 0 water, k + 1 cloth piece k
  std::vector<uint32_t> id;       // stable id for output; never reused within a run
  std::vector<float> mass;        // kg
  std::vector<float> invMass;     // 1/kg; 0 for pinned cloth
  std::vector<float> radius;      // m, SPH support radius h_i (adaptive water particles differ)
  std::vector<Vec3> x;            // m, position at the start of the step
  std::vector<Vec3> xPred;        // m, predicted position x* (Algorithm 1)
  std::vector<Vec3> v;            // m/s

  size_t size() const { return x.size(); }
  // mass m (kg) and its inverse together, 0 for a kinematic (pinned) particle: every stage that moves
  // water into or out of a particle writes its mass through this
  void setMass(size_t i, float m, bool kinematic) {
    mass[i] = m;
    invMass[i] = kinematic ? 0.0f : 1.0f / m;
  }
  void resize(size_t n);
  // append one particle; returns its index
  size_t add(int32_t phase, uint32_t id, float mass, float radius, const Vec3& x, const Vec3& v);
  // keep the particles whose keep[i] != 0, in order (stable, deterministic)
  void compact(const std::vector<uint8_t>& keep);
};

// where the water is: the sum of these stays constant (free + held + buffers + removed - emitted)
struct WaterLedger {
  double emitted = 0.0;            // kg, created by emitters (and held by the cloth at load, Fig. 6)
  double removedAtBounds = 0.0;    // kg, water particles that left the domain
  uint64_t particlesRemovedAtBounds = 0;
  double heldInCloth = 0.0;        // kg, water held by the cloth (Eq. 10's m^water), after the last wetting stage
  double inBuffers = 0.0;          // kg, excess water in the emission buffers (section 4.4)
  uint64_t particlesAbsorbed = 0;  // water particles absorbed whole (Eq. 11)
  uint64_t dripsEmitted = 0;       // drip particles created from the buffers (section 4.4)
  double takenByCloth = 0.0;       // kg, water particles that vanished into a Chen 2012 piece of unlimited supply
  uint64_t particlesTakenByCloth = 0;  // particles taken by Chen pieces (into clothWater, or vanished)
};

struct EmitterState {
  double emittedLength = 0.0;      // m of jet emitted so far (a new disc every spacing)
  uint64_t dropsEmitted = 0;       // rain: drops created so far (drop k's place hashes k)
  bool done = false;
};

struct State {
  double time = 0.0;               // s
  uint64_t stepCount = 0;
  uint32_t nextId = 0;
  Particles particles;
  WaterLedger ledger;
  std::vector<EmitterState> emitters;
  // cloth wetting (Shao 2017 section 4): one entry per cloth particle when model.wetting.enabled, or
  // when a piece is wetted by contact (Chen 2012, below; clothBuffer then stays 0).
  // double for the water stores so the ledger closes to 1e-5 over long runs
  std::vector<double> clothWater;      // kg held, m^water of Eq. 10 (Chen: the drops a vertex took)
  std::vector<double> clothBuffer;     // kg of excess water waiting to drip, EW^buffer of section 4.4
  std::vector<float> clothSaturation;  // S_i of Eq. 10 at the last wetting stage (Chen: s = Q / delta in [0, 1])
  std::vector<uint32_t> dripId;        // ids of the drips hanging from the cloth (Eq. 19), ascending
  std::vector<int32_t> dripSource;     // the cloth particle each drip hangs from
  // Chen 2012: the time each cloth particle first got wet (+infinity: dry); one entry per cloth
  // particle when a piece has wetByContact, else empty
  std::vector<float> clothWetStart;
  // Chen 2012 implicit pieces: each cloth particle's velocity change in the last implicit substep
  // (m/s), the next solve's initial guess (garment.cg.warmStart); one entry per cloth particle when a
  // piece is implicit, else empty
  std::vector<Vec3> clothVelocityChange;
  // PBF iterations the last substep took: the iterations to solver.fluidTolerance go below it only
  // with a margin (stopIterating, docs/models.md "Eq. 6-7 iterated to a tolerance")
  int fluidIterations = 0;
};

}  // namespace soak
