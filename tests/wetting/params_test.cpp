// the "wetting" section of a scene: Table 1 defaults, the switch, the initial water in the ledger, and
// the documented refusals, each naming the file and the JSON path
#include "wetting/wet_support.hpp"

#include <soak/error.hpp>

#include <gtest/gtest.h>

using namespace soak;
using namespace soak::testing;

namespace {

std::string errorOf(const std::vector<std::string>& overrides) {
  try {
    sceneFromJson(kHanging, overrides);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(WettingParams, DefaultsAreTable1AndASectionTurnsWettingOn) {
  const Scene on = sceneFromJson(kHanging);
  const WettingParams& w = on.model.wetting;
  EXPECT_TRUE(w.enabled);
  EXPECT_FLOAT_EQ(w.saturationSticky, 0.12f);
  EXPECT_FLOAT_EQ(w.saturationEmit, 0.35f);
  EXPECT_FLOAT_EQ(w.saturationMax, 0.4f);
  EXPECT_FLOAT_EQ(w.massThreshold, 0.002f);
  EXPECT_FLOAT_EQ(w.absorptionRate, 0.1f);
  EXPECT_FLOAT_EQ(w.diffusivity, WettingParams{}.diffusivity);
  EXPECT_GT(w.wickingHeight, 0.0f);
  EXPECT_FLOAT_EQ(w.attraction, 10.0f);
  EXPECT_FLOAT_EQ(w.stickingRate, 0.3f);
  EXPECT_FLOAT_EQ(w.absorptionGravity, 0.6f);
  EXPECT_FLOAT_EQ(w.diffusionGravityFactor, 0.4f);
  ASSERT_EQ(on.state.clothWater.size(), size_t(on.model.numCloth));
  const Scene off = sceneFromJson(kHanging, {"wetting.enabled=false"});
  EXPECT_FALSE(off.model.wetting.enabled);
  const Scene absent = sceneFromJson(R"({"cloth": [{"mesh": {"type": "rectangle", "size": [0.1, 0.1],
                                         "resolution": [3, 3]}}]})");
  EXPECT_FALSE(absent.model.wetting.enabled);
  EXPECT_TRUE(absent.state.clothWater.empty());
}

TEST(WettingParams, RefusesInconsistentSaturations) {
  const std::string sticky = errorOf({"wetting.saturation.sticky=0.35"});
  EXPECT_NE(sticky.find("<test>: at wetting.saturation.sticky: expected a number < wetting.saturation.emit"),
            std::string::npos)
      << sticky;
  const std::string emit = errorOf({"wetting.saturation.emit=0.45"});
  EXPECT_NE(emit.find("at wetting.saturation.emit: expected a number <= wetting.saturation.max (0.4), got 0.45"),
            std::string::npos)
      << emit;
  const std::string init = errorOf({"wetting.saturation.initial=0.5"});
  EXPECT_NE(init.find("at wetting.saturation.initial"), std::string::npos) << init;
}

TEST(WettingParams, RefusesNegativeRatesAndUnknownKeys) {
  for (const char* key : {"wetting.absorption.rate", "wetting.diffusion.diffusivity", "wetting.diffusion.wickingHeight",
                          "wetting.emission.beta", "wetting.emission.attraction", "wetting.sticking.rate",
                          "wetting.sticking.strength"}) {
    const std::string e = errorOf({std::string(key) + "=-0.1"});
    EXPECT_NE(e.find(std::string("<test>: at ") + key + ": expected a number"), std::string::npos) << e;
    EXPECT_NE(e.find("got -0.1"), std::string::npos) << e;
  }
  const std::string typo = errorOf({"wetting.diffusion.gravityy=true"});
  EXPECT_NE(typo.find("unknown key 'gravityy'"), std::string::npos) << typo;
}

TEST(WettingParams, RefusesADripThresholdNoParticleCanHold) {
  // a 0.02 m sheet holds 0.4 * 1.28e-5 / 1e-3 = 5.1 g per particle at S^MAX
  const std::string e = errorOf({"wetting.emission.massThreshold=0.006"});
  EXPECT_NE(e.find("<test>: at wetting.emission.massThreshold: expected at most the water a cloth particle of "
                   "cloth[0] ('sheet') can hold"),
            std::string::npos)
      << e;
  EXPECT_EQ(errorOf({"wetting.emission.massThreshold=0.005"}), "");
  // with emission off the threshold is never used
  EXPECT_EQ(errorOf({"wetting.emission.massThreshold=0.006", "wetting.emission.enabled=false"}), "");
}

TEST(WettingParams, RefusesALargestDripLighterThanTheThreshold) {
  const std::string e = errorOf({"wetting.emission.maxDripMass=0.001"});
  EXPECT_NE(e.find("<test>: at wetting.emission.maxDripMass: expected a number >= wetting.emission.massThreshold "
                   "(0.002), got 0.001"),
            std::string::npos)
      << e;
  EXPECT_NE(errorOf({"wetting.emission.maxDripMass=0"}).find("at wetting.emission.maxDripMass"), std::string::npos);
  EXPECT_EQ(errorOf({"wetting.emission.maxDripMass=0.002"}), "");
  EXPECT_FLOAT_EQ(sceneFromJson(kHanging).model.wetting.maxDripMass, 0.0f);  // unset: four water particles' mass
}
