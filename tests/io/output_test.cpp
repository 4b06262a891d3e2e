// the files of one frame (io/output.cpp): which files the settings ask for, and what writeFrame adds to
// them: Shao's saturation as a PLY attribute and OBJ colours, or Chen's wetness Q / delta
#include "io/output.hpp"

#include <gtest/gtest.h>

#include <soak/error.hpp>
#include <soak/output.hpp>

#include "io/io_support.hpp"
#include "io/file.hpp"
#include "io/ply.hpp"

#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>
#include <string>

namespace soak {
namespace {

using namespace soak::testing;

// the r g b of every "v x y z r g b" line of an OBJ
std::vector<Vec3> objColours(const std::string& path) {
  std::vector<Vec3> out;
  for (const std::string& l : lines(readTextFile(path))) {
    if (l.rfind("v ", 0) != 0) continue;
    std::istringstream ss(l.substr(2));
    float x, y, z, r, g, b;
    if (ss >> x >> y >> z >> r >> g >> b) out.emplace_back(r, g, b);
  }
  return out;
}

TEST(IoOutput, FrameFilesFollowSettingsAndNumbering) {
  const Fixture f = makeFixture();
  const fs::path dir = tempDir("frames");
  OutputSettings s;
  auto files = writeFrameFiles(dir.string(), f.model, f.state, s, 7);
  ASSERT_EQ(files.size(), 3u);
  EXPECT_TRUE(fs::exists(dir / "cloth_0007.obj"));
  EXPECT_TRUE(fs::exists(dir / "cloth_0007.ply"));
  EXPECT_TRUE(fs::exists(dir / "water_0007.ply"));
  s.clothObj = false;
  s.water = false;
  files = writeFrameFiles(dir.string(), f.model, f.state, s, 12345);
  ASSERT_EQ(files.size(), 1u);
  EXPECT_EQ(fs::path(files[0]).filename(), "cloth_12345.ply");
  EXPECT_EQ(frameFileName("water", 3, "ply"), "water_0003.ply");
  fs::remove_all(dir);
}

// a model without cloth writes its water only, whatever the cloth settings say; nothing enabled, nothing written
TEST(IoOutput, WithoutClothOnlyTheWaterIsWritten) {
  Fixture f = makeFixture();
  Model water;  // the same particles seen as water only
  State s;
  for (size_t i = 13; i < f.state.particles.size(); ++i)
    s.particles.add(kWaterPhase, f.state.particles.id[i], 0.008f, 0.04f, f.state.particles.x[i], Vec3::Zero());
  const fs::path dir = tempDir("wateronly");
  const auto files = writeFrameFiles(dir.string(), water, s, OutputSettings{}, 2);
  ASSERT_EQ(files.size(), 1u);
  EXPECT_EQ(fs::path(files[0]).filename(), "water_0002.ply");
  EXPECT_EQ(readPly(files[0]).element("vertex").count, 5u);
  OutputSettings none;
  none.clothObj = none.clothPly = none.water = false;
  EXPECT_TRUE(writeFrameFiles(dir.string(), f.model, f.state, none, 3).empty());
  EXPECT_FALSE(fs::exists(dir / "cloth_0003.obj"));
  fs::remove_all(dir);
}

// with Shao's wetting the cloth PLY carries S_i as "saturation" and the OBJ the paper's ramp, dry colour
// times 1 - S / S^MAX (red for Fig. 3, green for Fig. 4); "none" writes no colours
TEST(IoOutput, WriteFrameCarriesSaturationAndItsColours) {
  Fixture f = makeFixture();
  f.model.wetting.enabled = true;
  f.model.wetting.saturationMax = 0.4f;
  f.state.clothSaturation.resize(13);
  for (int i = 0; i < 13; ++i) f.state.clothSaturation[i] = 0.04f * i;  // 0 .. 0.48: the last ones clamp
  const fs::path dir = tempDir("saturation");
  OutputSettings settings;
  settings.colorRamp = "green";
  writeFrame(dir.string(), f.model, f.state, settings, 1);
  const PlyData ply = readPly((dir / "cloth_0001.ply").string());
  const PlyElement& v = ply.element("vertex");
  ASSERT_TRUE(v.has("saturation"));
  EXPECT_FALSE(v.has("wetness"));
  const std::vector<Vec3> c = objColours((dir / "cloth_0001.obj").string());
  ASSERT_EQ(c.size(), 13u);
  for (int i = 0; i < 13; ++i) {
    EXPECT_EQ(v.scalar("saturation")[i], f.state.clothSaturation[i]);
    const float t = std::min(0.04f * i / 0.4f, 1.0f);
    EXPECT_NEAR(c[i].y(), 1.0f - t, 1e-5f) << i;
    EXPECT_EQ(c[i].x(), 0.0f);
    EXPECT_EQ(c[i].z(), 0.0f);
  }
  settings.colorRamp = "none";
  writeFrame(dir.string(), f.model, f.state, settings, 2);
  EXPECT_TRUE(objColours((dir / "cloth_0002.obj").string()).empty());
  fs::remove_all(dir);
}

// a Chen 2012 piece without Shao's wetting: the PLY carries "wetness", each vertex's saturation
// Q / delta, and the OBJ colours follow it on the ramp with 1 drawn black
TEST(IoOutput, WriteFrameCarriesTheWetnessOfAChenPiece) {
  Fixture f = makeFixture();
  f.model.pieces[0].wetByContact = true;
  f.state.clothWetStart.assign(13, std::numeric_limits<float>::infinity());
  f.state.clothWater.assign(13, 0.0);
  f.state.clothBuffer.assign(13, 0.0);
  f.state.clothSaturation.assign(13, 0.0f);
  const double q = 0.3636;
  f.state.clothSaturation[2] = float(q);
  f.state.clothSaturation[10] = 0.5f;  // in the patch, which is not wetted by contact
  const fs::path dir = tempDir("wetness");
  writeFrame(dir.string(), f.model, f.state, OutputSettings{}, 0);
  const PlyData ply = readPly((dir / "cloth_0000.ply").string());
  const PlyElement& v = ply.element("vertex");
  ASSERT_TRUE(v.has("wetness"));
  EXPECT_FALSE(v.has("saturation"));
  EXPECT_NEAR(v.scalar("wetness")[2], q, 1e-6);
  EXPECT_EQ(v.scalar("wetness")[3], 0.0);
  EXPECT_EQ(v.scalar("wetness")[10], 0.0);
  const std::vector<Vec3> c = objColours((dir / "cloth_0000.obj").string());
  ASSERT_EQ(c.size(), 13u);
  EXPECT_NEAR(c[2].x(), 1.0 - q, 1e-5);
  EXPECT_EQ(c[3], Vec3(1, 0, 0));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace soak
