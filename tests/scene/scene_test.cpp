// scene loading: shipped scenes load and match the paper's figures, defaults are Table 1, and every
// documented error names the file and JSON path (the cloth entries: cloth_keys_test.cpp; the overrides
// and the JSON text layer: overrides_test.cpp)
#include <soak/error.hpp>
#include <soak/scene.hpp>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "scene/scene_support.hpp"
#include "world/colliders.hpp"
#include "world/emitters.hpp"

namespace soak {
namespace {

using namespace soak::testing;

TEST(SceneFiles, EveryShippedSceneLoadsWithADescription) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(SOAK_SOURCE_DIR) / "scenes")) {
    if (entry.path().extension() != ".json") continue;
    SCOPED_TRACE(entry.path().string());
    const Scene s = loadScene(entry.path().string());
    EXPECT_FALSE(s.description.empty());
    EXPECT_EQ(s.name, entry.path().stem().string());
    EXPECT_EQ(s.state.particles.size(), size_t(s.model.numCloth));
    EXPECT_EQ(s.state.emitters.size(), s.model.emitters.size());
    ++count;
  }
  EXPECT_GE(count, 3);
}

// the dry and wet scenes that the gallery and the dry/wet movies compare differ only in the rain: the
// name, the description, the emitters and whether the water is written out
TEST(SceneFiles, DryAndWetTwinsDifferOnlyInTheRain) {
  const auto withoutRain = [](const std::string& name) {
    nlohmann::json j = nlohmann::json::parse(std::ifstream(fs::path(SOAK_SOURCE_DIR) / "scenes" / name));
    for (const char* key : {"name", "description", "emitters"}) j.erase(key);
    j["output"].erase("water");
    return j;
  };
  for (const auto& [dry, wet] : {std::pair{"chen_fig8_silk_sphere_dry.json", "chen_fig8_silk_sphere_wet.json"},
                                 std::pair{"chen_fig9_garment_rain_dry.json", "chen_fig9_garment_rain_wet.json"},
                                 std::pair{"garment_tshirt_moving_dry.json", "garment_tshirt_moving.json"}}) {
    EXPECT_EQ(withoutRain(dry), withoutRain(wet)) << dry << " against " << wet;
    EXPECT_TRUE(loadScene(std::string(SOAK_SOURCE_DIR) + "/scenes/" + dry).model.emitters.empty()) << dry;
    EXPECT_FALSE(loadScene(std::string(SOAK_SOURCE_DIR) + "/scenes/" + wet).model.emitters.empty()) << wet;
  }
}

TEST(SceneFiles, Fig3aHasThePapersParticleCounts) {
  Scene s = loadScene(std::string(SOAK_SOURCE_DIR) + "/scenes/fig3a_cube_on_cloth.json");
  EXPECT_EQ(s.model.numCloth, 14400);  // Table 2: 14.4k cloth particles
  int pinned = 0;
  for (uint8_t p : s.model.clothPinned) pinned += p;
  EXPECT_EQ(pinned, 4);
  const size_t created = emitWater(s.model, s.state, 0.0, s.model.solver.dt);
  EXPECT_EQ(created, 13824u);  // 24^3 water particles (Table 2: 13.8k)
  float lowest = 1e9f, clothY = s.model.clothRestPosition[0].y();
  for (size_t i = size_t(s.model.numCloth); i < s.state.particles.size(); ++i)
    lowest = std::min(lowest, s.state.particles.x[i].y());
  EXPECT_NEAR(lowest - clothY, 0.15f, 0.02f);  // the cube starts ~0.15 m above the cloth
}

TEST(SceneFiles, DamBreakWaterStartsInsideTheContainer) {
  Scene s = loadScene(std::string(SOAK_SOURCE_DIR) + "/scenes/dam_break.json");
  ASSERT_EQ(s.model.colliders.size(), 1u);
  EXPECT_EQ(s.model.numCloth, 0);
  const size_t created = emitWater(s.model, s.state, 0.0, s.model.solver.dt);
  EXPECT_EQ(created, 20u * 30u * 20u);
  const ColliderPose pose = colliderPose(s.model.colliders[0], 0.0);
  for (size_t i = 0; i < s.state.particles.size(); ++i) {
    Vec3 n;
    // outside the walls' solid by at least the water's contact margin (half a spacing), up to rounding
    ASSERT_GE(colliderDistance(s.model.colliders[0], pose, s.state.particles.x[i], &n), 0.5f * 0.02f - 1e-5f)
        << "particle " << i;
  }
}

