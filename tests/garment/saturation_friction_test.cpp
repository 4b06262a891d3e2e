// Chen 2012 saturation mass (Eq. 15-19, Table 1) and wet friction (Fig. 5, Eq. 20-21)
#include <soak/error.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "garment/saturation_mass.hpp"
#include "garment/wet_friction.hpp"
#include "scene/cloth_piece.hpp"

namespace soak {
namespace {

TEST(GarmentSaturation, PresetsAreTable1) {
  const SaturationParams c = saturationPreset("cotton"), w = saturationPreset("coarse_wool"),
                         h = saturationPreset("high_absorption");
  EXPECT_FLOAT_EQ(c.delta, 0.84f);
  EXPECT_FLOAT_EQ(c.a3, 8.844f);
  EXPECT_FLOAT_EQ(w.delta, 1.24f);
  EXPECT_FLOAT_EQ(w.a3, 4.8936f);
  EXPECT_FLOAT_EQ(h.delta, 2.492f);
  EXPECT_FLOAT_EQ(h.a3, 3.3803f);
  // hand values of Eq. 18: Q(a3) = delta (1 - 1/e), Q -> delta
  EXPECT_NEAR(absorbedRatio(8.844, c), 0.84 * (1.0 - std::exp(-1.0)), 1e-6);
  EXPECT_NEAR(absorbedRatio(1000.0, h), 2.492, 1e-5);
  EXPECT_EQ(absorbedRatio(-1.0, c), 0.0);
}

// every preset: the per-vertex masses the step would use, integrated independently with Eq. 15 and
// the rate of Eq. 19 at dt = 1/60 s, stay within 0.5% of m_dry (1 + Q(t - t_wet)) of Eq. 18
TEST(GarmentSaturation, EachPresetFollowsQWithinHalfPercent) {
  Model model;
  const TriangleMesh mesh = makeRectangle(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), 0.2f, 0.2f, 3, 3);
  addClothPiece(model, "sheet", mesh, ClothMaterial{}, {0}, "<test>");
  Particles p;
  for (int i = 0; i < model.numCloth; ++i)
    p.add(1, uint32_t(i), model.clothDryMass[i], 0.04f, model.clothRestPosition[i], Vec3::Zero());
  for (const std::string& name : saturationPresetNames()) {
    const SaturationParams s = saturationPreset(name);
    std::vector<float> wetStart(9, kNeverWet);
    applySaturationMass(model, 0, {}, 100.0, s, p);  // no wet data: all dry
    for (int i = 0; i < 9; ++i) ASSERT_EQ(p.mass[i], model.clothDryMass[i]);
    const float dt = 1.0f / 60.0f;
    double euler = model.clothDryMass[4];  // Eq. 15 with Eq. 19, vertex 4 wet from t = 0.5 s
    const double dry = model.clothDryMass[4];
    for (int k = 0; k <= int(6.0 * s.a3 / dt); ++k) {
      const double t = k * dt;
      std::vector<uint8_t> wet(9, 0);
      if (t >= 0.5) wet[4] = wet[0] = 1;
      markWet(wet, t, wetStart);
      applySaturationMass(model, 0, wetStart, t, s, p);
      const double closed = dry * (1.0 + (t >= 0.5 ? s.delta * (1.0 - std::exp(-(t - 0.5) / s.a3)) : 0.0));
      ASSERT_NEAR(p.mass[4], closed, 1e-5 * closed) << name << " t " << t;
      ASSERT_NEAR(euler, closed, 5e-3 * closed) << name << " t " << t;
      ASSERT_FLOAT_EQ(p.mass[1], model.clothDryMass[1]) << "a dry vertex keeps its mass";
      ASSERT_EQ(p.invMass[0], 0.0f) << "a pinned vertex stays pinned";
      if (t >= 0.5) euler += dt * dry * absorptionRate(t - 0.5, s);
    }
    EXPECT_NEAR(p.mass[4], dry * (1.0 + s.delta), 0.01 * dry * s.delta) << name << " saturates";
  }
}

TEST(GarmentSaturation, TimeScaleStretchesTheCurve) {
  SaturationParams s = saturationPreset("coarse_wool");
  const double q1 = absorbedRatio(3.0, s);
  s.timeScale = 60.0f;  // paper unit = minutes
  EXPECT_NEAR(absorbedRatio(180.0, s), q1, 1e-9);
  EXPECT_NEAR(absorptionRate(180.0, s) * 60.0, absorptionRate(3.0, saturationPreset("coarse_wool")), 1e-9);
}

TEST(GarmentSaturation, UnknownFabricIsRefusedWithTheKnownNames) {
  try {
    saturationPreset("silk", "scene.json: at cloth[0].fabric");
    FAIL() << "silk is not in Table 1";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("cloth[0].fabric"), std::string::npos) << msg;
    EXPECT_NE(msg.find("\"silk\""), std::string::npos) << msg;
    for (const char* n : {"cotton", "coarse_wool", "high_absorption"}) EXPECT_NE(msg.find(n), std::string::npos) << msg;
  }
}

