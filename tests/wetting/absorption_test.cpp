// absorption (Eq. 11): gravity makes cloth below water soak up more than cloth above it (Fig. 4); the
// cloth gains exactly what the water loses; partial absorption shrinks the particle
#include "wetting/wet_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

using namespace soak;
using namespace soak::testing;

namespace {

// two pinned horizontal sheets far apart: "low" with a water layer 0.02 m above it (the cloth is below
// the water) and "high" with a layer 0.02 m below it (the cloth is above the water)
Scene twoSheets(float eta) {
  const std::string json =
      R"({"cloth": [)" +
      rectangleJson("low", Vec3(0, 0, 0), 0.2f, 0.2f, 11, 11, "[1, 0, 0]", "[0, 0, 1]", kPinAll) + ", " +
      rectangleJson("high", Vec3(0, 1, 0), 0.2f, 0.2f, 11, 11, "[1, 0, 0]", "[0, 0, 1]", kPinAll) +
      R"(], "wetting": {"absorption": {"rate": 0.02, "gravityInfluence": )" + std::to_string(eta) + "}}}";
  Scene scene = sceneFromJson(json);
  for (int i = 0; i < 7; ++i)
    for (int k = 0; k < 7; ++k) {
      const float x = -0.06f + 0.02f * float(i), z = -0.06f + 0.02f * float(k);
      addWater(scene, Vec3(x, 0.02f, z));  // above "low"
      addWater(scene, Vec3(x, 0.98f, z));  // below "high"
    }
  return scene;
}

double heldBy(const Scene& scene, int piece) {
  const ClothPiece& c = scene.model.pieces[size_t(piece)];
  double m = 0.0;
  for (int i = c.firstParticle; i < c.firstParticle + c.particleCount; ++i) m += scene.state.clothWater[size_t(i)];
  return m;
}

}  // namespace

TEST(WettingAbsorption, ClothBelowWaterAbsorbsMoreThanClothAbove) {
  Scene scene = twoSheets(0.6f);
  StageRig rig;
  rig.refresh(scene.state, scene.model);
  const double before = accountedWater(scene);
  absorbWater(scene.model, scene.state, rig.nb, rig.s, scene.model.solver.dt);
  finishWetting(scene.model, scene.state, rig.s);
  const double low = heldBy(scene, 0), high = heldBy(scene, 1);
  EXPECT_GT(low, 0.0);
  EXPECT_GT(high, 0.0);
  // (1 + eta cos) over the layer's neighbours: about 1.5 against 0.5
  EXPECT_GT(low, 2.0 * high);
  EXPECT_NEAR(accountedWater(scene), before, 1e-12 * before);
  // without the gravity term both sheets soak up the same
  Scene flat = twoSheets(0.0f);
  rig.refresh(flat.state, flat.model);
  absorbWater(flat.model, flat.state, rig.nb, rig.s, flat.model.solver.dt);
  EXPECT_NEAR(heldBy(flat, 0), heldBy(flat, 1), 1e-6 * heldBy(flat, 0));
}

TEST(WettingAbsorption, PartialAbsorptionKeepsMassAndShrinksTheRadius) {
  // a slow rate so the particle shrinks over several steps instead of vanishing in one
  Scene scene = sceneFromJson(R"({"cloth": [)" +
                              rectangleJson("s", Vec3(0, 0, 0), 0.1f, 0.1f, 6, 6, "[1, 0, 0]", "[0, 0, 1]", kPinAll) +
                              R"(], "wetting": {"absorption": {"rate": 0.02}}})");
  const size_t q = addWater(scene, Vec3(0.0f, 0.02f, 0.0f));
  const float m0 = scene.model.water.particleMass, h0 = scene.model.water.supportRadius;
  StageRig rig;
  for (int step = 0; step < 5; ++step) {
    rig.refresh(scene.state, scene.model);
    const double before = accountedWater(scene);
    EXPECT_EQ(absorbWater(scene.model, scene.state, rig.nb, rig.s, scene.model.solver.dt), 0u);
    finishWetting(scene.model, scene.state, rig.s);
    const Particles& p = scene.state.particles;
    ASSERT_EQ(p.size(), q + 1);
    // the cloth gained exactly what the water lost
    EXPECT_NEAR(accountedWater(scene), before, 1e-12);
    EXPECT_LT(p.mass[q], m0);
    EXPECT_NEAR(p.radius[q], std::cbrt(p.mass[q] / m0) * h0, 1e-7f);
  }
  EXPECT_NEAR(double(scene.state.particles.mass[q]) + sum(scene.state.clothWater), double(m0), 1e-9);
  EXPECT_LT(scene.state.particles.radius[q], h0);
}