TEST(SceneDefaults, EqualTable1OfShao2017) {
  const Scene s = fromString(kSmall);
  EXPECT_FLOAT_EQ(s.model.solver.dt, 0.015f);
  EXPECT_FLOAT_EQ(s.model.water.spacing, 0.02f);
  EXPECT_FLOAT_EQ(s.model.water.supportRadius, 0.04f);
  EXPECT_FLOAT_EQ(s.model.water.restDensity, 1000.0f);
  EXPECT_FLOAT_EQ(s.model.water.particleMass, 0.0082f);
  ASSERT_EQ(s.model.pieces.size(), 1u);
  EXPECT_FLOAT_EQ(s.model.pieces[0].material.restDensity, 800.0f);
  // the cloth's default: Table 1's 0.0066 kg particle on its 0.02 m spacing, as an areal density
  EXPECT_FLOAT_EQ(s.model.pieces[0].material.arealDensity, 0.0066f / (0.02f * 0.02f));
  EXPECT_FLOAT_EQ(s.model.pieces[0].material.particleMass, 0.0f);
  EXPECT_FLOAT_EQ(s.model.wetting.referenceArea, 0.02f * 0.02f);
  EXPECT_FLOAT_EQ(s.model.solver.gravity.y(), -9.81f);
  EXPECT_EQ(s.name, "test");  // the stem of the source name
  EXPECT_EQ(s.output.frames, 100);
  EXPECT_TRUE(s.output.clothObj && s.output.clothPly && s.output.water);
}

TEST(SceneBuild, ClothParticlesFollowTheContract) {
  const Scene s = fromString(R"({
    "cloth": [{"mesh": {"type": "rectangle", "size": [0.3, 0.2], "resolution": [4, 3]}},
              {"name": "b", "mesh": {"type": "rectangle", "center": [0, 2, 0], "size": [0.1, 0.1], "resolution": [2, 2]},
               "material": {"particleMass": 0.01}, "pin": {"vertices": [1]}}]})");
  const Particles& p = s.state.particles;
  ASSERT_EQ(p.size(), 16u);
  EXPECT_EQ(s.model.numCloth, 16);
  EXPECT_EQ(s.state.nextId, 16u);
  EXPECT_EQ(s.model.pieces[0].name, "cloth0");
  EXPECT_EQ(s.model.pieces[1].name, "b");
  for (size_t i = 0; i < p.size(); ++i) {
    const bool second = i >= 12;
    EXPECT_EQ(p.phase[i], second ? 2 : 1);
    EXPECT_EQ(p.id[i], uint32_t(i));
    // the first piece weighs the default areal density: 16.5 kg/m^2 x 0.01 m^2 cells (inside, 1/2 at an
    // edge, 1/4 at a corner); the second particleMass
    EXPECT_FLOAT_EQ(p.mass[i], second ? 0.01f : 16.5f * s.model.clothRestArea[i]);
    EXPECT_FLOAT_EQ(p.radius[i], 0.04f);
    EXPECT_TRUE(p.x[i] == s.model.clothRestPosition[i] && p.xPred[i] == p.x[i]);
    EXPECT_TRUE(p.v[i].isZero());
    const bool pinned = i == 13;
    EXPECT_EQ(s.model.clothPinned[i], pinned ? 1 : 0);
    EXPECT_FLOAT_EQ(p.invMass[i], pinned ? 0.0f : 1.0f / p.mass[i]);
  }
  EXPECT_FLOAT_EQ(s.model.clothRestArea[5], 0.01f);  // inside the 4 x 3 grid of 0.1 m cells
  EXPECT_FLOAT_EQ(s.model.clothRestArea[1], 0.005f);
  EXPECT_FLOAT_EQ(s.model.clothRestArea[0], 0.0025f);
}

