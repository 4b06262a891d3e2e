// diffusion (Eq. 12-17 as a rate in time with a capillary equilibrium): held water is conserved
// exactly, spreads like the heat kernel with the diffusivity D, rises as sqrt(t) and levels off at the
// wicking height, the same for any dt or iteration count, and never above S^MAX
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
  for (int it = 0; it < 100; ++it) {
    EXPECT_GT(diffuseWater(s.model, s.state, rig.nb, rig.s, s.model.solver.dt), 0);
    const float m = *std::max_element(s.state.clothSaturation.begin(), s.state.clothSaturation.end());
    EXPECT_LE(m, s.model.wetting.saturationMax * (1.0f + 1e-6f));  // the drift fills no particle past S^MAX
  }
  for (int i = 0; i < s.model.numCloth; ++i)  // the mass followed the water
    EXPECT_EQ(s.state.particles.mass[i], s.model.clothDryMass[i] + float(s.state.clothWater[i] + s.state.clothBuffer[i]));
  EXPECT_NEAR(sum(s.state.clothWater), before, 1e-13 * before);
  EXPECT_GE(*std::min_element(s.state.clothWater.begin(), s.state.clothWater.end()), 0.0);
}

TEST(WettingDiffusion, SpreadsLikeTheHeatKernelWithDiffusivityD) {
  // a horizontal sheet, a pulse in the middle: its variance along x grows as 2 D t (D in m^2/s), for
  // any dt, and the profile along x is the Gaussian of that variance
  const float D = 1e-3f;
  double rate[2];
  for (int k = 0; k < 2; ++k) {
    const float dt = k == 0 ? 0.015f : 0.03f;
    Scene s = pinnedSheet(Vec3(0, 1, 0), 0.6f, 0.6f, 61, 61, "[0, 0, 1]",
                          "{\"emission\": {\"enabled\": false}, \"diffusion\": {\"diffusivity\": " + std::to_string(D) + "}}");
    StageRig rig;
    rig.refresh(s.state, s.model);
    s.state.clothWater[30 * 61 + 30] = 1e-4;
    const double mass = sum(s.state.clothWater);
    const int steps = int(std::lround(0.3 / dt));
    for (int it = 0; it < steps; ++it) diffuseWater(s.model, s.state, rig.nb, rig.s, dt);
    const double v1 = moments(s).var;
    for (int it = 0; it < 2 * steps; ++it) diffuseWater(s.model, s.state, rig.nb, rig.s, dt);
    const Moments m = moments(s);
    EXPECT_NEAR(m.mean, 0.0, 1e-6);
    rate[k] = (m.var - v1) / (2.0 * 0.6);  // (var(0.9 s) - var(0.3 s)) / 2 t
    EXPECT_NEAR(rate[k], D, 0.05 * D) << "dt " << dt;
    double l1 = 0.0;  // water per column against the Gaussian of that mass and variance
    for (int c = 0; c < 61; ++c) {
      double column = 0.0;
      for (int r = 0; r < 61; ++r) column += s.state.clothWater[size_t(r * 61 + c)];
      const double x = s.state.particles.x[size_t(c)].x();
      l1 += std::fabs(column - mass * 0.01 / std::sqrt(2.0 * kPi * m.var) * std::exp(-0.5 * x * x / m.var));
    }
    EXPECT_LT(l1 / mass, 0.05);
    EXPECT_NEAR(sum(s.state.clothWater), mass, 1e-12 * mass);
  }
  EXPECT_NEAR(rate[1], rate[0], 0.02 * rate[0]);
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
    front[g] = wetFront(s, 11, 21, 0.5f * s.model.wetting.saturationMax);
    EXPECT_GT(s.state.ledger.heldInCloth, 0.0);
  }
  EXPECT_GT(front[0], 0.2f);  // it wicked up above the water line (0.12 m)
  EXPECT_LT(front[1], front[0] - 0.015f);
}

// the pair flow both sides compute: antisymmetric bit for bit (what i gains from j is what j loses to
// i), down the saturation difference without gravity, sped up going down and slowed going up, and
// zero at the capillary equilibrium S_i = S_j (1 + lambda (z_j - z_i))
TEST(WettingDiffusion, PairFlowIsAntisymmetricAndGravityShaped) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const float eta = 0.4f, lambda = std::log(2.0f) / 0.2f;
  for (int k = 0; k < 1000; ++k) {
    const float t = 1e-3f * (0.1f + u(rng)), cosIJ = 2.0f * u(rng) - 1.0f;  // cos theta_ij: i below j when > 0
    const float si = 0.4f * u(rng), sj = 0.4f * u(rng), rise = 0.04f * (2.0f * u(rng) - 1.0f);
    const double intoI = diffusionFlow(0.01, t, eta, cosIJ, si, sj, lambda, rise);
    const double intoJ = diffusionFlow(0.01, t, eta, -cosIJ, sj, si, lambda, -rise);
    EXPECT_EQ(intoI, -intoJ) << k;
    const double flat = diffusionFlow(0.01, t, 0.0f, cosIJ, si, sj, 0.0f, rise);
    EXPECT_GE(flat * (double(sj) - si), 0.0) << k;  // no gravity: down the saturation difference
  }
  EXPECT_GT(diffusionFlow(1.0, 1.0f, eta, 0.8f, 0.1f, 0.2f, 0.0f, 0.0f), diffusionFlow(1.0, 1.0f, eta, 0.0f, 0.1f, 0.2f, 0.0f, 0.0f));
  EXPECT_LT(diffusionFlow(1.0, 1.0f, eta, -0.8f, 0.1f, 0.2f, 0.0f, 0.0f), diffusionFlow(1.0, 1.0f, eta, 0.0f, 0.1f, 0.2f, 0.0f, 0.0f));
  // equal saturations: the upper particle's water drifts down; S_i = S_j (1 + lambda rise): no flow
  EXPECT_GT(diffusionFlow(1.0, 1.0f, 0.0f, 1.0f, 0.2f, 0.2f, lambda, 0.01f), 0.0);
  EXPECT_NEAR(diffusionFlow(1.0, 1.0f, 0.0f, 1.0f, 0.2f * (1.0f + lambda * 0.01f), 0.2f, lambda, 0.01f), 0.0, 1e-7);
}

