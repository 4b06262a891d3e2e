// Chen 2012 saturation mass (section 3.3, Eq. 15-19, Table 1): the presets, Q(t) of Eq. 18 and its rate
// (Eq. 19), the first wet time per vertex, and the wet mass set on one cloth piece
#include "garment/saturation_mass.hpp"

#include <soak/error.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

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

// Eq. 18 as written, m_dry (1 + delta (1 - exp(-(t - t_wet) / (a3 timeScale)))): dry before the wet start
// and for a vertex never wet, and the closed form to 1e-12 after it (the saturation mass is an exact
// integral, not a step-by-step sum)
TEST(GarmentSaturation, WetMassIsDryUntilTheWetStartThenEq18) {
  SaturationParams s = saturationPreset("coarse_wool");  // delta 1.24, a3 4.8936
  s.timeScale = 2.0f;
  const double dry = 0.004;
  EXPECT_EQ(wetMass(dry, kNeverWet, 1e6, s), dry);
  EXPECT_EQ(wetMass(dry, 3.0f, 1.0, s), dry);   // not wet yet
  EXPECT_EQ(wetMass(dry, 3.0f, 3.0, s), dry);   // wet this instant: Q(0) = 0
  for (double t : {0.1, 1.0, 4.8936 * 2.0, 30.0, 500.0}) {
    const double tau = double(s.a3) * 2.0;
    const double expected = dry * (1.0 + double(s.delta) * (1.0 - std::exp(-t / tau)));
    EXPECT_NEAR(wetMass(dry, 3.0f, 3.0 + t, s), expected, 1e-12 * expected) << t;
  }
  // one time constant in: 1 - 1/e of delta
  EXPECT_NEAR(absorbedRatio(4.8936 * 2.0, s), 1.24 * (1.0 - std::exp(-1.0)), 1e-6);
}

// Eq. 19 is the derivative of Eq. 18: a central difference of Q matches the rate to 1e-7 relative for every
// preset and time scale; the rate at t = 0 is delta / (a3 timeScale) and 0 before the fabric is wet
TEST(GarmentSaturation, RateIsTheDerivativeOfQ) {
  for (const std::string& name : saturationPresetNames())
    for (float scale : {1.0f, 60.0f}) {
      SaturationParams s = saturationPreset(name);
      s.timeScale = scale;
      const double tau = double(s.a3) * scale;
      EXPECT_NEAR(absorptionRate(0.0, s), s.delta / tau, 1e-12 * s.delta / tau) << name;
      EXPECT_EQ(absorptionRate(-0.5, s), 0.0) << name;
      for (double f : {0.05, 0.5, 1.0, 3.0}) {
        const double t = f * tau, e = 1e-4 * tau;
        const double slope = (absorbedRatio(t + e, s) - absorbedRatio(t - e, s)) / (2.0 * e);
        EXPECT_NEAR(slope, absorptionRate(t, s), 1e-7 * absorptionRate(t, s)) << name << " t " << t;
      }
    }
}

// markWet keeps the first wet time of each vertex, ignores dry entries, and touches only the vertices both
// spans hold
TEST(GarmentSaturation, MarkWetKeepsTheFirstTimeWithinBothSpans) {
  std::vector<float> start(5, kNeverWet);
  const std::vector<uint8_t> first{0, 1, 0, 1, 0};
  markWet(first, 1.5, start);
  EXPECT_EQ(start, (std::vector<float>{kNeverWet, 1.5f, kNeverWet, 1.5f, kNeverWet}));
  const std::vector<uint8_t> all(5, 1);
  markWet(all, 2.25, start);  // 1 and 3 keep 1.5
  EXPECT_EQ(start, (std::vector<float>{2.25f, 1.5f, 2.25f, 1.5f, 2.25f}));
  // a shorter wet span leaves the rest; a shorter start span is not overrun
  std::vector<float> fresh(4, kNeverWet);
  markWet(std::vector<uint8_t>{1, 1}, 7.0, fresh);
  EXPECT_EQ(fresh, (std::vector<float>{7.0f, 7.0f, kNeverWet, kNeverWet}));
  std::vector<float> two(2, kNeverWet);
  markWet(all, 8.0, two);
  EXPECT_EQ(two, (std::vector<float>{8.0f, 8.0f}));
}

// applySaturationMass writes the masses of its own piece only (wetStart indexed from the piece's first
// particle), keeps the pinned vertices kinematic and gives the free ones invMass = 1 / m
TEST(GarmentSaturation, AppliesToItsPieceOnlyWithLocalIndices) {
  Model model;
  const TriangleMesh a = makeRectangle(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), 0.2f, 0.2f, 3, 3);
  const TriangleMesh b = makeRectangle(Vec3(0, 1, 0), Vec3::UnitX(), Vec3::UnitZ(), 0.1f, 0.1f, 2, 2);
  addClothPiece(model, "a", a, ClothMaterial{}, {}, "<test>");
  addClothPiece(model, "b", b, ClothMaterial{}, {1}, "<test>");
  ASSERT_EQ(model.numCloth, 13);
  Particles p;
  for (int i = 0; i < model.numCloth; ++i)
    p.add(i < 9 ? 1 : 2, uint32_t(i), model.clothDryMass[i], 0.04f, model.clothRestPosition[i], Vec3::Zero());
  const SaturationParams s = saturationPreset("high_absorption");
  const std::vector<float> wetStart{0.0f, 0.0f, kNeverWet, 2.0f};  // piece b's vertices 0..3
  applySaturationMass(model, 1, wetStart, 5.0, s, p);
  for (int i = 0; i < 9; ++i) {
    EXPECT_EQ(p.mass[i], model.clothDryMass[i]) << "piece a untouched, " << i;
    EXPECT_EQ(p.invMass[i], 1.0f / model.clothDryMass[i]) << i;
  }
  const double q5 = 2.492 * (1.0 - std::exp(-5.0 / 3.3803)), q3 = 2.492 * (1.0 - std::exp(-3.0 / 3.3803));
  EXPECT_NEAR(p.mass[9], model.clothDryMass[9] * (1.0 + q5), 1e-6 * p.mass[9]);
  EXPECT_NEAR(p.mass[10], model.clothDryMass[10] * (1.0 + q5), 1e-6 * p.mass[10]);
  EXPECT_EQ(p.mass[11], model.clothDryMass[11]);
  EXPECT_NEAR(p.mass[12], model.clothDryMass[12] * (1.0 + q3), 1e-6 * p.mass[12]);
  EXPECT_EQ(p.invMass[10], 0.0f) << "piece b's pinned vertex 1 stays kinematic";
  EXPECT_FLOAT_EQ(p.invMass[9], 1.0f / p.mass[9]);
  EXPECT_FLOAT_EQ(p.invMass[12], 1.0f / p.mass[12]);
}

}  // namespace
}  // namespace soak
