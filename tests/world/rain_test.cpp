// rain emitter: drop count = rate * area * time, drops inside the rectangle at the drop speed,
// deterministic and independent of dt, time window, drop mass from its radius
#include "world/emitters.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace soak {
namespace {

Model rainModel(float rate, float start = 0.0f, float end = 1.0e30f) {
  Model m;
  m.water.spacing = 0.02f;
  m.water.particleMass = 0.0082f;
  m.water.supportRadius = 0.04f;
  Emitter e;
  e.kind = EmitterKind::Rain;
  e.origin = Vec3(0.3f, 2.5f, -0.2f);
  e.halfExtents = Vec3(0.5f, 0.0f, 0.25f);  // 0.5 m^2
  e.rate = rate;
  e.dropSpeed = 6.5f;
  e.direction = Vec3(0, -1, 0);
  e.start = start;
  e.end = end;
  m.emitters.push_back(e);
  return m;
}

size_t run(const Model& m, State& s, double dt, int n) {
  size_t total = 0;
  for (int k = 0; k < n; ++k) total += emitWater(m, s, k * dt, static_cast<float>(dt));
  return total;
}

TEST(RainEmitter, EmitsRateTimesAreaTimesDuration) {
  const Model m = rainModel(500.0f);  // 250 drops per second over 0.5 m^2
  State s;
  const size_t n = run(m, s, 0.01, 100);
  EXPECT_NEAR(static_cast<double>(n), 250.0, 1.0);
  EXPECT_EQ(s.particles.size(), n);
  EXPECT_NEAR(s.ledger.emitted, static_cast<double>(n) * m.water.particleMass, 1e-9);
  // a further 0.6 s adds 150 more
  const size_t more = [&] {
    size_t total = 0;
    for (int k = 100; k < 160; ++k) total += emitWater(m, s, k * 0.01, 0.01f);
    return total;
  }();
  EXPECT_NEAR(static_cast<double>(n + more), 400.0, 1.0);
}

TEST(RainEmitter, DropsInsideTheRectangleFallingAtTheDropSpeed) {
  const Model m = rainModel(2000.0f);
  const Emitter& e = m.emitters[0];
  State s;
  const double dt = 0.02;
  for (int k = 0; k < 20; ++k) {
    const size_t before = s.particles.size();
    emitWater(m, s, k * dt, static_cast<float>(dt));
    for (size_t i = before; i < s.particles.size(); ++i) {
      const Vec3& x = s.particles.x[i];
      EXPECT_LE(std::fabs(x.x() - e.origin.x()), e.halfExtents.x());
      EXPECT_LE(std::fabs(x.z() - e.origin.z()), e.halfExtents.z());
      // born during the step, so at most one step of fall below the rectangle
      EXPECT_LE(x.y(), e.origin.y() + 1e-5f);
      EXPECT_GE(x.y(), e.origin.y() - e.dropSpeed * static_cast<float>(dt) - 1e-4f);
      EXPECT_NEAR((s.particles.v[i] - Vec3(0, -6.5f, 0)).norm(), 0.0f, 1e-5f);
      EXPECT_EQ(s.particles.phase[i], kWaterPhase);
    }
  }
  ASSERT_GT(s.particles.size(), 350u);
  // evenly spread: each quadrant of the rectangle gets a quarter of the drops (4 sigma)
  int quadrant[4] = {0, 0, 0, 0};
  for (size_t i = 0; i < s.particles.size(); ++i) {
    const Vec3 r = s.particles.x[i] - e.origin;
    ++quadrant[(r.x() > 0.0f ? 1 : 0) + (r.z() > 0.0f ? 2 : 0)];
  }
  const double n = static_cast<double>(s.particles.size()), sigma = std::sqrt(n * 0.25 * 0.75);
  for (int q = 0; q < 4; ++q) EXPECT_NEAR(quadrant[q], n / 4.0, 4.0 * sigma) << "quadrant " << q;
}

TEST(RainEmitter, SameDropsForAnyStepAndEveryRun) {
  const Model m = rainModel(400.0f);
  State a, b, c;
  // steps exact in binary, so both runs reach t = 0.5 exactly
  run(m, a, 1.0 / 64.0, 32);
  run(m, b, 1.0 / 128.0, 64);
  run(m, c, 1.0 / 64.0, 32);
  EXPECT_EQ(a.particles.size(), 100u);
  ASSERT_EQ(a.particles.size(), b.particles.size());
  ASSERT_EQ(a.particles.size(), c.particles.size());
  for (size_t i = 0; i < a.particles.size(); ++i) {
    EXPECT_EQ(a.particles.x[i], c.particles.x[i]);
    // drop i lands on the same spot of the rectangle whatever the step
    EXPECT_EQ(a.particles.x[i].x(), b.particles.x[i].x());
    EXPECT_EQ(a.particles.x[i].z(), b.particles.x[i].z());
  }
  // a second rain emitter is another sequence
  Model two = m;
  two.emitters.push_back(m.emitters[0]);
  State d;
  run(two, d, 1.0 / 64.0, 32);
  ASSERT_EQ(d.particles.size(), 2 * a.particles.size());
  int same = 0;
  for (size_t i = 0; i < d.particles.size(); i += 2) same += d.particles.x[i] == d.particles.x[i + 1];
  EXPECT_EQ(same, 0);
}

TEST(RainEmitter, OnlyInsideItsTimeWindow) {
  const Model m = rainModel(1000.0f, 0.2f, 0.5f);  // 500 drops per second
  State s;
  EXPECT_EQ(run(m, s, 0.01, 20), 0u);  // t in [0, 0.2)
  size_t n = 0;
  for (int k = 20; k < 60; ++k) n += emitWater(m, s, k * 0.01, 0.01f);
  EXPECT_NEAR(static_cast<double>(n), 150.0, 1.0);
  EXPECT_TRUE(s.emitters[0].done);
}

TEST(RainEmitter, DropRadiusSetsMassAndSupportRadius) {
  Model m = rainModel(1000.0f);
  m.emitters[0].dropRadius = 0.002f;
  State s;
  const size_t n = run(m, s, 0.01, 10);
  ASSERT_GT(n, 0u);
  const double mass = 1000.0 * 4.0 / 3.0 * M_PI * 0.002 * 0.002 * 0.002;
  EXPECT_NEAR(s.particles.mass[0], mass, 1e-9);
  EXPECT_NEAR(s.particles.radius[0], 0.04 * std::cbrt(mass / 0.0082), 1e-6);
  EXPECT_NEAR(s.ledger.emitted, static_cast<double>(n) * mass, 1e-9);
}

TEST(RainEmitter, StopsAtTheParticleCap) {
  Model m = rainModel(1000.0f);
  m.solver.maxParticles = 30;
  State s;
  run(m, s, 0.01, 100);
  EXPECT_EQ(s.particles.size(), 30u);
}

}  // namespace
}  // namespace soak
