// diffusion (Eq. 12-17 as pairwise exchange): held water is conserved exactly, spreads like the 1-D
// heat kernel, and rises more slowly against gravity (Fig. 5)
#include "wetting/wet_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

using namespace soak;
using namespace soak::testing;

namespace {

Scene pinnedSheet(const Vec3& center, float w, float h, int nx, int ny, const std::string& axisV,
                  const std::string& wetting) {
  return sceneFromJson(R"({"cloth": [)" + rectangleJson("s", center, w, h, nx, ny, "[1, 0, 0]", axisV, kPinAll) +
                       R"(], "wetting": )" + wetting + "}");
}

struct Moments {
  double mass = 0, mean = 0, var = 0;
};

// moments of the held water along x
Moments moments(const Scene& s) {
  Moments m;
  const Particles& p = s.state.particles;
  for (int i = 0; i < s.model.numCloth; ++i) {
    m.mass += s.state.clothWater[i];
    m.mean += s.state.clothWater[i] * p.x[i].x();
  }
  m.mean /= m.mass;
  for (int i = 0; i < s.model.numCloth; ++i) m.var += s.state.clothWater[i] * std::pow(p.x[i].x() - m.mean, 2);
  m.var /= m.mass;
  return m;
}

// the highest row (y) of a vertical pinned sheet whose mean saturation reaches `level`
float wetFront(const Scene& s, int nx, int ny, float level) {
  float top = -1e9f;
  for (int r = 0; r < ny; ++r) {
    float mean = 0.0f;
    for (int c = 0; c < nx; ++c) mean += s.state.clothSaturation[size_t(r * nx + c)] / float(nx);
    if (mean >= level) top = std::max(top, s.state.particles.x[size_t(r * nx)].y());
  }
  return top;
}

}  // namespace

TEST(WettingDiffusion, ConservesHeldWaterExactly) {
  // a vertical sheet with a ragged saturation field, gravity on: the exchange moves water, never
  // makes or loses any
  Scene s = pinnedSheet(Vec3(0, 1, 0), 0.4f, 0.4f, 21, 21, "[0, 1, 0]", "{}");
  StageRig rig;
  rig.refresh(s.state, s.model);
  uint32_t lcg = 12345u;
  for (double& m : s.state.clothWater) {
    lcg = lcg * 1664525u + 1013904223u;
    m = 1e-3 * double(lcg >> 8) / double(1u << 24);
  }
  const double before = sum(s.state.clothWater);
  computeSaturation(s.model, s.state, rig.s, s.state.clothSaturation);
  float maxS = *std::max_element(s.state.clothSaturation.begin(), s.state.clothSaturation.end());
  for (int it = 0; it < 100; ++it) {
    diffuseWater(s.model, s.state, rig.nb, rig.s, s.model.solver.dt);
    const float m = *std::max_element(s.state.clothSaturation.begin(), s.state.clothSaturation.end());
    EXPECT_LE(m, maxS * (1.0f + 1e-6f));  // a maximum principle: no overshoot
    maxS = m;
  }
  EXPECT_NEAR(sum(s.state.clothWater), before, 1e-13 * before);
  EXPECT_GE(*std::min_element(s.state.clothWater.begin(), s.state.clothWater.end()), 0.0);
}

TEST(WettingDiffusion, SpreadsLikeTheHeatKernel) {
  // a long horizontal strip two particles wide, gravity term off: a pulse in the middle spreads with a
  // variance growing linearly in time into a Gaussian
  Scene s = pinnedSheet(Vec3(0, 1, 0), 2.0f, 0.01f, 201, 2, "[0, 0, 1]", R"({"diffusion": {"gravity": false}})");
  StageRig rig;
  rig.refresh(s.state, s.model);
  s.state.clothWater[100] = s.state.clothWater[301] = 1e-4;
  const double mass = sum(s.state.clothWater);
  double var[3];
  int done = 0;
  const int marks[3] = {100, 200, 400};
  for (int k = 0; k < 3; ++k) {
    for (; done < marks[k]; ++done) diffuseWater(s.model, s.state, rig.nb, rig.s, s.model.solver.dt);
    const Moments m = moments(s);
    EXPECT_NEAR(m.mean, 0.0, 1e-6);
    var[k] = m.var;
  }
  // var = var0 + 2 D t: doubling the time from 200 to 400 adds twice what 100 to 200 added
  EXPECT_NEAR((var[2] - var[1]) / (var[1] - var[0]), 2.0, 0.1);
  // the profile (water per column) against the Gaussian of the same mass and variance
  const double dx = 0.01, sd = std::sqrt(var[2]);
  double l1 = 0.0;
  for (int c = 0; c < 201; ++c) {
    const double x = s.state.particles.x[size_t(c)].x();
    const double column = s.state.clothWater[size_t(c)] + s.state.clothWater[size_t(201 + c)];
    const double gauss = mass * dx / (sd * std::sqrt(2.0 * kPi)) * std::exp(-0.5 * x * x / var[2]);
    l1 += std::fabs(column - gauss);
  }
  EXPECT_LT(l1 / mass, 0.05);
  EXPECT_GT(sd, 0.05);  // it did spread over many particles
  EXPECT_NEAR(sum(s.state.clothWater), mass, 1e-13 * mass);
}

