// per-frame statistics (io/stats.cpp): a frame's steps summed and reduced, where the water is, the stage
// parts by name, the wetting and garment sections when those models are on, one JSON object per line
#include "io/stats.hpp"

#include <gtest/gtest.h>

#include <soak/error.hpp>
#include <soak/output.hpp>

#include "io/io_support.hpp"
#include "io/file.hpp"

#include <cmath>
#include <limits>
#include <string>

namespace soak {
namespace {

using namespace soak::testing;

TEST(IoStats, FrameLineSumsStepsAndAccountsWater) {
  Fixture f = makeFixture();
  f.state.ledger.emitted = 0.05;
  f.state.ledger.removedAtBounds = 0.0123;
  f.state.ledger.particlesRemovedAtBounds = 3;
  FrameStats fs;
  StepStats a, b;
  a.substeps = 2;
  a.ms.neighbors = 1.0;
  a.ms.part(StagePart::neighborsLists) = 0.75;
  a.ms.total = 4.0;
  a.couplingContacts = 10;
  a.meanDensityRatio = 0.9f;
  a.fluidIterations = 8;  // 4 and 4
  a.fluidIterationsMax = 4;
  a.maxSpeed = 2.0f;
  a.removedParticles = 1;
  b.substeps = 2;
  b.ms.neighbors = 0.5;
  b.ms.part(StagePart::neighborsLists) = 0.25;
  b.ms.part(StagePart::wettingEmission) = 0.5;
  b.ms.total = 2.0;
  b.couplingContacts = 5;
  b.meanDensityRatio = 1.1f;
  b.fluidIterations = 20;  // 4 and 16
  b.fluidIterationsMax = 16;
  b.maxSpeed = 3.0f;
  b.removedParticles = 2;
  fs.add(a);
  fs.add(b);
  const auto j = frameStatsJson(f.model, f.state, 1, fs);
  EXPECT_EQ(j["frame"], 1);
  EXPECT_DOUBLE_EQ(j["time"].get<double>(), 0.03);
  EXPECT_EQ(j["step"], 2);
  EXPECT_EQ(j["steps"], 2);
  EXPECT_EQ(j["substeps"], 4);
  EXPECT_EQ(j["counts"]["water"], 5);
  EXPECT_EQ(j["counts"]["cloth"], 13);
  EXPECT_EQ(j["couplingContacts"], 15);
  EXPECT_EQ(j["removedAtBounds"]["frame"], 3);
  EXPECT_EQ(j["removedAtBounds"]["total"], 3);
  EXPECT_NEAR(j["meanDensityRatio"].get<double>(), 1.0, 1e-6);
  EXPECT_FLOAT_EQ(j["maxSpeed"].get<float>(), 3.0f);
  EXPECT_DOUBLE_EQ(j["fluidIterations"]["mean"].get<double>(), 7.0);  // 28 over 4 substeps
  EXPECT_EQ(j["fluidIterations"]["max"], 16);
  EXPECT_DOUBLE_EQ(j["ms"]["neighbors"].get<double>(), 1.5);
  EXPECT_DOUBLE_EQ(j["ms"]["total"].get<double>(), 6.0);
  EXPECT_DOUBLE_EQ(j["msPerStep"].get<double>(), 3.0);
  for (const char* stage : {"emit", "predict", "neighbors", "water", "cloth", "coupling", "colliders", "velocities"})
    EXPECT_TRUE(j["ms"].contains(stage)) << stage;
  // the stages' parts, summed over the frame's steps, every one named
  ASSERT_EQ(j["msParts"].size(), static_cast<size_t>(kStagePartCount));
  EXPECT_DOUBLE_EQ(j["msParts"]["neighbors.lists"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(j["msParts"]["wetting.emission"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(j["msParts"]["wetting.absorption"].get<double>(), 0.0);
  // free = sum of water masses (0.0082 + 0.0072 + ... + 0.0042) in float
  double free = 0.0;
  for (int k = 0; k < 5; ++k) free += 0.0082f - 0.001f * k;
  EXPECT_NEAR(j["waterMass"]["free"].get<double>(), free, 1e-9);
  EXPECT_NEAR(j["waterMass"]["total"].get<double>(), free + 0.0123, 1e-9);
  EXPECT_DOUBLE_EQ(j["waterMass"]["emitted"].get<double>(), 0.05);

  // frame 0: no steps, max speed measured on the state, no density ratio yet
  const auto j0 = frameStatsJson(f.model, f.state, 0, FrameStats{});
  EXPECT_TRUE(j0["meanDensityRatio"].is_null());
  EXPECT_FALSE(j0.contains("fluidIterations"));
  // the fastest particle is water particle 4 with v = (0, -1.2, 1.5)
  EXPECT_NEAR(j0["maxSpeed"].get<double>(), std::sqrt(1.2 * 1.2 + 1.5 * 1.5), 1e-5);
  EXPECT_EQ(j0["msPerStep"], 0.0);
}

TEST(IoStats, JsonLinesAreOneObjectPerLine) {
  const fs::path dir = tempDir("jsonl");
  const std::string path = (dir / "stats.jsonl").string();
  {
    JsonLinesWriter w(path);
    w.write({{"frame", 0}});
    w.write({{"frame", 1}, {"error", "boom"}});
  }
  const auto ls = lines(readTextFile(path));
  ASSERT_EQ(ls.size(), 2u);
  EXPECT_EQ(nlohmann::json::parse(ls[1])["error"], "boom");
  fs::remove_all(dir);
}

// every stage part by its name, in StagePart's order, with its time
TEST(IoStats, StagePartsAreNamedInTheirOrder) {
  StageTimes t;
  for (int k = 0; k < kStagePartCount; ++k) t.parts[k] = 0.5 * k + 0.25;
  const nlohmann::ordered_json j = stagePartsJson(t);
  ASSERT_EQ(j.size(), size_t(kStagePartCount));
  int k = 0;
  for (const auto& [name, value] : j.items()) {
    EXPECT_EQ(name, kStagePartNames[k]) << k;
    EXPECT_EQ(value.get<double>(), 0.5 * k + 0.25) << name;
    ++k;
  }
}

// waterMass: free is the mass of the water particles only (not the cloth's), and total adds held, buffered,
// removed and taken water, so it equals emitted while water is conserved
TEST(IoStats, WaterMassAddsEveryStore) {
  Fixture f = makeFixture();
  f.state.clothWater.assign(13, 0.001);
  f.state.clothBuffer.assign(13, 0.0);
  f.state.clothBuffer[4] = 0.002;
  f.state.ledger.removedAtBounds = 0.03;
  f.state.ledger.takenByCloth = 0.004;
  f.state.ledger.emitted = 0.5;
  const WaterMass w = waterMass(f.state);
  double free = 0.0;
  for (int k = 0; k < 5; ++k) free += 0.0082f - 0.001f * k;
  EXPECT_NEAR(w.free, free, 1e-12);
  EXPECT_NEAR(w.heldInCloth, 0.013, 1e-15);
  EXPECT_EQ(w.inBuffers, 0.002);
  EXPECT_EQ(w.emitted, 0.5);
  EXPECT_NEAR(w.total, free + 0.013 + 0.002 + 0.03 + 0.004, 1e-12);
}

// the largest speed of any particle, cloth or water; 0 for an empty state
TEST(IoStats, StateMaxSpeedIsTheFastestParticle) {
  Fixture f = makeFixture();
  f.state.particles.v[2] = Vec3(3.0f, -4.0f, 12.0f);  // a cloth particle at 13 m/s
  EXPECT_FLOAT_EQ(stateMaxSpeed(f.state), 13.0f);
  EXPECT_EQ(stateMaxSpeed(State{}), 0.0f);
}

// the "wetting" section appears with Shao's wetting, the "garment" one with a wet start per vertex
// (counting the wet vertices) or an implicit piece; neither otherwise
TEST(IoStats, WettingAndGarmentSectionsOnlyWhenTheirModelsAreOn) {
  Fixture f = makeFixture();
  const auto plain = frameStatsJson(f.model, f.state, 3, FrameStats{});
  EXPECT_FALSE(plain.contains("wetting"));
  EXPECT_FALSE(plain.contains("garment"));
  f.model.wetting.enabled = true;
  f.state.ledger.particlesAbsorbed = 7;
  f.state.ledger.dripsEmitted = 2;
  f.state.dripId = {40, 41, 42};
  f.state.clothWetStart.assign(13, std::numeric_limits<float>::infinity());
  f.state.clothWetStart[1] = f.state.clothWetStart[5] = 0.5f;
  f.state.ledger.particlesTakenByCloth = 11;
  FrameStats fs;
  StepStats s;
  s.garment.solves = 2;
  s.garment.cgIterations = 30;
  s.garment.cgIterationsMax = 17;
  s.garment.dropsTaken = 4;
  s.garment.maxStrain = 0.05f;
  s.garment.strainLimited = 3;
  s.garment.halvedSteps = 1;
  fs.add(s);
  s.garment.maxStrain = 0.02f;
  fs.add(s);
  const auto j = frameStatsJson(f.model, f.state, 3, fs);
  EXPECT_EQ(j["wetting"]["particlesAbsorbed"], 7);
  EXPECT_EQ(j["wetting"]["dripsEmitted"], 2);
  EXPECT_EQ(j["wetting"]["dripsHanging"], 3);
  EXPECT_EQ(j["garment"]["solves"], 4);
  EXPECT_EQ(j["garment"]["cgIterations"], 60);
  EXPECT_EQ(j["garment"]["cgIterationsMax"], 17);
  EXPECT_FLOAT_EQ(j["garment"]["maxStrain"].get<float>(), 0.05f);  // the largest, not a sum
  EXPECT_EQ(j["garment"]["strainLimited"], 6);
  EXPECT_EQ(j["garment"]["halvedSteps"], 2);
  EXPECT_EQ(j["garment"]["dropsTaken"], 8);
  EXPECT_EQ(j["garment"]["dropsTakenTotal"], 11);
  EXPECT_EQ(j["garment"]["wetVertices"], 2);
}

// how a Chen piece hangs, at the frame's end: its lowest vertex, its mean saturation and its mean
// distance to the nearest collider (absent without colliders); the other piece does not count
TEST(IoStats, GarmentShapeOfTheWettedPieces) {
  Fixture f = makeFixture();
  f.model.pieces[0].wetByContact = true;  // "sheet": 9 vertices; "patch" is not a garment
  f.state.clothWetStart.assign(13, std::numeric_limits<float>::infinity());
  f.state.clothWater.assign(13, 0.0);
  f.state.clothBuffer.assign(13, 0.0);
  f.state.clothSaturation.assign(13, 0.0f);
  f.state.clothSaturation[2] = 0.9f;
  f.state.clothSaturation[11] = 1.0f;  // the patch's
  Particles& p = f.state.particles;
  p.x[4].y() -= 0.25f;
  double lowest = 1e30, height = 0.0;
  for (int i = 0; i < 9; ++i) lowest = std::min(lowest, double(p.x[size_t(i)].y())), height += p.x[size_t(i)].y();
  auto j = frameStatsJson(f.model, f.state, 0, FrameStats{});
  EXPECT_DOUBLE_EQ(j["garment"]["lowestPoint"].get<double>(), lowest);
  EXPECT_NEAR(j["garment"]["meanHeight"].get<double>(), height / 9.0, 1e-7);
  EXPECT_NEAR(j["garment"]["meanSaturation"].get<double>(), 0.1, 1e-7);
  EXPECT_FALSE(j["garment"].contains("meanColliderDistance"));
  Collider ball;
  ball.shape = ColliderShape::Sphere;
  ball.radius = 0.1f;
  ball.keys = {Keyframe{0.0f, Vec3(0.0f, -1.0f, 0.0f), Quat::Identity()}};
  f.model.colliders.push_back(ball);
  double mean = 0.0;
  for (int i = 0; i < 9; ++i) mean += (p.x[size_t(i)] - Vec3(0.0f, -1.0f, 0.0f)).norm() - 0.1;
  j = frameStatsJson(f.model, f.state, 0, FrameStats{});
  EXPECT_NEAR(j["garment"]["meanColliderDistance"].get<double>(), mean / 9.0, 1e-5);
}

}  // namespace
}  // namespace soak