TEST(SceneBuild, CollidersAndEmittersAreRead) {
  const Scene s = fromString(R"({
    "colliders": [
      {"type": "plane", "normal": [1, 1, 0], "position": [0, -1, 0]},
      {"type": "capsule", "radius": 0.1, "halfHeight": 0.3, "friction": 0.7, "restitution": 0.2,
       "rotation": {"axis": [1, 0, 0], "degrees": 90}},
      {"type": "box", "halfExtents": [1, 2, 3],
       "keyframes": [{"time": 0, "position": [0, 0, 0]}, {"time": 2, "position": [1, 0, 0]}]}],
    "emitters": [{"name": "hose", "type": "jet", "origin": [0, 1, 0], "direction": [0, 0, -3], "speed": 4,
                  "radius": 0.03, "start": 0.5, "end": 2}]})");
  const auto& c = s.model.colliders;
  ASSERT_EQ(c.size(), 3u);
  EXPECT_EQ(c[0].shape, ColliderShape::Plane);
  ASSERT_EQ(c[0].keys.size(), 1u);
  EXPECT_TRUE((c[0].keys[0].rotation * Vec3::UnitY()).isApprox(Vec3(1, 1, 0).normalized(), 1e-5f));
  EXPECT_TRUE(c[0].keys[0].translation.isApprox(Vec3(0, -1, 0)));
  EXPECT_EQ(c[1].shape, ColliderShape::Capsule);
  EXPECT_FLOAT_EQ(c[1].radius, 0.1f);
  EXPECT_FLOAT_EQ(c[1].halfHeight, 0.3f);
  EXPECT_FLOAT_EQ(c[1].friction, 0.7f);
  EXPECT_FLOAT_EQ(c[1].restitution, 0.2f);
  EXPECT_TRUE((c[1].keys[0].rotation * Vec3::UnitY()).isApprox(Vec3(0, 0, 1), 1e-5f));
  ASSERT_EQ(c[2].keys.size(), 2u);
  EXPECT_FLOAT_EQ(c[2].keys[1].time, 2.0f);
  EXPECT_TRUE(c[2].halfExtents.isApprox(Vec3(1, 2, 3)));
  ASSERT_EQ(s.model.emitters.size(), 1u);
  const Emitter& e = s.model.emitters[0];
  EXPECT_EQ(e.kind, EmitterKind::Jet);
  EXPECT_EQ(e.name, "hose");
  EXPECT_TRUE(e.direction.isApprox(Vec3(0, 0, -1)));  // normalised
  EXPECT_FLOAT_EQ(e.start, 0.5f);
  EXPECT_FLOAT_EQ(e.end, 2.0f);
  EXPECT_EQ(s.state.particles.size(), 0u);  // emitters do not run at load
}

TEST(SceneErrors, UnknownKeysAtTopLevelAndNested) {
  EXPECT_HAS(errorWith("solvr.dt=1"), "test.json: at solvr: unknown key 'solvr' (known: name, description, solver,");
  EXPECT_HAS(errorWith("solvr.dt=1"), "did you mean 'solver'?");
  EXPECT_HAS(errorWith("solver.substep=2"), "test.json: at solver.substep: unknown key 'substep' (known: dt, substeps,");
  EXPECT_HAS(errorWith("cloth.0.material.thicknes=0.1"), "at cloth[0].material.thicknes: unknown key 'thicknes'");
  EXPECT_HAS(errorWith("cloth.0.mesh.path=a.obj"),
             "at cloth[0].mesh.path: 'path' is not a key of a rectangle mesh (keys of a rectangle mesh: type, center,");
}

