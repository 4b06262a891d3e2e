// the paper's saturation colours for the cloth OBJ (wetting/output.cpp): dry cloth in a bright colour
// (red in Fig. 3, green in Fig. 4) fading linearly to black as S / S^MAX goes from 0 to 1
#include "wetting/wet_support.hpp"

#include <gtest/gtest.h>

#include <vector>

using namespace soak;
using namespace soak::testing;

// (1 - t) times the dry colour with t = clamp(value / valueMax, 0, 1): a quarter, half, full, past full and
// negative values; valueMax <= 0 draws everything dry; other ramp names give no colours
TEST(WettingOutput, RampsFadeLinearlyToBlack) {
  const std::vector<float> v{0.0f, 0.1f, 0.2f, 0.4f, 0.9f, -0.3f};
  const std::vector<Vec3> red = rampColors(v, 0.4f, "red");
  ASSERT_EQ(red.size(), v.size());
  const float expected[] = {1.0f, 0.75f, 0.5f, 0.0f, 0.0f, 1.0f};
  for (size_t i = 0; i < v.size(); ++i) {
    EXPECT_NEAR(red[i].x(), expected[i], 1e-6f) << i;
    EXPECT_EQ(red[i].y(), 0.0f);
    EXPECT_EQ(red[i].z(), 0.0f);
  }
  const std::vector<Vec3> green = rampColors(v, 0.4f, "green");
  for (size_t i = 0; i < v.size(); ++i) EXPECT_EQ(green[i], Vec3(0.0f, red[i].x(), 0.0f)) << i;
  for (const Vec3& c : rampColors(v, 0.0f, "red")) EXPECT_EQ(c, Vec3(1, 0, 0));
  EXPECT_TRUE(rampColors(v, 0.4f, "none").empty());
  EXPECT_TRUE(rampColors(v, 0.4f, "blue").empty());
  EXPECT_TRUE(rampColors({}, 0.4f, "red").empty());
}

// the cloth's colours by S_i / S^MAX of the scene; none when wetting is off or before the saturation is
// sized to the cloth
TEST(WettingOutput, SaturationColoursOnlyWithWetting) {
  Scene s = sceneFromJson(R"({"cloth": [{"mesh": {"type": "rectangle", "size": [0.06, 0.06], "resolution": [4, 4]}}],
                             "wetting": {"saturation": {"max": 0.5, "emit": 0.45}}})");
  ASSERT_EQ(s.model.numCloth, 16);
  for (int i = 0; i < 16; ++i) s.state.clothSaturation[size_t(i)] = 0.5f * i / 15.0f;
  const std::vector<Vec3> c = saturationColors(s.model, s.state, "green");
  ASSERT_EQ(c.size(), 16u);
  for (int i = 0; i < 16; ++i) EXPECT_NEAR(c[size_t(i)].y(), 1.0f - i / 15.0f, 1e-6f) << i;
  Model off = s.model;
  off.wetting.enabled = false;
  EXPECT_TRUE(saturationColors(off, s.state, "green").empty());
  State unsized = s.state;
  unsized.clothSaturation.resize(3);
  EXPECT_TRUE(saturationColors(s.model, unsized, "green").empty());
}
