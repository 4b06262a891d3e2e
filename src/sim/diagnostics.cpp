// whole-state diagnostics of the step's API (soak/step.hpp): the divergence check, the state hash of
// the determinism tests and the fastest particle
#include <soak/step.hpp>

#include "sim/diagnostics.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <initializer_list>

namespace soak {

float maxSpeed(const Particles& p) {
  float m = 0.0f;
  for (const Vec3& v : p.v) m = std::max(m, v.norm());
  return m;
}

std::string checkState(const Model& model, const State& state) {
  const Particles& p = state.particles;
  for (size_t i = 0; i < p.size(); ++i) {
    const char* kind = isWater(p.phase[i]) ? "water" : "cloth";
    if (!p.x[i].allFinite() || !p.v[i].allFinite())
      return fmt::format("{} particle {} (id {}) has a non-finite position or velocity", kind, i, p.id[i]);
    const float speed = p.v[i].norm();
    if (speed > model.solver.maxSpeed)
      return fmt::format("{} particle {} (id {}) moves at {:.3g} m/s, above solver.maxSpeed = {:.3g} m/s", kind, i,
                         p.id[i], speed, model.solver.maxSpeed);
  }
  return {};
}

namespace {
template <class T>
void hashBytes(uint64_t& h, const std::vector<T>& a) {
  const auto* b = reinterpret_cast<const unsigned char*>(a.data());
  for (size_t k = 0; k < a.size() * sizeof(T); ++k) {
    h ^= b[k];
    h *= 1099511628211ull;
  }
}
template <class T>
void hashValues(uint64_t& h, std::initializer_list<T> values) {
  hashBytes(h, std::vector<T>(values));
}
}  // namespace

uint64_t stateHash(const State& state) {
  uint64_t h = 1469598103934665603ull;
  const Particles& p = state.particles;
  hashBytes(h, p.phase);
  hashBytes(h, p.id);
  hashBytes(h, p.mass);
  hashBytes(h, p.invMass);
  hashBytes(h, p.radius);
  hashBytes(h, p.x);
  hashBytes(h, p.xPred);
  hashBytes(h, p.v);
  const WaterLedger& w = state.ledger;
  hashValues(h, {w.emitted, w.removedAtBounds, w.heldInCloth, w.inBuffers, w.takenByCloth});
  hashValues(h, {w.particlesRemovedAtBounds, w.particlesAbsorbed, w.dripsEmitted, w.particlesTakenByCloth,
                 state.stepCount, uint64_t{state.nextId}, static_cast<uint64_t>(state.fluidIterations)});
  hashValues(h, {state.time});
  for (const EmitterState& e : state.emitters) {
    hashValues(h, {e.emittedLength});
    hashValues(h, {e.dropsEmitted, uint64_t{e.done}});
  }
  hashBytes(h, state.clothWater);
  hashBytes(h, state.clothBuffer);
  hashBytes(h, state.clothSaturation);
  hashBytes(h, state.dripId);
  hashBytes(h, state.dripSource);
  hashBytes(h, state.clothWetStart);
  hashBytes(h, state.clothVelocityChange);
  return h;
}

}  // namespace soak