TEST(WettingDiffusion, GravitySlowsTheRisingFront) {
  // a vertical strip whose bottom row is kept saturated (a reservoir): with the gravity term the water
  // climbs less high and less of it climbs (Fig. 5b against 5c)
  float front[2];
  double risen[2];
  for (int g = 0; g < 2; ++g) {
    Scene s = pinnedSheet(Vec3(0, 1, 0), 0.04f, 0.6f, 3, 31, "[0, 1, 0]",
                          std::string(R"({"diffusion": {"gravity": )") + (g ? "true" : "false") + "}}");
    StageRig rig;
    rig.refresh(s.state, s.model);
    const WettingParams& w = s.model.wetting;
    for (int it = 0; it < 400; ++it) {
      for (int c = 0; c < 3; ++c) s.state.clothWater[size_t(c)] = double(w.saturationMax) * rig.s.volume[size_t(c)] / w.c;
      diffuseWater(s.model, s.state, rig.nb, rig.s, s.model.solver.dt);
    }
    front[g] = wetFront(s, 3, 31, 0.05f * w.saturationMax);
    risen[g] = sum(s.state.clothWater);
  }
  EXPECT_LT(front[1], front[0] - 0.03f);  // at least a row and a half lower
  EXPECT_LT(risen[1], 0.92 * risen[0]);
  EXPECT_GT(front[1], 0.8f);  // it still rose
}

TEST(WettingDiffusion, DippedClothWetsLessHighWithGravity) {
  // Fig. 5 scaled down: a pinned vertical cloth dips 2 cm into a pool; the water it absorbs climbs
  // less high when the diffusion feels gravity (5c) than when it does not (5b)
  float front[2];
  for (int g = 0; g < 2; ++g) {
    Scene s = sceneFromJson(std::string(R"({"solver": {"dt": 0.015, "substeps": 1},
      "cloth": [)") + rectangleJson("s", Vec3(0, 0.3f, 0), 0.2f, 0.4f, 11, 21, "[1, 0, 0]", "[0, 1, 0]", kPinAll) +
                            R"(], "colliders": [{"type": "container", "halfExtents": [0.15, 0.1, 0.06],
                                   "position": [0, 0.1, 0]}],
      "emitters": [{"type": "block", "min": [-0.15, 0.0, -0.06], "max": [0.15, 0.12, 0.06]}],
      "wetting": {"emission": {"enabled": false}, "diffusion": {"gravity": )" + (g ? "true" : "false") + "}}}");
    runSteps(s, 200);
    front[g] = wetFront(s, 11, 21, 0.05f * s.model.wetting.saturationMax);
    EXPECT_GT(s.state.ledger.heldInCloth, 0.0);
  }
  EXPECT_GT(front[0], 0.2f);  // it wicked up above the water line (0.12 m)
  EXPECT_LT(front[1], front[0] - 0.015f);
}

// the pair terms both diffusion loops call: the exchange is antisymmetric bit for bit (what i gains
// from j is what j loses to i, with the flow's cos seen the same from both ends), flows down the
// saturation difference, and gravity speeds water going down (cos > 0) against water going up
TEST(WettingDiffusion, PairExchangeIsAntisymmetricAndGravityShaped) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const float kd = 0.02f, rho0 = 800.0f, eta = 0.5f, kappa = 0.3f;
  const double c = 4e-4;
  for (int k = 0; k < 100; ++k) {
    const float lap = 1e6f * (0.1f + u(rng)), cosIJ = 2.0f * u(rng) - 1.0f;  // cos theta_ij: i below j when > 0
    const float si = u(rng), sj = u(rng), sgi = 0.1f + u(rng), sgj = 0.1f + u(rng);
    const float vi = 1e-5f * (0.5f + u(rng)), vj = 1e-5f * (0.5f + u(rng));
    const double dIJ = double(sj) - double(si), dJI = double(si) - double(sj);
    // the flow's cos with gravity from each end, as exchangeFlows takes it (cos theta_ji = -cos theta_ij)
    const float wFromI = diffusionWeight(kd, lap, rho0, eta, dIJ > 0.0 ? cosIJ : -cosIJ);
    const float wFromJ = diffusionWeight(kd, lap, rho0, eta, dJI > 0.0 ? -cosIJ : cosIJ);
    ASSERT_EQ(wFromI, wFromJ) << k;
    const double intoI = diffusionExchange(kappa, sgi, sgj, wFromI, vi, vj, c, dIJ);
    const double intoJ = diffusionExchange(kappa, sgj, sgi, wFromJ, vj, vi, c, dJI);
    EXPECT_EQ(intoI, -intoJ) << k;
    EXPECT_GE(intoI * dIJ, 0.0) << k;  // down the saturation difference
    const double expected = double(kappa) * std::min(sgi, sgj) * double(wFromI) * std::min(vi, vj) / c * dIJ;
    EXPECT_NEAR(intoI, expected, 1e-6 * std::fabs(expected)) << k;
  }
  EXPECT_GT(diffusionWeight(kd, 1e6f, rho0, eta, 0.8f), diffusionWeight(kd, 1e6f, rho0, eta, 0.0f));
  EXPECT_LT(diffusionWeight(kd, 1e6f, rho0, eta, -0.8f), diffusionWeight(kd, 1e6f, rho0, eta, 0.0f));
  EXPECT_FLOAT_EQ(diffusionWeight(kd, 1e6f, rho0, 0.0f, 0.8f), kd * 1e6f / rho0);  // no gravity factor
}