TEST(SceneErrors, WrongTypeAndOutOfRange) {
  EXPECT_HAS(errorWith("solver.dt=fast"), "test.json: at solver.dt: expected a number > 0, got the string \"fast\"");
  EXPECT_HAS(errorWith("solver.dt=0"), "at solver.dt: expected a number > 0, got 0");
  EXPECT_HAS(errorWith("solver.gravity=[0, -9.81]"), "at solver.gravity: expected an array of 3 numbers, got [0,-9.81]");
  EXPECT_HAS(errorWith("cloth.0.material.friction=-0.5"), "at cloth[0].material.friction: expected a number >= 0, got -0.5");
  EXPECT_HAS(errorWith("cloth.0.mesh.resolution=[1, 3]"), "at cloth[0].mesh.resolution[0]: expected an integer >= 2, got 1");
  EXPECT_HAS(errorWith("solver.fluidIterations=0"), "at solver.fluidIterations: expected an integer in [1, 1000], got 0");
  // the most iterations cannot be fewer than the least (4 by default)
  EXPECT_HAS(errorWith("solver.fluidMaxIterations=3"), "at solver.fluidMaxIterations: expected an integer in [4, 1000], got 3");
  EXPECT_HAS(errorWith("solver.fluidTolerance=0"), "at solver.fluidTolerance: expected a number > 0, got 0");
  EXPECT_HAS(errorWith("solver.clothIterations=-1"), "at solver.clothIterations: expected an integer in [0, 1000], got -1");
  EXPECT_HAS(errorWith("cloth.0.material.tetherSlack=-0.1"), "at cloth[0].material.tetherSlack: expected a number >= 0");
  EXPECT_HAS(errorWith("output.water=1"), "at output.water: expected true or false, got 1");
  EXPECT_HAS(errorWith("cloth=3"), "test.json: at cloth: expected an array, got 3");
  EXPECT_HAS(errorWith("cloth.0.mesh.axisV=[0, 0, 0]"), "at cloth[0].mesh.axisV: expected a non-zero direction");
}

TEST(SceneBuild, ViewIsReadForTheRenderer) {
  const Scene none = fromString(kSmall);
  EXPECT_FALSE(none.view.camera || none.view.lookAt || none.view.fov || none.view.zoom);
  const Scene s = fromString(kSmall, {"view={\"camera\": [1, 2, 3], \"lookAt\": [0, 1, 0], \"fov\": 30, \"zoom\": 2}"});
  ASSERT_TRUE(s.view.camera && s.view.lookAt && s.view.fov && s.view.zoom);
  EXPECT_TRUE(s.view.camera->isApprox(Vec3(1, 2, 3)));
  EXPECT_FLOAT_EQ(*s.view.fov, 30.0f);
  EXPECT_FALSE(s.view.azimuth.has_value());
  EXPECT_HAS(errorWith("view.fov=200"), "at view.fov: expected a number in (1, 179)");
  EXPECT_HAS(errorWith("view={\"camera\": [0, 1, 0], \"lookAt\": [0, 1, 0]}"),
             "at view.lookAt: expected a point other than view.camera");
  EXPECT_HAS(errorWith("view.light=1"), "unknown key 'light'");
}

TEST(SceneErrors, BadEnumListsTheAllowedValues) {
  EXPECT_HAS(loadError(R"({"cloth": [], "emitters": [{"type": "block", "min": [0,0,0], "max": [1,1,1]}],
                           "colliders": [{"type": "cube"}]})"),
             "test.json: at colliders[0].type: expected one of \"plane\", \"box\", \"container\", \"sphere\", "
             "\"capsule\", \"mesh\", \"mannequin\", \"meshSequence\", got the string \"cube\"");
  EXPECT_HAS(errorWith("emitters.0.type=hose"), "at emitters[0].type: expected one of \"block\", \"jet\"");
  EXPECT_HAS(errorWith("cloth.0.mesh.type=sphere"), "at cloth[0].mesh.type: expected one of \"rectangle\", \"obj\"");
}

TEST(SceneErrors, KeysOfOtherTypesAreRefused) {
  const std::string base = R"({"emitters": [{"type": "block", "min": [0,0,0], "max": [1,1,1]}], "colliders": [)";
  EXPECT_HAS(loadError(base + R"({"type": "box", "radius": 0.2}]})"),
             "test.json: at colliders[0].radius: 'radius' is not a key of a box collider");
  EXPECT_HAS(loadError(base + R"({"type": "sphere", "normal": [0, 1, 0]}]})"),
             "at colliders[0].normal: 'normal' is not a key of a sphere collider");
  EXPECT_HAS(errorWith("emitters.0.speed=3"), "at emitters[0].speed: 'speed' is not a key of a block emitter");
}

