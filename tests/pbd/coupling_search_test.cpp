// the coupling's candidate search (src/pbd/coupling_search.cpp): every triangle a water particle's
// path comes within reach of, exactly, the same for any thread count, and the side it is held on
#include "support/run_scene.hpp"

#include "pbd/coupling.hpp"

#include <soak/threads.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

using namespace soak;
using namespace soak::testing;

namespace {
// distance from x to the segment a -> b
float segmentDistance(const Vec3& x, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const float len2 = ab.squaredNorm();
  const float u = len2 > 0.0f ? std::clamp((x - a).dot(ab) / len2, 0.0f, 1.0f) : 0.0f;
  return (x - (a + u * ab)).norm();
}

// a wavy 25 x 25 sheet and 1200 water particles on random paths through and beside it
Scene sheetWithPaths() {
  Scene scene = sceneFromJson(R"({
    "solver": {"gravity": [0, 0, 0], "domain": {"min": [-1, -1, -1], "max": [1, 1, 1]}},
    "cloth": [{"mesh": {"type": "rectangle", "center": [0, 0, 0], "size": [0.2, 0.2], "resolution": [25, 25],
               "axisU": [1, 0, 0], "axisV": [0, 0, 1]}}]
  })");
  Particles& p = scene.state.particles;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-0.11f, 0.11f), dy(-0.004f, 0.004f), step(-0.01f, 0.01f);
  for (int i = 0; i < scene.model.numCloth; ++i) {
    p.x[i].y() = 0.01f * std::sin(40.0f * p.x[i].x()) * std::cos(30.0f * p.x[i].z());
    p.xPred[i] = p.x[i] + Vec3(0.0f, dy(rng), 0.0f);  // the sheet moved a little this substep
  }
  for (int k = 0; k < 1200; ++k) {
    const Vec3 from(u(rng), 3.0f * dy(rng) + 0.005f, u(rng));
    // every third a small drop (partly absorbed): its own reach (h_q + h_cloth) / 2 is then the shorter
    const float h = k % 3 == 0 ? 0.1f * scene.model.water.supportRadius : scene.model.water.supportRadius;
    p.add(kWaterPhase, 1000, scene.model.water.particleMass, h, from, Vec3::Zero());
    p.xPred.back() = from + Vec3(step(rng), 2.0f * step(rng), step(rng));
  }
  return scene;
}
}  // namespace

// a triangle is a candidate of water particle q exactly when one of its corners j (at its predicted
// position) lies within min((h_q + h_cloth) / 2, reach_j) of q's path x_q -> x*_q, and it is not
// degenerate: the grid walk neither misses one nor adds one
TEST(CouplingSearch, CandidatesAreTheTrianglesOfTheClothParticlesWithinReachOfThePath) {
  Scene scene = sheetWithPaths();
  const Model& model = scene.model;
  const Particles& p = scene.state.particles;
  CouplingScratch s;
  findCouplingCandidates(model, p, s);
  const int nc = model.numCloth, nw = static_cast<int>(p.size()) - nc;
  ASSERT_EQ(s.candidateStart.size(), static_cast<size_t>(nw) + 1);
  size_t withCandidates = 0, total = 0, byOwnReach = 0;
  for (int w = 0; w < nw; ++w) {
    const size_t q = static_cast<size_t>(nc + w);
    const float reachQ = 0.5f * (p.radius[q] + s.clothRadius);
    std::set<uint32_t> expected;
    for (int j = 0; j < nc; ++j) {
      const float d = segmentDistance(p.xPred[j], p.x[q], p.xPred[q]);
      if (d >= reachQ && d < s.vertexReach[j]) ++byOwnReach;  // left out by q's own reach
      if (d >= std::min(reachQ, s.vertexReach[j])) continue;
      for (int f = model.vertexTriangleStart[j]; f < model.vertexTriangleStart[j + 1]; ++f)
        expected.insert(static_cast<uint32_t>(model.vertexTriangles[f]));
    }
    const std::set<uint32_t> got(s.candidates.begin() + s.candidateStart[w], s.candidates.begin() + s.candidateStart[w + 1]);
    EXPECT_EQ(got.size(), s.candidateStart[w + 1] - s.candidateStart[w]) << "a triangle listed twice, particle " << w;
    EXPECT_EQ(got, expected) << "water particle " << w;
    withCandidates += got.empty() ? 0 : 1;
    total += got.size();
  }
  EXPECT_GT(withCandidates, 100u);  // the case is not empty
  EXPECT_GT(total, 1000u);
  EXPECT_GT(byOwnReach, 10u);  // both reaches decide somewhere
  // the active triangles are those some particle has
  std::set<uint32_t> active(s.candidates.begin(), s.candidates.end());
  EXPECT_EQ(std::set<uint32_t>(s.activeTriangles.begin(), s.activeTriangles.end()), active);
}