namespace {

// a vertical pinned strip (0.04 m wide, 1 m tall) whose bottom row is kept at S^MAX (a pool): the
// height above that row of the front (half S^MAX, interpolated between rows) at each time of `at`
std::vector<double> dippedStripFront(float dt, int iterations, const std::vector<double>& at, float D = 0.01f,
                                     float H = 0.2f, bool gravity = true) {
  Scene s = pinnedSheet(Vec3(0, 0.5f, 0), 0.04f, 1.0f, 5, 101, "[0, 1, 0]",
                        R"({"emission": {"enabled": false}, "diffusion": {"diffusivity": )" + std::to_string(D) +
                            R"(, "wickingHeight": )" + std::to_string(H) + R"(, "gravity": )" +
                            (gravity ? "true" : "false") + R"(, "iterations": )" + std::to_string(iterations) + "}}");
  StageRig rig;
  rig.refresh(s.state, s.model);
  const WettingParams& w = s.model.wetting;
  std::vector<double> fronts;
  double t = 0.0;
  for (const double until : at) {
    for (; t < until - 1e-9; t += dt) {
      for (int c = 0; c < 5; ++c) s.state.clothWater[size_t(c)] = double(w.saturationMax) * rig.s.volume[size_t(c)] / w.c;
      diffuseWater(s.model, s.state, rig.nb, rig.s, dt);
    }
    const float level = 0.5f * w.saturationMax;
    double front = 0.0;
    for (int r = 1; r < 101; ++r) {
      float row = 0.0f, below = 0.0f;
      for (int c = 0; c < 5; ++c) row += s.state.clothSaturation[size_t(r * 5 + c)] / 5.0f,
                                 below += s.state.clothSaturation[size_t((r - 1) * 5 + c)] / 5.0f;
      if (row < level) {
        front = 0.01 * (r - 1) + 0.01 * (below - level) / (below - row);
        break;
      }
    }
    fronts.push_back(front);
  }
  return fronts;
}

}  // namespace

TEST(WettingDiffusion, WickingFrontIsTheSameForAnyDtOrIterations) {
  // issue 22: the front at a fixed time moves by at most 10% when dt is halved or doubled or the
  // iterations doubled
  const double ref = dippedStripFront(0.015f, 1, {1.5})[0];
  EXPECT_GT(ref, 0.05);
  for (const auto& [dt, it] : {std::pair{0.0075f, 1}, std::pair{0.03f, 1}, std::pair{0.015f, 2}}) {
    const double f = dippedStripFront(dt, it, {1.5})[0];
    EXPECT_NEAR(f, ref, 0.05 * ref) << "dt " << dt << ", iterations " << it;
  }
}

TEST(WettingDiffusion, WicksAsSqrtTThenLevelsOffAtTheWickingHeight) {
  // Lucas-Washburn: without gravity the front rises as sqrt(t); with it, at capillary equilibrium S
  // halves every wickingHeight (0.1 m) of height, so the half-saturation front stops there
  const std::vector<double> free = dippedStripFront(0.03f, 1, {0.5, 2.0}, 0.02f, 0.1f, false);
  EXPECT_NEAR(std::log(free[1] / free[0]) / std::log(4.0), 0.5, 0.1) << free[0] << " " << free[1];
  const std::vector<double> f = dippedStripFront(0.03f, 1, {2.0, 10.0, 15.0}, 0.02f, 0.1f);
  EXPECT_LT(f[0], free[1]);  // gravity holds it back
  EXPECT_NEAR(f[1], 0.1, 0.01);
  EXPECT_NEAR(f[2], f[1], 0.02 * f[1]);  // levelled off
}

TEST(WettingDiffusion, NeverFillsAParticlePastSMax) {
  // a vertical sheet near S^MAX everywhere: the drift down would overfill the lower rows; they take
  // only what fits
  Scene s = pinnedSheet(Vec3(0, 1, 0), 0.2f, 0.4f, 11, 21, "[0, 1, 0]", R"({"diffusion": {"wickingHeight": 0.05}})");
  StageRig rig;
  rig.refresh(s.state, s.model);
  const WettingParams& w = s.model.wetting;
  for (int i = 0; i < s.model.numCloth; ++i)
    s.state.clothWater[size_t(i)] = (0.9 + 0.1 * (i % 3) / 2.0) * w.saturationMax * rig.s.volume[size_t(i)] / w.c;
  const double before = sum(s.state.clothWater);
  for (int it = 0; it < 50; ++it) diffuseWater(s.model, s.state, rig.nb, rig.s, 0.03f);
  EXPECT_LE(*std::max_element(s.state.clothSaturation.begin(), s.state.clothSaturation.end()),
            w.saturationMax * (1.0f + 1e-6f));
  EXPECT_NEAR(sum(s.state.clothWater), before, 1e-12 * before);
}
