// water emitters: block lattice, jet discs evenly spaced at the jet speed, timing, particle cap
#include "world/emitters.hpp"

#include <soak/scene.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

namespace soak {
namespace {

Model blockModel() {
  Model m;
  m.water.spacing = 0.02f;
  m.water.particleMass = 0.0082f;
  m.water.supportRadius = 0.04f;
  Emitter e;
  e.kind = EmitterKind::Block;
  e.boxMin = Vec3(0.3f, 1.0f, -0.05f);
  e.boxMax = Vec3(0.402f, 1.102f, 0.052f);  // 5 sites a side, with room for the rest spacing
  e.velocity = Vec3(0, -1, 0.5f);
  e.start = 0.0f;
  m.emitters.push_back(e);
  return m;
}

Model jetModel(const Vec3& direction) {
  Model m;
  m.water.spacing = 0.02f;
  m.water.particleMass = 0.0082f;
  Emitter e;
  e.kind = EmitterKind::Jet;
  e.origin = Vec3(0.1f, 2.0f, -0.3f);
  e.direction = direction.normalized();
  e.speed = 4.0f;
  e.radius = 0.05f;
  m.emitters.push_back(e);
  return m;
}

// runs the emitter from t = 0 over n steps of dt; returns the total created
size_t run(const Model& m, State& s, float dt, int n) {
  size_t total = 0;
  for (int k = 0; k < n; ++k) total += emitWater(m, s, k * static_cast<double>(dt), dt);
  return total;
}

TEST(EmitterBlock, FillsTheBoxOnASpacingLattice) {
  const Model m = blockModel();
  State s;
  s.nextId = 7;
  s.particles.add(1, 0, 0.006f, 0.0f, Vec3::Zero(), Vec3::Zero());  // a cloth particle already there
  const size_t n = emitWater(m, s, 0.0, 0.01f);
  ASSERT_EQ(n, 125u);
  ASSERT_EQ(s.particles.size(), 126u);
  ASSERT_EQ(s.emitters.size(), 1u);
  EXPECT_TRUE(s.emitters[0].done);
  EXPECT_EQ(s.nextId, 7u + 125u);
  std::set<std::array<long, 3>> sites;
  for (size_t i = 1; i < s.particles.size(); ++i) {
    EXPECT_EQ(s.particles.id[i], 7u + (i - 1));
    EXPECT_EQ(s.particles.phase[i], kWaterPhase);
    EXPECT_FLOAT_EQ(s.particles.mass[i], m.water.particleMass);
    EXPECT_FLOAT_EQ(s.particles.invMass[i], 1.0f / m.water.particleMass);
    EXPECT_FLOAT_EQ(s.particles.radius[i], m.water.supportRadius);
    EXPECT_EQ(s.particles.v[i], m.emitters[0].velocity);
    // 5 sites a side (as many as fit at the spacing), at the rest spacing about the box's centre
    const Vec3 centre = 0.5f * (m.emitters[0].boxMin + m.emitters[0].boxMax);
    const Vec3 rel = (s.particles.x[i] - centre) / restLatticeSpacing(m.water) + Vec3::Constant(2.0f);
    std::array<long, 3> site{};
    for (int a = 0; a < 3; ++a) {
      site[a] = std::lround(rel[a]);
      EXPECT_NEAR(rel[a], static_cast<float>(site[a]), 1e-3f);
      EXPECT_GE(site[a], 0);
      EXPECT_LE(site[a], 4);
    }
    sites.insert(site);
  }
  EXPECT_EQ(sites.size(), 125u);  // no two particles on one site
  EXPECT_NEAR(s.ledger.emitted, 125.0 * m.water.particleMass, 1e-9);
  // emitted once only
  EXPECT_EQ(emitWater(m, s, 0.01, 0.01f), 0u);
  EXPECT_EQ(s.particles.size(), 126u);
}

TEST(EmitterBlock, LaidOutAtTheSpacingOfRestDensity) {
  const Model m = blockModel();
  // Table 1's mass at its spacing sums to more than the rest density: a block laid out there starts
  // compressed and flies apart
  EXPECT_GT(latticeDensity(m.water, m.water.spacing), 1.02f * m.water.restDensity);
  const float rest = restLatticeSpacing(m.water);
  EXPECT_NEAR(latticeDensity(m.water, rest), m.water.restDensity, 1e-3f * m.water.restDensity);
  EXPECT_GT(rest, m.water.spacing);
  EXPECT_LT(rest, 1.03f * m.water.spacing);
}

TEST(EmitterBlock, ABoxWithoutRoomKeepsTheSpacingAndItsParticlesInside) {
  Model m = blockModel();
  m.emitters[0].boxMax = Vec3(0.4f, 1.1f, 0.05f);  // exactly 5 spacings a side, as a pool filling its container
  State s;
  ASSERT_EQ(emitWater(m, s, 0.0, 0.01f), 125u);
  for (size_t i = 0; i < s.particles.size(); ++i) {
    const Vec3 rel = (s.particles.x[i] - m.emitters[0].boxMin) / m.water.spacing - Vec3::Constant(0.5f);
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(rel[a], std::round(rel[a]), 1e-3f);
      EXPECT_GE(s.particles.x[i][a], m.emitters[0].boxMin[a] + 0.5f * m.water.spacing - 1e-5f);
      EXPECT_LE(s.particles.x[i][a], m.emitters[0].boxMax[a] - 0.5f * m.water.spacing + 1e-5f);
    }
  }
}

TEST(EmitterBlock, EmittedInTheStepHoldingItsStart) {
  Model m = blockModel();
  m.emitters[0].start = 0.1f;
  State s;
  const float dt = 0.015f;
  for (int k = 0; k < 20; ++k) {
    const double t = k * static_cast<double>(dt);
    const size_t n = emitWater(m, s, t, dt);
    const bool due = t <= 0.1 && 0.1 < t + dt;
    EXPECT_EQ(n, due ? 125u : 0u) << "t = " << t;
  }
  EXPECT_EQ(s.particles.size(), 125u);
}

TEST(EmitterBlock, MaxParticlesCapsTheTotal) {
  Model m = blockModel();
  m.solver.maxParticles = 100;
  State s;
  s.particles.add(1, 0, 0.006f, 0.0f, Vec3::Zero(), Vec3::Zero());
  EXPECT_EQ(emitWater(m, s, 0.0, 0.01f), 99u);
  EXPECT_EQ(s.particles.size(), 100u);
  EXPECT_NEAR(s.ledger.emitted, 99.0 * m.water.particleMass, 1e-9);
  EXPECT_EQ(s.nextId, 99u);
}

// the jet emits one disc per spacing travelled: after T seconds floor(speed T / spacing) discs,
// one spacing apart along the direction, every particle at speed * direction inside the radius
void checkJet(const Vec3& direction, float dt, int steps) {
  const Model m = jetModel(direction);
  const Emitter& e = m.emitters[0];
  State s;
  // discs are placed where they are at the end of the step, so the earlier ones are moved on first
  size_t total = 0;
  for (int k = 0; k < steps; ++k) {
    for (size_t i = 0; i < s.particles.size(); ++i) s.particles.x[i] += dt * s.particles.v[i];
    total += emitWater(m, s, k * static_cast<double>(dt), dt);
  }
  ASSERT_EQ(total, s.particles.size());
  // a disc of radius 0.05 on a 0.02 square lattice: the 5x5 block less its 4 corners
  const size_t perDisc = 21;
  ASSERT_GT(total, 0u);
  ASSERT_EQ(total % perDisc, 0u);
  const double T = steps * static_cast<double>(dt);
  const double expectedDiscs = std::floor(e.speed * T / m.water.spacing);
  EXPECT_NEAR(static_cast<double>(total / perDisc), expectedDiscs, 1.0);
  std::vector<float> along;
  for (size_t i = 0; i < s.particles.size(); ++i) {
    EXPECT_NEAR((s.particles.v[i] - e.speed * e.direction).norm(), 0.0f, 1e-5f);
    const Vec3 r = s.particles.x[i] - e.origin;
    const float a = r.dot(e.direction);
    EXPECT_LE((r - a * e.direction).norm(), e.radius + 1e-5f);
    // no particle is behind the nozzle or past where the jet front has got to
    EXPECT_GE(a, -1e-4f);
    EXPECT_LE(a, e.speed * T + 1e-4);
    along.push_back(a);
    EXPECT_EQ(s.particles.id[i], static_cast<uint32_t>(i));
  }
  std::sort(along.begin(), along.end());
  std::vector<float> levels;
  for (float a : along)
    if (levels.empty() || a - levels.back() > 1e-3f) levels.push_back(a);
  ASSERT_EQ(levels.size(), total / perDisc);
  for (size_t k = 1; k < levels.size(); ++k) EXPECT_NEAR(levels[k] - levels[k - 1], m.water.spacing, 1e-4f);
  EXPECT_NEAR(s.ledger.emitted, static_cast<double>(total) * m.water.particleMass, 1e-6);
}

// soak validate's count of the water the blocks will make: the particles emitBlock creates, a jet not
// counted, the total capped at solver.maxParticles
TEST(EmitterBlock, BlockParticleCountIsWhatTheBlocksEmit) {
  Model m = blockModel();
  Emitter second = m.emitters[0];
  second.boxMin = Vec3(-0.5f, 1.0f, -0.05f);
  second.boxMax = Vec3(-0.4f, 1.06f, 0.05f);
  second.start = 0.3f;
  m.emitters.push_back(second);
  Emitter jet;
  jet.kind = EmitterKind::Jet;
  m.emitters.push_back(jet);
  State state;
  state.emitters.resize(m.emitters.size());
  m.emitters.pop_back();  // the jet's particles are not the blocks'
  state.emitters.pop_back();
  const size_t emitted = emitWater(m, state, 0.0, 1.0f);
  ASSERT_EQ(emitted, 125u + 5u * 3u * 5u);
  m.emitters.push_back(jet);
  EXPECT_EQ(blockParticleCount(m), emitted);
  m.solver.maxParticles = 100;
  EXPECT_EQ(blockParticleCount(m), 100u);
}

TEST(EmitterJet, DiscsEvenlySpacedWithSmallSteps) { checkJet(Vec3(0, -1, 0), 0.001f, 100); }

TEST(EmitterJet, DiscsEvenlySpacedWhenAStepSpansSeveralSpacings) { checkJet(Vec3(1, -1, 0.5f), 0.015f, 10); }

TEST(EmitterJet, NothingOutsideStartEnd) {
  Model m = jetModel(Vec3(0, 0, 1));
  m.emitters[0].start = 0.05f;
  m.emitters[0].end = 0.1f;
  State s;
  const float dt = 0.002f;
  size_t total = 0;
  for (int k = 0; k < 100; ++k) {
    const double t = k * static_cast<double>(dt);
    const size_t n = emitWater(m, s, t, dt);
    if (t + dt <= 0.05 - 1e-9 || t >= 0.1 + 1e-9) EXPECT_EQ(n, 0u) << "t = " << t;
    total += n;
  }
  // 0.05 s at 4 m/s = 0.2 m = 10 spacings
  EXPECT_NEAR(static_cast<double>(total / 21), 10.0, 1.0);
  EXPECT_TRUE(s.emitters[0].done);
}

TEST(EmitterJet, MaxParticlesCapsTheJet) {
  Model m = jetModel(Vec3(0, -1, 0));
  m.solver.maxParticles = 50;
  State s;
  EXPECT_EQ(run(m, s, 0.01f, 50), 50u);
  EXPECT_EQ(s.particles.size(), 50u);
}

TEST(EmitterJet, DeterministicAcrossRuns) {
  const Model m = jetModel(Vec3(0.3f, -1, 0.2f));
  State a, b;
  run(m, a, 0.004f, 40);
  run(m, b, 0.004f, 40);
  ASSERT_EQ(a.particles.size(), b.particles.size());
  for (size_t i = 0; i < a.particles.size(); ++i) {
    EXPECT_EQ(a.particles.x[i], b.particles.x[i]);
    EXPECT_EQ(a.particles.id[i], b.particles.id[i]);
  }
}

}  // namespace
}  // namespace soak