TEST(GarmentFriction, PeaksAtTau1AndIsOnItsPlateauAfterTau2) {
  const WetFrictionParams f{0.3f, 0.7f, 0.5f, 2.0f, 5.0f, 1.5f};  // times in s: tau1 = 3 s, tau2 = 7.5 s
  EXPECT_FLOAT_EQ(wetFriction(-1.0, f), 0.3f);
  EXPECT_FLOAT_EQ(wetFriction(INFINITY, f), 0.3f);
  EXPECT_FLOAT_EQ(wetFriction(-INFINITY, f), 0.3f);
  EXPECT_FLOAT_EQ(wetFriction(3.0, f), 0.7f);
  double best = -1.0, bestT = -1.0, prev = wetFriction(0.0, f);
  for (int k = 0; k <= 12000; ++k) {
    const double t = k * 1e-3;
    const double mu = wetFriction(t, f);
    if (mu > best) {
      best = mu;
      bestT = t;
    }
    EXPECT_LT(std::abs(mu - prev), 1e-3) << "continuous at t " << t;
    if (t < 3.0) {
      EXPECT_GE(mu, prev - 1e-7) << "rises before tau1, t " << t;
    } else if (t > 3.0 && t < 7.5) {
      EXPECT_LE(mu, prev + 1e-7) << "falls after tau1, t " << t;
    } else if (t >= 7.5) {
      EXPECT_FLOAT_EQ(mu, 0.5f) << "plateau after tau2, t " << t;
    }
    prev = mu;
  }
  EXPECT_NEAR(bestT, 3.0, 1e-3);
  EXPECT_FLOAT_EQ(best, 0.7f);
  EXPECT_GT(wetFriction(7.4, f), 0.5f);  // still falling just before tau2
}

TEST(GarmentFriction, CoulombHoldsBelowTheConeAndSlidesAbove) {
  const Vec3 n(0, 1, 0);
  // normal velocity change 1 m/s, mu 0.5: up to 0.5 m/s of slip is stopped
  const Vec3 held = coulombFriction(Vec3(0.4f, 0.0f, 0.2f), n, 0.5f, 1.0f);
  EXPECT_LT(held.norm(), 1e-7f);
  const Vec3 slid = coulombFriction(Vec3(2.0f, 0.0f, 0.0f), n, 0.5f, 1.0f);
  EXPECT_NEAR(slid.x(), 1.5f, 1e-6f);
  EXPECT_NEAR(slid.y(), 0.0f, 1e-7f);
  const Vec3 keepsNormal = coulombFriction(Vec3(2.0f, 0.3f, 0.0f), n, 0.5f, 1.0f);
  EXPECT_NEAR(keepsNormal.y(), 0.3f, 1e-6f);
  EXPECT_NEAR(keepsNormal.x(), 1.5f, 1e-6f);
  EXPECT_FLOAT_EQ(mixFriction(0.36f, 0.25f), 0.3f);
  EXPECT_EQ(mixFriction(0.6f, 0.0f), 0.0f);
}

}  // namespace
}  // namespace soak
