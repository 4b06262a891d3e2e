#include "grid/reorder.hpp"

#include "core/parallel.hpp"

#include <gtest/gtest.h>

#include <map>
#include <random>

using namespace soak;

namespace {

// cloth-like particles first (phase 1), then water in a random order with distinct data per particle
Particles randomParticles(size_t numCloth, size_t numWater, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-0.5f, 0.5f);
  Particles p;
  for (size_t i = 0; i < numCloth + numWater; ++i) {
    const bool water = i >= numCloth;
    const Vec3 x(u(rng), u(rng), u(rng));
    p.add(water ? 0 : 1, static_cast<uint32_t>(i), 0.001f * (1.0f + float(i)), 0.04f + 1e-6f * float(i), x,
          Vec3(float(i), -float(i), 0.5f * float(i)));
    p.xPred.back() = x + Vec3(0.01f, 0.0f, 0.0f);
  }
  return p;
}

struct Record {
  int32_t phase;
  float mass, invMass, radius;
  Vec3 x, xPred, v;
};

std::map<uint32_t, Record> byId(const Particles& p) {
  std::map<uint32_t, Record> out;
  for (size_t i = 0; i < p.size(); ++i)
    out[p.id[i]] = {p.phase[i], p.mass[i], p.invMass[i], p.radius[i], p.x[i], p.xPred[i], p.v[i]};
  return out;
}

}  // namespace

TEST(Reorder, MortonCodeInterleavesAxes) {
  EXPECT_EQ(mortonCode(0, 0, 0), 0u);
  EXPECT_EQ(mortonCode(1, 0, 0), 1u);
  EXPECT_EQ(mortonCode(0, 1, 0), 2u);
  EXPECT_EQ(mortonCode(0, 0, 1), 4u);
  EXPECT_EQ(mortonCode(3, 3, 3), 63u);
  EXPECT_EQ(mortonCode(5000, 0, 0), mortonCode(1023, 0, 0));  // clamped
}

TEST(Reorder, KeepsEveryParticlesDataTogetherAndClothInPlace) {
  Particles p = randomParticles(300, 4000, 3);
  const Particles before = p;
  const auto records = byId(p);
  ReorderScratch scratch;
  ASSERT_TRUE(sortParticlesByCell(p, 300, 0.04f, scratch));
  ASSERT_EQ(p.size(), before.size());
  // cloth untouched, in its order
  for (size_t i = 0; i < 300; ++i) {
    EXPECT_EQ(p.id[i], before.id[i]);
    EXPECT_EQ(p.x[i], before.x[i]);
  }
  // every id once, with all of its data
  EXPECT_EQ(byId(p).size(), records.size());
  for (size_t i = 0; i < p.size(); ++i) {
    const Record& r = records.at(p.id[i]);
    EXPECT_EQ(p.phase[i], r.phase);
    EXPECT_EQ(p.mass[i], r.mass);
    EXPECT_EQ(p.invMass[i], r.invMass);
    EXPECT_EQ(p.radius[i], r.radius);
    EXPECT_EQ(p.x[i], r.x);
    EXPECT_EQ(p.xPred[i], r.xPred);
    EXPECT_EQ(p.v[i], r.v);
  }
  // the water is now in ascending Morton order of its cells
  Vec3 lo = p.x[300];
  for (size_t i = 301; i < p.size(); ++i) lo = lo.cwiseMin(p.x[i]);
  uint32_t last = 0;
  for (size_t i = 300; i < p.size(); ++i) {
    const Vec3 c = ((p.x[i] - lo) / 0.04f).array().floor();
    const uint32_t code = mortonCode(uint32_t(c.x()), uint32_t(c.y()), uint32_t(c.z()));
    EXPECT_LE(last, code) << "particle " << i;
    last = code;
  }
  // sorted water is left as it is
  EXPECT_FALSE(sortParticlesByCell(p, 300, 0.04f, scratch));
}

TEST(Reorder, SameOrderForAnyThreadCount) {
  Particles a = randomParticles(100, 20000, 5), b = a;
  ReorderScratch sa, sb;
  setThreadCount(1);
  sortParticlesByCell(a, 100, 0.04f, sa);
  setThreadCount(2);
  sortParticlesByCell(b, 100, 0.04f, sb);
  EXPECT_EQ(a.id, b.id);
  EXPECT_EQ(a.x, b.x);
}

TEST(Reorder, EqualCellsKeepTheirOrder) {
  Particles p;
  // four particles in one cell, then one in a lower cell: it moves first, the four keep their order
  for (uint32_t k = 0; k < 4; ++k) p.add(0, 10 + k, 1.0f, 0.04f, Vec3(0.5f + 0.001f * float(k), 0.5f, 0.5f), Vec3::Zero());
  p.add(0, 99, 1.0f, 0.04f, Vec3(0.0f, 0.0f, 0.0f), Vec3::Zero());
  ReorderScratch scratch;
  sortParticlesByCell(p, 0, 0.04f, scratch);
  EXPECT_EQ(p.id, (std::vector<uint32_t>{99, 10, 11, 12, 13}));
}
