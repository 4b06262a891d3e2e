// water passing through wet cloth (wetting/permeability.cpp, Shao 2017 Eq. 22): the coupling stiffness
// kappa^couple = clamp(1 - (S~a + S~b + S~c) / (3 (S^MAX - S^T)), 0, 1) per triangle from its corners'
// saturations, and the same factor per particle on the cloth's Akinci boundary mass
#include "wetting/wet_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace soak;
using namespace soak::testing;

namespace {

// a 4 x 4 sheet with wetting on
const char* kSheet = R"({
  "cloth": [{"name": "sheet", "mesh": {"type": "rectangle", "center": [0, 1, 0], "size": [0.06, 0.06],
             "resolution": [4, 4]}}],
  "wetting": {}
})";

// Eq. 22 written out, in double
double eq22(double st, double sm, double a, double b, double c) {
  const double wet = std::max(0.0, a - st) + std::max(0.0, b - st) + std::max(0.0, c - st);
  return std::clamp(1.0 - wet / (3.0 * (sm - st)), 0.0, 1.0);
}

}  // namespace

TEST(WettingPermeability, StiffnessFallsWithSaturation) {
  const WettingParams w;
  const float st = w.saturationSticky, sm = w.saturationMax;
  EXPECT_EQ(couplingStiffness(w, 0.0f, 0.0f, 0.0f), 1.0f);
  EXPECT_EQ(couplingStiffness(w, st, st, st), 1.0f);  // below S^T the cloth is as tight as dry
  EXPECT_NEAR(couplingStiffness(w, sm, sm, sm), 0.0f, 1e-6f);
  const float half = 0.5f * (st + sm);
  EXPECT_NEAR(couplingStiffness(w, half, half, half), 0.5f, 1e-6f);
  EXPECT_NEAR(couplingStiffness(w, sm, st, st), 2.0f / 3.0f, 1e-6f);
  EXPECT_EQ(couplingStiffness(w, 1.0f, 1.0f, 1.0f), 0.0f);  // clamped
}

// mixed corners: only the part of each saturation above S^T counts, summed over the three corners, so a
// dry corner does not offset a wet one; values off the defaults (S^T 0.1, S^MAX 0.5)
TEST(WettingPermeability, MixedCornersFollowEq22) {
  WettingParams w;
  w.saturationSticky = 0.1f;
  w.saturationMax = 0.5f;
  const float cases[][3] = {{0.0f, 0.3f, 0.5f}, {0.05f, 0.05f, 0.45f}, {0.2f, 0.2f, 0.2f}, {0.5f, 0.5f, 0.3f},
                            {0.11f, 0.0f, 0.0f}, {0.9f, 0.0f, 0.0f}};
  for (const auto& s : cases)
    EXPECT_NEAR(couplingStiffness(w, s[0], s[1], s[2]), eq22(0.1, 0.5, s[0], s[1], s[2]), 1e-6)
        << s[0] << " " << s[1] << " " << s[2];
  EXPECT_NEAR(couplingStiffness(w, 0.0f, 0.3f, 0.5f), 1.0 - 0.6 / 1.2, 1e-6);  // 0.2 + 0.4 above S^T
  // the order of the corners does not matter
  EXPECT_EQ(couplingStiffness(w, 0.5f, 0.0f, 0.3f), couplingStiffness(w, 0.0f, 0.3f, 0.5f));
  // no range between S^T and S^MAX: any wet corner opens the triangle, a dry one keeps it shut
  w.saturationMax = w.saturationSticky;
  EXPECT_EQ(couplingStiffness(w, 0.1f, 0.1f, 0.1f), 1.0f);
  EXPECT_EQ(couplingStiffness(w, 0.1f, 0.1f, 0.1001f), 0.0f);
}

// every triangle gets Eq. 22 of its own three corners; with wetting off, permeability off, or no
// saturation yet, every triangle keeps the dry stiffness 1
TEST(WettingPermeability, EachTriangleFromItsCorners) {
  Scene s = sceneFromJson(kSheet);
  const Model& m = s.model;
  const WettingParams& w = m.wetting;
  ASSERT_EQ(m.numCloth, 16);
  // the first two rows (8 particles) below S^T, the rest above it and rising
  for (int i = 0; i < 16; ++i) s.state.clothSaturation[size_t(i)] = i < 8 ? 0.01f * i : 0.15f + 0.02f * (i - 8);
  std::vector<float> k;
  updateCouplingStiffness(m, s.state, k);
  ASSERT_EQ(k.size(), m.triangles.size());
  int open = 0;
  for (size_t t = 0; t < k.size(); ++t) {
    const auto& f = m.triangles[t];
    const std::vector<float>& S = s.state.clothSaturation;
    EXPECT_NEAR(k[t], eq22(w.saturationSticky, w.saturationMax, S[f[0]], S[f[1]], S[f[2]]), 1e-6) << t;
    open += k[t] < 1.0f;
  }
  ASSERT_EQ(k.size(), 18u);
  EXPECT_EQ(open, 12);  // the 6 triangles between the two dry rows stay at 1, the 12 touching a wet row open
  Model off = m;
  off.wetting.permeability = false;
  updateCouplingStiffness(off, s.state, k);
  for (float v : k) EXPECT_EQ(v, 1.0f);
  off.wetting.permeability = true;
  off.wetting.enabled = false;
  updateCouplingStiffness(off, s.state, k);
  for (float v : k) EXPECT_EQ(v, 1.0f);
  State fresh = s.state;
  fresh.clothSaturation.clear();
  updateCouplingStiffness(m, fresh, k);
  ASSERT_EQ(k.size(), m.triangles.size());
  for (float v : k) EXPECT_EQ(v, 1.0f);
}

// the Akinci boundary mass of cloth particle i is scaled by kappa^couple(S_i, S_i, S_i): 1 up to S^T,
// 0 at S^MAX, linear between; entries past the cloth (water) are untouched, as is everything when off
TEST(WettingPermeability, BoundaryMassThinsWithEachParticlesSaturation) {
  Scene s = sceneFromJson(kSheet);
  const Model& m = s.model;
  const float st = m.wetting.saturationSticky, sm = m.wetting.saturationMax;
  for (int i = 0; i < 16; ++i) s.state.clothSaturation[size_t(i)] = sm * i / 15.0f;
  std::vector<float> psi(20, 2.0f);
  scaleBoundaryByPermeability(m, s.state, psi);
  for (int i = 0; i < 16; ++i) {
    const float si = s.state.clothSaturation[size_t(i)];
    const double expected = 2.0 * (si <= st ? 1.0 : (sm - si) / (sm - st));
    EXPECT_NEAR(psi[size_t(i)], expected, 2e-6) << i;
  }
  EXPECT_NEAR(psi[15], 0.0f, 1e-6f);
  for (int i = 16; i < 20; ++i) EXPECT_EQ(psi[size_t(i)], 2.0f);
  Model off = m;
  off.wetting.permeability = false;
  std::vector<float> same(20, 2.0f);
  scaleBoundaryByPermeability(off, s.state, same);
  for (float v : same) EXPECT_EQ(v, 2.0f);
}
