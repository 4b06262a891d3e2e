// Chen 2012 saturation mass (section 3.3, Eq. 15-19, Table 1): the presets, Q(t) of Eq. 18 and its rate
// (Eq. 19), the saturation a vertex absorbs from the water it holds, and the wet mass set on one piece
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

// a 3 x 3 sheet (vertex 0 pinned) and a State holding Chen's per-vertex arrays, all dry
struct Sheet {
  Model model;
  State state;
  Sheet() {
    const TriangleMesh mesh = makeRectangle(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), 0.2f, 0.2f, 3, 3);
    addClothPiece(model, "sheet", mesh, ClothMaterial{}, {0}, "<test>");
    for (int i = 0; i < model.numCloth; ++i)
      state.particles.add(1, uint32_t(i), model.clothDryMass[i], 0.04f, model.clothRestPosition[i], Vec3::Zero());
    state.clothWetStart.assign(9, kNeverWet);
    state.clothWater.assign(9, 0.0);
    state.clothSaturation.assign(9, 0.0f);
  }
  // the step's order: saturation to t + dt, then the mass
  void step(const SaturationParams& s, double t, float dt) {
    model.pieces[0].garment.saturation = s;
    updateSaturation(model, 0, s, t, dt, state);
    applySaturationMass(model, 0, state.clothSaturation, s, state.particles);
  }
};

// every preset, both supplies: a vertex given its full capacity of water at t = 0.5 s (drops) or wet
// then (unlimited) has the mass m_dry (1 + Q(t - 0.5)) of Eq. 18 at every step, to 1e-5, and an
// independent Euler sum of Eq. 15 with the rate of Eq. 19 stays within 0.5% of it; dry vertices keep
// their mass and the pinned one stays kinematic
TEST(GarmentSaturation, EachPresetFollowsQWithinHalfPercent) {
  for (const std::string& name : saturationPresetNames())
    for (bool unlimited : {false, true}) {
      SaturationParams s = saturationPreset(name);
      s.unlimitedSupply = unlimited;
      Sheet sh;
      const Particles& p = sh.state.particles;
      const float dt = 1.0f / 60.0f;
      const double dry = sh.model.clothDryMass[4];
      double euler = dry;
      for (int k = 0; k <= int(6.0 * s.a3 / dt); ++k) {
        const double t = k * dt;
        if (k == 30) {  // t = 0.5 s
          for (int v : {0, 4}) {
            sh.state.clothWetStart[size_t(v)] = 0.5f;
            sh.state.clothWater[size_t(v)] = unlimited ? 0.0 : waterCapacity(sh.model.clothDryMass[size_t(v)], s);
          }
        }
        sh.step(s, t, dt);
        const double te = t + dt;
        if (te > 0.5) euler += dt * dry * absorptionRate(te - 0.5 - 0.5 * dt, s);
        const double closed = dry * (1.0 + (te > 0.5 ? s.delta * (1.0 - std::exp(-(te - 0.5) / s.a3)) : 0.0));
        ASSERT_NEAR(p.mass[4], closed, 1e-5 * closed) << name << " t " << te;
        ASSERT_NEAR(euler, closed, 5e-3 * closed) << name << " t " << te;
        ASSERT_FLOAT_EQ(p.mass[1], sh.model.clothDryMass[1]) << "a dry vertex keeps its mass";
        ASSERT_EQ(p.invMass[0], 0.0f) << "a pinned vertex stays pinned";
      }
      EXPECT_NEAR(p.mass[4], dry * (1.0 + s.delta), 0.01 * dry * s.delta) << name << " saturates";
    }
}

