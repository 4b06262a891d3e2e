// whole-state diagnostics (src/sim/diagnostics.cpp): the state hash sees every array and counter of
// the State, so a determinism test cannot miss a difference in the cloth's water or the ledger
#include <soak/step.hpp>

#include "support/run_scene.hpp"

#include <gtest/gtest.h>

#include <functional>

using namespace soak;
using namespace soak::testing;

TEST(Diagnostics, StateHashSeesEveryArrayAndCounter) {
  const Scene s = sceneFromJson(R"({"cloth": [{"mesh": {"type": "rectangle", "center": [0, 1, 0], "size": [0.2, 0.2],
                                   "resolution": [5, 5]}}], "wetting": {}, "emitters": [{"type": "jet", "origin": [0, 1.5, 0]}]})");
  const uint64_t base = stateHash(s.state);
  EXPECT_EQ(stateHash(s.state), base);
  const std::vector<std::pair<const char*, std::function<void(State&)>>> changes = {
      {"x", [](State& t) { t.particles.x[3].y() += 1e-6f; }},
      {"xPred", [](State& t) { t.particles.xPred[3].y() += 1e-6f; }},
      {"v", [](State& t) { t.particles.v[3].x() = 1e-6f; }},
      {"mass", [](State& t) { t.particles.mass[3] *= 2.0f; }},
      {"invMass", [](State& t) { t.particles.invMass[3] *= 2.0f; }},
      {"radius", [](State& t) { t.particles.radius[3] *= 2.0f; }},
      {"id", [](State& t) { t.particles.id[3] += 100; }},
      {"phase", [](State& t) { t.particles.phase[3] = 7; }},
      {"time", [](State& t) { t.time += 1e-9; }},
      {"stepCount", [](State& t) { ++t.stepCount; }},
      {"nextId", [](State& t) { ++t.nextId; }},
      {"ledger.emitted", [](State& t) { t.ledger.emitted += 1e-9; }},
      {"ledger.heldInCloth", [](State& t) { t.ledger.heldInCloth += 1e-9; }},
      {"ledger.dripsEmitted", [](State& t) { ++t.ledger.dripsEmitted; }},
      {"emitters", [](State& t) { t.emitters[0].emittedLength += 1e-9; }},
      {"clothWater", [](State& t) { t.clothWater[3] += 1e-12; }},
      {"clothBuffer", [](State& t) { t.clothBuffer[3] += 1e-12; }},
      {"clothSaturation", [](State& t) { t.clothSaturation[3] += 1e-6f; }},
      {"drips", [](State& t) { t.dripId.push_back(1), t.dripSource.push_back(3); }},
      {"clothWetStart", [](State& t) { t.clothWetStart.assign(t.particles.size(), 0.0f); }},
  };
  for (const auto& [name, change] : changes) {
    State t = s.state;
    change(t);
    EXPECT_NE(stateHash(t), base) << name;
  }
}