TEST(CouplingSearch, CandidatesAndSidesDoNotDependOnTheThreadCount) {
  Scene scene = sheetWithPaths();
  const int before = threadCount();
  CouplingScratch one, two;
  setThreadCount(1);
  findCouplingCandidates(scene.model, scene.state.particles, one);
  setThreadCount(2);
  findCouplingCandidates(scene.model, scene.state.particles, two);
  setThreadCount(before);
  EXPECT_EQ(one.candidateStart, two.candidateStart);
  EXPECT_EQ(one.candidates, two.candidates);
  EXPECT_EQ(one.candidateSide, two.candidateSide);
  EXPECT_EQ(one.particleSide, two.particleSide);
}

TEST(CouplingSearch, SideFollowsTheFaceUnderAParticleOnATightlyCurvedSheet) {
  // a sheet rolled onto a half cylinder of radius 5 cm (spacing 2 cm) and a water particle 0.3 mm
  // outside it, halfway between two vertex rows: the tangent plane at the nearest vertex passes
  // outside the particle (the sagitta s^2 / 8R is 1 mm), so that vertex's normal puts the particle on
  // the inner side while the face under it says outer. Every candidate must take the face's side: the
  // triangles beside it, given the other side, pushed the particle through the face under it
  Scene scene = sceneFromJson(R"({
    "solver": {"gravity": [0, 0, 0], "domain": {"min": [-1, -1, -1], "max": [1, 1, 1]}},
    "cloth": [{"mesh": {"type": "rectangle", "center": [0, 0, 0], "size": [0.16, 0.16], "resolution": [9, 9],
               "axisU": [1, 0, 0], "axisV": [0, 0, 1]}}]
  })");
  const float R = 0.05f, eps = 0.0003f;
  Particles& p = scene.state.particles;
  const auto roll = [&](float u, float z, float out) {  // arc length u from the top, out along the outward normal
    const float a = u / R;
    return Vec3((R + out) * std::sin(a), (R + out) * std::cos(a) - R, z);
  };
  for (int i = 0; i < scene.model.numCloth; ++i) p.x[i] = p.xPred[i] = roll(p.x[i].x(), p.x[i].z(), 0.0f);
  const Vec3 q = roll(0.01f, 0.0f, eps);  // between the vertex rows at u = 0 and 0.02, on the row z = 0
  p.add(kWaterPhase, 1000, scene.model.water.particleMass, scene.model.water.supportRadius, q, Vec3::Zero());
  p.xPred.back() = q;
  CouplingScratch s;
  findCouplingCandidates(scene.model, p, s);
  ASSERT_EQ(s.candidateStart.size(), 2u);
  const uint32_t c0 = s.candidateStart[0], c1 = s.candidateStart[1];
  ASSERT_GT(c1 - c0, 4u);
  // the side of the face under q: its chord plane lies inside the arc, so q is on the outer side
  float under = 0.0f;
  for (uint32_t c = c0; c < c1; ++c) {
    const auto& f = scene.model.triangles[s.candidates[c]];
    const Vec3 &a = p.x[f[0]], &b = p.x[f[1]], &d = p.x[f[2]];
    const Vec3 n = (b - a).cross(d - a).normalized();
    const float dist = (q - a).dot(n);
    const Vec3 foot = q - dist * n;
    // barycentric inside test of the foot point
    const Vec3 v0 = b - a, v1 = d - a, v2 = foot - a;
    const float d00 = v0.dot(v0), d01 = v0.dot(v1), d11 = v1.dot(v1), d20 = v2.dot(v0), d21 = v2.dot(v1);
    const float den = d00 * d11 - d01 * d01, v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
    if (v >= 0 && w >= 0 && v + w <= 1) under = dist > 0.0f ? 1.0f : -1.0f;
  }
  ASSERT_NE(under, 0.0f);
  for (uint32_t c = c0; c < c1; ++c) EXPECT_EQ(s.candidateSide[c], under) << "candidate triangle " << s.candidates[c];
}

