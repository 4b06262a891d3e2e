// the particle arrays (core/particles.cpp): appending sets the inverse mass and the predicted position,
// resizing and compaction keep every array the same length, and compaction is stable across all of them
#include <soak/state.hpp>

#include <gtest/gtest.h>

#include <vector>

namespace soak {
namespace {

// particle k of a test set: every field a different function of k, so a field mixed up with another, or
// an element moved to the wrong place, shows
void addTestParticle(Particles& p, int k) {
  p.add(k % 3, uint32_t(100 + k), 0.5f + k, 0.01f * (k + 1), Vec3(float(k), 2.0f * k, -1.0f * k),
        Vec3(0.5f * k, 0.0f, 1.0f));
}

void expectParticle(const Particles& p, size_t i, int k) {
  EXPECT_EQ(p.phase[i], k % 3) << i;
  EXPECT_EQ(p.id[i], uint32_t(100 + k)) << i;
  EXPECT_EQ(p.mass[i], 0.5f + k) << i;
  EXPECT_EQ(p.invMass[i], 1.0f / (0.5f + k)) << i;
  EXPECT_EQ(p.radius[i], 0.01f * (k + 1)) << i;
  EXPECT_EQ(p.x[i], Vec3(float(k), 2.0f * k, -1.0f * k)) << i;
  EXPECT_EQ(p.xPred[i], p.x[i]) << i;
  EXPECT_EQ(p.v[i], Vec3(0.5f * k, 0.0f, 1.0f)) << i;
}

void expectSizes(const Particles& p, size_t n) {
  EXPECT_EQ(p.size(), n);
  for (size_t s : {p.phase.size(), p.id.size(), p.mass.size(), p.invMass.size(), p.radius.size(), p.x.size(),
                   p.xPred.size(), p.v.size()})
    EXPECT_EQ(s, n);
}

// add returns the new index and fills every array: invMass = 1/m (0 for a massless particle), x* = x
TEST(CoreParticles, AddFillsEveryArray) {
  Particles p;
  for (int k = 0; k < 4; ++k) {
    Particles q = p;
    addTestParticle(q, k);
    EXPECT_EQ(q.size(), size_t(k) + 1);
    addTestParticle(p, k);
  }
  expectSizes(p, 4);
  for (int k = 0; k < 4; ++k) expectParticle(p, size_t(k), k);
  EXPECT_EQ(p.add(0, 7, 0.0f, 0.04f, Vec3::Zero(), Vec3::Zero()), 4u);
  EXPECT_EQ(p.invMass[4], 0.0f);
  // setMass: the inverse with it, 0 for a kinematic particle
  p.setMass(1, 4.0f, false);
  EXPECT_EQ(p.mass[1], 4.0f);
  EXPECT_EQ(p.invMass[1], 0.25f);
  p.setMass(1, 4.0f, true);
  EXPECT_EQ(p.invMass[1], 0.0f);
}

// compact keeps the particles marked, in their order, with all their fields together
TEST(CoreParticles, CompactIsStableAcrossEveryArray) {
  Particles p;
  for (int k = 0; k < 10; ++k) addTestParticle(p, k);
  const std::vector<uint8_t> keep{1, 0, 0, 1, 1, 0, 1, 0, 0, 1};
  p.compact(keep);
  expectSizes(p, 5);
  const int kept[] = {0, 3, 4, 6, 9};
  for (size_t i = 0; i < 5; ++i) expectParticle(p, i, kept[i]);
  p.compact(std::vector<uint8_t>(5, 1));  // keeping all changes nothing
  for (size_t i = 0; i < 5; ++i) expectParticle(p, i, kept[i]);
  p.compact(std::vector<uint8_t>(5, 0));
  expectSizes(p, 0);
}

// resize grows or shrinks every array together, keeping the first particles
TEST(CoreParticles, ResizeKeepsTheArraysTogether) {
  Particles p;
  for (int k = 0; k < 6; ++k) addTestParticle(p, k);
  p.resize(3);
  expectSizes(p, 3);
  for (int k = 0; k < 3; ++k) expectParticle(p, size_t(k), k);
  p.resize(8);
  expectSizes(p, 8);
  expectParticle(p, 2, 2);
}

}  // namespace
}  // namespace soak