TEST(SceneErrors, CrossFieldChecks) {
  EXPECT_HAS(errorWith("water.supportRadius=0.02"), "at water.supportRadius: expected a number in (water.spacing, 10 x water.spacing] = (0.02, 0.2], got 0.02");
  EXPECT_HAS(errorWith("solver.domain.max=[1, -20, 1]"), "at solver.domain.max: expected every component greater than");
  EXPECT_HAS(errorWith("emitters.0.max=[0, 1, 0]"), "at emitters[0].max: expected every component greater than min");
  EXPECT_HAS(errorWith("emitters.0.min=[-30, 1, 0]"), "at emitters[0]: expected a block inside solver.domain");
  EXPECT_HAS(errorWith("cloth.0.mesh.axisV=[1, 0.5, 0]"), "at cloth[0].mesh.axisV: expected a direction perpendicular to axisU");
  const std::string jet = R"({"emitters": [{"type": "jet", "origin": [0, 0, 0], "start": 2, "end": 1}]})";
  EXPECT_HAS(loadError(jet), "at emitters[0].end: expected a time > start (2 s), got 1");
  const std::string keys = R"({"cloth": [{"mesh": {"type": "rectangle", "size": [1, 1], "resolution": [2, 2]}}],
      "colliders": [{"type": "sphere", "position": [0, 0, 0], "keyframes": [{"time": 1}, {"time": 1}]}]})";
  const std::string keysError = loadError(keys);
  EXPECT_HAS(keysError, "at colliders[0].keyframes[1].time: expected a time > the previous keyframe's (1 s), got 1");
  EXPECT_HAS(keysError, "at colliders[0].keyframes: expected either position/rotation or keyframes, got both");
}

TEST(SceneErrors, EmptySceneAndMissingRequiredKeys) {
  EXPECT_HAS(loadError(R"({"name": "nothing", "cloth": []})"),
             "test.json: at (top level): expected at least one cloth piece or emitter, got none");
  EXPECT_HAS(loadError(R"([1, 2])"), "test.json: at (top level): expected a JSON object at the top level, got [1,2]");
  EXPECT_HAS(loadError(R"({"cloth": [{"name": "a"}]})"), "at cloth[0].mesh: expected an object, got nothing (the key is required)");
  EXPECT_HAS(loadError(R"({"cloth": [{"mesh": {"type": "rectangle", "resolution": [2, 2]}}]})"),
             "at cloth[0].mesh.size: expected an array of 2 numbers > 0, got nothing (the key is required)");
}

TEST(SceneErrors, AllErrorsAreReportedTogether) {
  const std::string msg = loadError(kSmall, {"solver.dt=-1", "water.viscosity=2", "output.frames=0"});
  EXPECT_HAS(msg, "at solver.dt:");
  EXPECT_HAS(msg, "at water.viscosity:");
  EXPECT_HAS(msg, "at output.frames:");
  EXPECT_EQ(std::count(msg.begin(), msg.end(), '\n'), 2);
}

TEST(SceneErrors, NegativeHyperviscosityIsRefused) {
  EXPECT_HAS(loadError(kSmall, {"water.hyperviscosity=-1"}), "at water.hyperviscosity: expected a number >= 0, got -1");
}

TEST(SceneErrors, LongErrorListsAreCut) {
  std::string many = "[";
  for (int i = 0; i < 80; ++i) many += (i ? ", " : "") + std::to_string(100 + i);
  const std::string msg = errorWith("cloth.0.pin.vertices=" + many + "]");
  EXPECT_HAS(msg, "at cloth[0].pin.vertices[0]: expected an integer in [0, 11], got 100");
  EXPECT_HAS(msg, "at cloth[0].pin.vertices[49]:");
  EXPECT_EQ(msg.find("vertices[50]"), std::string::npos);
  EXPECT_HAS(msg, "test.json: and 30 more errors");
}

TEST(SceneErrors, FileErrorsNameTheFile) {
  TempDir dir;
  const std::string path = dir.write("bad.json", R"({"cloth": [{"mesh": {"type": "rectangle", "size": [1, 1],
      "resolution": [2, 2]}, "material": {"thickness": -0.01}}]})");
  try {
    loadScene(path);
    FAIL() << "a negative thickness loaded";
  } catch (const Error& e) {
    EXPECT_HAS(std::string(e.what()), path + ": at cloth[0].material.thickness: expected a number > 0, got -0.01");
  }
  EXPECT_THROW(loadScene((dir.path / "absent.json").string()), Error);
}

}  // namespace
}  // namespace soak