// the water that reached a vertex bounds what it absorbs: a quarter of its capacity saturates it to
// 0.25 and no further; more water later raises it again at Eq. 18's rate; and the saturation at a
// given time is the same (to 1e-4) for steps of 1/15, 1/60 and 1/240 s, the supply arriving at the
// same instants
TEST(GarmentSaturation, AbsorbsOnlyTheWaterThatArrivedAtAnyStep) {
  const SaturationParams s = saturationPreset("cotton");  // a3 8.844 s
  auto run = [&](int perSecond) {
    Sheet sh;
    const double cap = waterCapacity(sh.model.clothDryMass[4], s);
    const float dt = 1.0f / float(perSecond);
    std::vector<float> trace;
    for (int k = 0; k < 40 * perSecond; ++k) {
      if (k == perSecond) sh.state.clothWater[4] = 0.25 * cap;            // t = 1 s
      if (k == 30 * perSecond) sh.state.clothWater[4] = 0.75 * cap;       // t = 30 s
      const float before = sh.state.clothSaturation[4];
      sh.step(s, double(k) / perSecond, dt);
      EXPECT_GE(sh.state.clothSaturation[4], before) << "absorbed water stays absorbed";
      EXPECT_LE(sh.state.clothSaturation[4], sh.state.clothWater[4] / cap + 1e-6);
      if ((k + 1) % (5 * perSecond) == 0) trace.push_back(sh.state.clothSaturation[4]);  // t = 5, 10, ... s
    }
    return trace;
  };
  const std::vector<float> coarse = run(15), mid = run(60), fine = run(240);
  ASSERT_EQ(mid.size(), 8u);  // t = 5, 10, ..., 40
  ASSERT_EQ(coarse.size(), mid.size());
  ASSERT_EQ(fine.size(), mid.size());
  for (size_t k = 0; k < mid.size(); ++k) {
    EXPECT_NEAR(coarse[k], mid[k], 1e-4) << k;
    EXPECT_NEAR(fine[k], mid[k], 1e-4) << k;
  }
  // closed forms: 0.25 (1 - e^(-4 / a3)) at 5 s; just under 0.25 at 30 s; then towards 0.75 at the same rate
  EXPECT_NEAR(mid[0], 0.25 * (1.0 - std::exp(-4.0 / 8.844)), 1e-5);
  EXPECT_NEAR(mid[5], 0.25 * (1.0 - std::exp(-29.0 / 8.844)), 1e-5);  // t = 30: the new water is not absorbed yet
  EXPECT_NEAR(mid[7], 0.75 - (0.75 - mid[5]) * std::exp(-10.0 / 8.844), 1e-5);
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

// the mass at saturation s is m_dry (1 + delta s) (Eq. 15 with Q = delta s); with an unlimited supply
// s = 1 - exp(-(t - t_wet) / (a3 timeScale)): 0 before the wet start, for a vertex never wet and at the
// wet instant, Eq. 18 / delta to 1e-6 after it
TEST(GarmentSaturation, WetMassIsDryUntilTheWetStartThenEq18) {
  SaturationParams s = saturationPreset("coarse_wool");  // delta 1.24, a3 4.8936
  s.timeScale = 2.0f;
  const double dry = 0.004;
  EXPECT_EQ(wetMass(dry, 0.0f, s), dry);
  EXPECT_NEAR(wetMass(dry, 0.5f, s), dry * (1.0 + 0.62), 1e-9);
  EXPECT_NEAR(wetMass(dry, 2.0f, s), dry * (1.0 + 1.24), 1e-9) << "at most saturated";
  EXPECT_EQ(unlimitedSaturation(1e6 - double(kNeverWet), s), 0.0f);
  EXPECT_EQ(unlimitedSaturation(-2.0, s), 0.0f);  // not wet yet
  EXPECT_EQ(unlimitedSaturation(0.0, s), 0.0f);   // wet this instant: Q(0) = 0
  for (double t : {0.1, 1.0, 4.8936 * 2.0, 30.0, 500.0}) {
    const double tau = double(s.a3) * 2.0;
    EXPECT_NEAR(unlimitedSaturation(t, s), 1.0 - std::exp(-t / tau), 1e-6) << t;
    EXPECT_NEAR(unlimitedSaturation(t, s) * s.delta, absorbedRatio(t, s), 1e-6) << t;
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

// applySaturationMass writes the masses of its own piece only (saturation indexed from the piece's first
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
  const std::vector<float> saturation{0.5f, 0.5f, 0.0f, 0.25f};  // piece b's vertices 0..3
  applySaturationMass(model, 1, saturation, s, p);
  for (int i = 0; i < 9; ++i) {
    EXPECT_EQ(p.mass[i], model.clothDryMass[i]) << "piece a untouched, " << i;
    EXPECT_EQ(p.invMass[i], 1.0f / model.clothDryMass[i]) << i;
  }
  const double q5 = 2.492 * 0.5, q3 = 2.492 * 0.25;
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