TEST(WettingAbsorption, ARemnantBelowTheMinimumMassIsAbsorbedWhole) {
  Scene scene = sceneFromJson(R"({"cloth": [)" +
                              rectangleJson("s", Vec3(0, 0, 0), 0.1f, 0.1f, 6, 6, "[1, 0, 0]", "[0, 0, 1]", kPinAll) +
                              R"(], "wetting": {}})");
  const size_t q = addWater(scene, Vec3(0.0f, 0.02f, 0.0f));
  const uint32_t keptId = scene.state.particles.id[q];
  addWater(scene, Vec3(0.0f, 0.5f, 0.0f));  // out of reach: stays, and keeps its id
  Particles& p = scene.state.particles;
  p.mass[q] = 0.11f * scene.model.water.particleMass;  // just above the minimum (0.1 m0)
  StageRig rig;
  rig.refresh(scene.state, scene.model);
  const double before = accountedWater(scene);
  EXPECT_EQ(absorbWater(scene.model, scene.state, rig.nb, rig.s, scene.model.solver.dt), 1u);
  finishWetting(scene.model, scene.state, rig.s);
  ASSERT_EQ(p.size(), q + 1);  // only the far particle is left
  EXPECT_EQ(p.id[q], keptId + 1);
  EXPECT_EQ(scene.state.ledger.particlesAbsorbed, 1u);
  EXPECT_NEAR(accountedWater(scene), before, 1e-12);
  EXPECT_NEAR(scene.state.ledger.heldInCloth, double(0.11f * scene.model.water.particleMass), 1e-12);
}

TEST(WettingAbsorption, ARemnantAbsorbedWholeNeverFillsPastSMax) {
  // a nearly full corner particle beside a water particle just above the minimum mass: the particle is
  // absorbed whole, and what does not fit below S^MAX goes to the buffer (never destroyed)
  Scene scene = sceneFromJson(R"({"cloth": [)" +
                              rectangleJson("s", Vec3(0, 0, 0), 0.1f, 0.1f, 6, 6, "[1, 0, 0]", "[0, 0, 1]", kPinAll) +
                              R"(], "wetting": {"absorption": {"rate": 1.0, "minMassFraction": 0.99}}})");
  addWater(scene, Vec3(-0.05f, 0.012f, -0.05f));
  StageRig rig;
  rig.refresh(scene.state, scene.model);
  const WettingParams& w = scene.model.wetting;
  for (int i = 0; i < scene.model.numCloth; ++i)
    scene.state.clothWater[size_t(i)] = 0.97 * w.saturationMax * rig.s.volume[size_t(i)] / w.c;
  rig.refresh(scene.state, scene.model);
  const double before = accountedWater(scene);
  EXPECT_EQ(absorbWater(scene.model, scene.state, rig.nb, rig.s, scene.model.solver.dt), 1u);
  finishWetting(scene.model, scene.state, rig.s);
  computeSaturation(scene.model, scene.state, rig.s, scene.state.clothSaturation);
  EXPECT_LE(*std::max_element(scene.state.clothSaturation.begin(), scene.state.clothSaturation.end()),
            w.saturationMax * (1.0f + 1e-6f));
  EXPECT_GT(sum(scene.state.clothBuffer), 0.0);
  EXPECT_NEAR(accountedWater(scene), before, 1e-12 * before);
  for (int i = 0; i < scene.model.numCloth; ++i)  // the mass followed the water
    EXPECT_EQ(scene.state.particles.mass[i],
              scene.model.clothDryMass[i] + float(scene.state.clothWater[i] + scene.state.clothBuffer[i]));
}
