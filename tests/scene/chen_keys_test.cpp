// scene keys of the Chen 2012 models (scene/chen_keys.cpp): mannequin, mesh collider, rain, procedural
// garment and a cloth piece's solver, fabric, saturation, garment and body settings reach the model, and
// every refusal names the file, the JSON path and what was expected
#include "scene/chen_keys.hpp"

#include <soak/error.hpp>
#include <soak/scene.hpp>

#include <gtest/gtest.h>

#include "support/garment_scene.hpp"
#include "world/colliders.hpp"
#include "world/garment_mesh.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

namespace soak {
namespace {

using namespace soak::testing;

TEST(GarmentScene, KeysReachTheModel) {
  const Scene s = fromString(R"({
    "colliders": [{"name": "body", "type": "mannequin", "height": 1.6, "yaw": 90, "friction": 0.4,
                   "pose": {"shoulderAbduction": [45, 45]}}],
    "cloth": [{"name": "shirt", "solver": "implicit", "fabric": "high_absorption",
               "mesh": {"type": "garment", "body": "body", "edgeLength": 0.04},
               "saturation": {"timeScale": 60},
               "garment": {"shear": {"a1": 50, "a2": 1}, "rayleigh": {"beta": 0.002},
                           "friction": {"peak": 0.7, "peakSaturation": 0.1, "plateauSaturation": 0.3},
                           "wrinkles": {"interval": 5}}}],
    "emitters": [{"type": "rain", "origin": [0, 2, 0], "halfExtents": [0.5, 0.3], "rate": 100}]})");
  const Model& m = s.model;
  // one smooth body of 18 parts, blended over 0.02 of its height (the default)
  ASSERT_EQ(m.colliders.size(), 1u);
  const Collider& body = m.colliders[0];
  EXPECT_EQ(body.name, "body");
  EXPECT_EQ(body.shape, ColliderShape::Body);
  EXPECT_FLOAT_EQ(body.blendRadius, 0.02f * 1.6f);
  EXPECT_FLOAT_EQ(body.friction, 0.4f);
  ASSERT_TRUE(body.parts);
  ASSERT_EQ(body.parts->size(), 18u);
  EXPECT_EQ(body.parts->front().name, "body.head");
  EXPECT_EQ(body.parts->back().name, "body.foot_r");
  EXPECT_FLOAT_EQ((*body.parts)[3].friction, 0.4f);
  ASSERT_EQ(m.pieces.size(), 1u);
  const ClothPiece& p = m.pieces[0];
  EXPECT_EQ(p.solver, ClothSolver::Implicit);
  EXPECT_FLOAT_EQ(p.garment.saturation.delta, 2.492f);  // Table 1, high-absorption fabric
  EXPECT_FLOAT_EQ(p.garment.saturation.timeScale, 60.0f);
  EXPECT_TRUE(p.garment.saturationMass);                // implicit, no Shao wetting: on by default
  EXPECT_TRUE(p.wetByContact);
  EXPECT_FLOAT_EQ(p.garment.laws.shear.a1, 50.0f);
  EXPECT_FLOAT_EQ(p.garment.rayleighBeta, 0.002f);
  EXPECT_FLOAT_EQ(p.garment.friction.peak, 0.7f);
  EXPECT_TRUE(p.garment.wrinkles.enabled);              // a present section is on
  EXPECT_EQ(p.garment.wrinkles.interval, 5);
  EXPECT_TRUE(p.material.selfCollision);  // on by default for both solvers
  // the garment's panels are the wrinkle subdomains; no PBD constraints or tethers for it
  EXPECT_EQ(p.panelOfVertex.size(), size_t(p.particleCount));
  EXPECT_TRUE(m.stretch.ids.empty());
  EXPECT_TRUE(m.bend.ids.empty());
  EXPECT_TRUE(m.tethers.anchor.empty());
  for (int i = 0; i < m.numCloth; ++i) EXPECT_TRUE(m.implicitCloth(i));
  EXPECT_EQ(s.state.clothWetStart.size(), size_t(m.numCloth));
  ASSERT_EQ(m.emitters.size(), 1u);
  EXPECT_EQ(m.emitters[0].kind, EmitterKind::Rain);
  EXPECT_FLOAT_EQ(m.emitters[0].halfExtents.z(), 0.3f);
  // the garment starts outside the body by its margin
  for (int i = 0; i < m.numCloth; ++i)
    EXPECT_GE(bodyDistance(m.colliders, 0.0, s.state.particles.x[size_t(i)], nullptr), 0.0099f) << i;
}

TEST(GarmentScene, MannequinPoseKeyframesAnimateItsColliders) {
  const Scene s = fromString(R"({
    "colliders": [{"name": "body", "type": "mannequin",
                   "keyframes": [{"time": 0, "pose": {"shoulderAbduction": [45, 45]}},
                                 {"time": 1, "pose": {"shoulderAbduction": [45, 45], "elbowFlexion": [90, 0]}}]}],
    "emitters": [{"type": "rain", "origin": [0, 2, 0], "halfExtents": [0.5, 0.5]}]})");
  ASSERT_EQ(s.model.colliders.size(), 1u);
  const Collider& body = s.model.colliders[0];
  ASSERT_TRUE(body.parts);
  const std::vector<Collider>& c = *body.parts;
  const auto find = [&](const std::string& name) -> size_t {
    for (size_t k = 0; k < c.size(); ++k)
      if (c[k].name == name) return k;
    throw Error("no part " + name);
  };
  const size_t left = find("body.hand_l"), right = find("body.hand_r");
  EXPECT_GT(c[left].keys.size(), 20u);  // sampled every 1/30 s
  const ColliderPose p0 = colliderPose(body, 0.0), p1 = colliderPose(body, 1.0);
  const Vec3 l0 = p0.parts[left].translation, l1 = p1.parts[left].translation;
  const Vec3 r0 = p0.parts[right].translation, r1 = p1.parts[right].translation;
  EXPECT_GT((l1 - l0).norm(), 0.1f);   // the bent left elbow brings the hand forward
  EXPECT_GT(l1.z(), l0.z() + 0.1f);
  EXPECT_LT((r1 - r0).norm(), 1e-4f);  // the right arm keeps its pose
  // the skin moves with the hand: the body's surface velocity at the left hand is the hand's
  const ColliderPose mid = colliderPose(body, 0.5);
  const Vec3 onHand = mid.parts[left].translation + Vec3(c[left].radius, 0, 0);
  EXPECT_LT((colliderVelocity(body, mid, onHand) - mid.parts[left].velocityAt(onHand)).norm(), 1e-5f);
  EXPECT_GT(mid.parts[left].velocityAt(onHand).norm(), 0.1f);
  EXPECT_HAS(loadError(R"({"colliders": [{"name": "b", "type": "mannequin", "pose": {},
                                          "keyframes": [{"time": 0, "pose": {}}]}],
                           "emitters": [{"type": "rain", "origin": [0, 2, 0], "halfExtents": [1, 1]}]})"),
             "at colliders[0].keyframes: expected either pose or keyframes, got both");
}

TEST(GarmentSceneErrors, UnknownFabricListsTheKnownOnes) {
  EXPECT_HAS(loadError(kSheet, {"cloth.0.fabric=denim"}),
             "garment.json: at cloth[0].fabric: expected one of \"cotton\", \"coarse_wool\", \"high_absorption\", "
             "got the string \"denim\"");
}

TEST(GarmentSceneErrors, KeysOfTheOtherSolverAreRefused) {
  EXPECT_HAS(loadError(kSheet, {"cloth.0.material.stretchCompliance=0.1"}),
             "at cloth[0].material.stretchCompliance: expected no stretchCompliance on a piece with \"solver\": "
             "\"implicit\"");
  EXPECT_HAS(loadError(kSheet, {"cloth.0.material.tetherSlack=0.1"}),
             "at cloth[0].material.tetherSlack: expected no tetherSlack on a piece with \"solver\": \"implicit\"");
  EXPECT_HAS(loadError(kSheet, {"cloth.0.solver=pbd"}), "at cloth[0].garment: expected no garment section on a piece "
                                                         "solved by PBD");
  EXPECT_HAS(loadError(kSheet, {"cloth.0.solver=verlet"}), "at cloth[0].solver: expected one of \"pbd\", \"implicit\"");
  EXPECT_HAS(loadError(kSheet, {"cloth.0.garment.rayleigh.alpha=-9"}),
             "at cloth[0].garment.rayleigh.alpha: expected a number >= 0 (1/s; a negative alpha adds energy");
  EXPECT_HAS(loadError(kSheet, {"cloth.0.garment.friction.plateauSaturation=0.1"}),
             "at cloth[0].garment.friction.plateauSaturation: expected a saturation > friction.peakSaturation (0.2), "
             "got 0.1");
  // the curve was over time once: the old keys are refused with what to give instead
  EXPECT_HAS(loadError(kSheet, {"cloth.0.garment.friction.tau1=2"}),
             "at cloth[0].garment.friction.tau1: expected no times: the friction curve follows the saturation");
  EXPECT_HAS(loadError(kSheet, {"cloth.0.garment.friction.peakSaturation=1"}),
             "at cloth[0].garment.friction.peakSaturation: expected a number in");
  EXPECT_HAS(loadError(kSheet, {"cloth.0.garment.stretch.a1=0"}), "at cloth[0].garment.stretch.a1: expected a number > 0");
}

TEST(GarmentSceneErrors, SaturationMassAndShaoWettingExcludeEachOther) {
  EXPECT_HAS(loadError(kSheet, {"wetting.enabled=true", "cloth.0.saturation.enabled=true"}),
             "at cloth[0].saturation.enabled: expected false while the wetting section is on");
  // with Shao's wetting the implicit piece's mass comes from the water it holds
  const Scene s = fromString(kSheet, {"wetting.enabled=true", "wetting.emission.massThreshold=1e-5"});
  EXPECT_FALSE(s.model.pieces[0].garment.saturationMass);
  EXPECT_TRUE(s.model.pieces[0].wetByContact);
}

TEST(GarmentSceneErrors, GarmentNeedsAMannequinAndRoomForItsArms) {
  const std::string body = R"({"colliders": [{"name": "body", "type": "mannequin", "pose": {"shoulderAbduction": [45, 45]}}],
    "cloth": [{"solver": "implicit", "mesh": {"type": "garment", "body": "bob"}}]})";
  EXPECT_HAS(loadError(body), "at cloth[0].mesh.body: expected the name of a mannequin collider (known: body), got \"bob\"");
  EXPECT_HAS(loadError(body, {"cloth.0.mesh.body=body", "colliders.0.pose.shoulderAbduction=[5, 5]"}),
             "at cloth[0].mesh");
  EXPECT_HAS(loadError(body, {"cloth.0.mesh.body=body", "colliders.0.pose.elbowFlexion=[400, 0]"}),
             "at colliders[0].pose.elbowFlexion[0]: expected a number in [-180, 180]");
}

TEST(GarmentSceneErrors, ClothStartingInsideTheBodyIsPushedOutOrRefusedNamingVertices) {
  // a sheet through the middle of a ball
  const std::string scene = R"({
    "colliders": [{"name": "ball", "type": "sphere", "radius": 0.1, "position": [0, 1, 0]}],
    "cloth": [{"mesh": {"type": "rectangle", "center": [0, 1, 0], "size": [0.4, 0.4], "resolution": [9, 9]},
               "body": {"name": "ball", "pushOut": false}}]})";
  const std::string err = loadError(scene);
  EXPECT_HAS(err, "garment.json: at cloth[0].mesh: expected every vertex at least 0.005 m outside \"ball\" at t = 0, "
                  "got 13 vertices inside: 22, 30, 31, 32, 38, 39, 40, 41, 42, 48, 49, 50 and 1 more");
  EXPECT_HAS(loadError(scene, {"cloth.0.body.name=rock"}), "at cloth[0].body.name: expected the name of a collider or "
                                                           "mannequin (known: ball), got \"rock\"");
  // a ball poking 1.5 cm up through the sheet: the vertices over it are pushed out, the rest stay
  const Scene pushed = fromString(scene, {"cloth.0.body.pushOut=true", "colliders.0.position=[0, 0.915, 0]"});
  int moved = 0;
  for (int i = 0; i < pushed.model.numCloth; ++i) {
    const Vec3 x = pushed.state.particles.x[size_t(i)];
    EXPECT_GE((x - Vec3(0, 0.915f, 0)).norm(), 0.105f - 1e-4f) << i;
    moved += x.y() > 1.0f + 1e-5f ? 1 : 0;
  }
  EXPECT_GT(moved, 0);
}

TEST(GarmentScene, MeshColliderFromAnObjFile) {
  // a closed unit cube, outward winding
  const std::string dir = ::testing::TempDir();
  const std::string obj = dir + "/soak_cube_collider.obj";
  std::ofstream(obj) << "v -0.5 -0.5 -0.5\nv 0.5 -0.5 -0.5\nv 0.5 0.5 -0.5\nv -0.5 0.5 -0.5\n"
                        "v -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\nv 0.5 0.5 0.5\nv -0.5 0.5 0.5\n"
                        "f 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\n"
                        "f 4 8 7\nf 4 7 3\nf 1 5 8\nf 1 8 4\nf 2 3 7\nf 2 7 6\n";
  const std::string scene = R"({"colliders": [{"name": "rock", "type": "mesh", "path": ")" + obj +
                            R"(", "resolution": 0.05, "position": [0, 1, 0]}],
    "emitters": [{"type": "block", "min": [-0.1, 2, -0.1], "max": [0.1, 2.2, 0.1]}]})";
  const Scene s = fromString(scene);
  ASSERT_EQ(s.model.colliders.size(), 1u);
  const Collider& c = s.model.colliders[0];
  EXPECT_EQ(c.shape, ColliderShape::Mesh);
  ASSERT_TRUE(c.sdf != nullptr);
  // the cube's top face is at y = 1.5 in the world
  EXPECT_NEAR(colliderDistance(c, colliderPose(c, 0.0), Vec3(0, 1.7f, 0), nullptr), 0.2f, 0.02f);
  EXPECT_LT(colliderDistance(c, colliderPose(c, 0.0), Vec3(0, 1.0f, 0), nullptr), 0.0f);
  EXPECT_HAS(loadError(scene, {"colliders.0.path=nowhere.obj"}),
             "at colliders[0].path: expected the path of an existing OBJ file, got \"nowhere.obj\"");
  EXPECT_HAS(loadError(scene, {"colliders.0.radius=1"}), "'radius' is not a key of a mesh collider");
}

// a "meshSequence" collider reads its frames by the pattern (scaled, played at fps from start, moved by
// its pose); a missing fps, no frame found, a range that is not complete or a key of another type is
// refused naming the path
TEST(GarmentScene, MeshSequenceColliderFromObjFrames) {
  const std::string dir = ::testing::TempDir() + "/soak_sequence_scene";
  std::filesystem::create_directories(dir);
  for (int f = 1; f <= 3; ++f)  // a cube of 100 cm (scale 0.01: 1 m) whose top rises 10 cm a frame
    writeBoxObj(dir + "/lift_" + std::to_string(f) + ".obj", Vec3(-50, -50, -50), Vec3(50, 50 + 10 * (f - 1), 50));
  const std::string scene = R"({"colliders": [{"name": "lift", "type": "meshSequence", "path": ")" + dir +
                            R"(/lift_#.obj", "fps": 10, "start": 0.5, "scale": 0.01, "position": [0, 1, 0]}],
    "emitters": [{"type": "block", "min": [-0.1, 2, -0.1], "max": [0.1, 2.2, 0.1]}]})";
  const Scene s = fromString(scene);
  ASSERT_EQ(s.model.colliders.size(), 1u);
  const Collider& c = s.model.colliders[0];
  EXPECT_EQ(c.shape, ColliderShape::MeshSequence);
  ASSERT_TRUE(c.sequence != nullptr);
  // the top at y = 1.5 until t = 0.5, then rising 1 m/s to 1.7 at t = 0.7
  for (const auto& [t, top] : {std::pair{0.0, 1.5f}, {0.55, 1.55f}, {0.65, 1.65f}, {3.0, 1.7f}})
    EXPECT_NEAR(colliderDistance(c, colliderPose(c, t), Vec3(0, 2.0f, 0), nullptr), 2.0f - top, 1e-5f) << t;
  EXPECT_NEAR(colliderVelocity(c, colliderPose(c, 0.6), Vec3(0, 1.61f, 0)).y(), 1.0f, 1e-4f);
  EXPECT_HAS(loadError(scene, {"colliders.0.fps=0"}), "at colliders[0].fps: expected a number > 0");
  EXPECT_HAS(loadError(scene, {"colliders.0.path=" + dir + "/lift_##.obj"}), "at colliders[0].path: ");
  EXPECT_HAS(loadError(scene, {"colliders.0.path=" + dir + "/lift_##.obj"}), "found none");
  EXPECT_HAS(loadError(scene, {"colliders.0.lastFrame=4"}), "lift_4.obj: at mesh sequence: expected frame 4");
  EXPECT_HAS(loadError(scene, {"colliders.0.firstFrame=3", "colliders.0.lastFrame=2"}),
             "at colliders[0].lastFrame: expected a frame >= firstFrame (3), got 2");
  EXPECT_HAS(loadError(scene, {"colliders.0.radius=1"}), "'radius' is not a key of a meshSequence collider");
  std::filesystem::remove_all(dir);
}

// every key of a rain emitter reaches the Emitter (halfExtents are x and z, the direction is normalised);
// an end not after the start is refused naming the path and the start
TEST(ChenKeys, RainKeysReachTheEmitterAndEndMustFollowStart) {
  const std::string rain = R"({"emitters": [{"name": "shower", "type": "rain", "origin": [0.1, 1.9, -0.2],
      "halfExtents": [0.3, 0.2], "rate": 450, "dropSpeed": 3.5, "dropRadius": 0.003, "direction": [0, -2, 0],
      "start": 0.25, "end": 1.5}]})";
  const Scene s = fromString(rain);
  ASSERT_EQ(s.model.emitters.size(), 1u);
  const Emitter& e = s.model.emitters[0];
  EXPECT_EQ(e.kind, EmitterKind::Rain);
  EXPECT_EQ(e.origin, Vec3(0.1f, 1.9f, -0.2f));
  EXPECT_EQ(e.halfExtents, Vec3(0.3f, 0.0f, 0.2f));
  EXPECT_FLOAT_EQ(e.rate, 450.0f);
  EXPECT_FLOAT_EQ(e.dropSpeed, 3.5f);
  EXPECT_FLOAT_EQ(e.dropRadius, 0.003f);
  EXPECT_EQ(e.direction, Vec3(0, -1, 0));
  EXPECT_FLOAT_EQ(e.start, 0.25f);
  EXPECT_FLOAT_EQ(e.end, 1.5f);
  EXPECT_HAS(loadError(rain, {"emitters.0.end=0.2"}),
             "garment.json: at emitters[0].end: expected a time > start (0.25 s), got 0.2");
  EXPECT_HAS(loadError(rain, {"emitters.0.halfExtents=[0.3]"}), "at emitters[0].halfExtents: expected an array of 2");
  EXPECT_HAS(loadError(rain, {"emitters.0.rate=0"}), "at emitters[0].rate: expected a number > 0, got 0");
  EXPECT_HAS(loadError(rain, {"emitters.0.direction=[0, 0, 0]"}), "at emitters[0].direction: expected a non-zero direction");
}

// the implicit solver's keys: KES laws, strain limit, bend straightness, wet friction of Fig. 5, Rayleigh
// damping, CG settings and the wrinkle model all reach ClothPiece::garment
TEST(ChenKeys, GarmentSolverKeysReachThePiece) {
  const Scene s = fromString(kSheet, {R"(cloth.0.garment={"stretch": {"a1": 700, "a2": 2}, "shear": {"a1": 60, "a2": 0.5},
      "bend": {"a1": 3, "a2": 1}, "strainLimit": 0.7, "strainLimiting": false, "bendStraightness": 0.6,
      "friction": {"dry": 0.2, "peak": 0.9, "plateau": 0.4, "peakSaturation": 0.15, "plateauSaturation": 0.8},
      "rayleigh": {"alpha": 0.5, "beta": 0.001}, "cg": {"tolerance": 1e-6, "maxIterations": 77, "preconditioner": "cholesky", "warmStart": true},
      "wrinkles": {"compressionThreshold": 0.1, "equilibriumSpeed": 0.3, "interval": 4, "patchSize": 50,
                   "tieTolerance": 0.01, "strength": 0.5, "dryStrength": 0.25, "seed": 9}})"});
  const GarmentParams& g = s.model.pieces[0].garment;
  EXPECT_FLOAT_EQ(g.laws.stretch.a1, 700.0f);
  EXPECT_FLOAT_EQ(g.laws.stretch.a2, 2.0f);
  EXPECT_FLOAT_EQ(g.laws.shear.a2, 0.5f);
  EXPECT_FLOAT_EQ(g.laws.bend.a1, 3.0f);
  EXPECT_FLOAT_EQ(g.laws.strainLimit, 0.7f);
  EXPECT_FALSE(g.strainLimiting);
  EXPECT_FLOAT_EQ(g.build.bendStraightness, 0.6f);
  EXPECT_FLOAT_EQ(g.friction.dry, 0.2f);
  EXPECT_FLOAT_EQ(g.friction.peak, 0.9f);
  EXPECT_FLOAT_EQ(g.friction.plateau, 0.4f);
  EXPECT_FLOAT_EQ(g.friction.peakSaturation, 0.15f);
  EXPECT_FLOAT_EQ(g.friction.plateauSaturation, 0.8f);
  EXPECT_FLOAT_EQ(g.rayleighAlpha, 0.5f);
  EXPECT_FLOAT_EQ(g.rayleighBeta, 0.001f);
  EXPECT_FLOAT_EQ(g.cgTolerance, 1e-6f);
  EXPECT_EQ(g.cgMaxIterations, 77);
  EXPECT_EQ(g.cgPreconditioner, CgPreconditioner::Cholesky);
  EXPECT_TRUE(g.cgWarmStart);
  EXPECT_TRUE(g.wrinkles.enabled);
  EXPECT_FLOAT_EQ(g.wrinkles.compressionThreshold, 0.1f);
  EXPECT_FLOAT_EQ(g.wrinkles.equilibriumSpeed, 0.3f);
  EXPECT_EQ(g.wrinkles.interval, 4);
  EXPECT_EQ(g.wrinkles.patchSize, 50);
  EXPECT_FLOAT_EQ(g.wrinkles.tieTolerance, 0.01f);
  EXPECT_FLOAT_EQ(g.wrinkles.strength, 0.5f);
  EXPECT_FLOAT_EQ(g.wrinkles.dryStrength, 0.25f);
  EXPECT_EQ(g.wrinkles.seed, 9u);
  // absent sections keep the defaults; wrinkles stay off unless their section is there
  const GarmentParams& d = fromString(kSheet, {"cloth.0.garment={}"}).model.pieces[0].garment;
  const GarmentParams defaults;
  EXPECT_FALSE(d.wrinkles.enabled);
  EXPECT_EQ(d.laws.shear.a1, defaults.laws.shear.a1);
  EXPECT_EQ(d.friction.peak, defaults.friction.peak);
  EXPECT_EQ(d.cgMaxIterations, defaults.cgMaxIterations);
  EXPECT_EQ(d.cgPreconditioner, CgPreconditioner::BlockJacobi);
  EXPECT_EQ(d.cgWarmStart, defaults.cgWarmStart);
  EXPECT_TRUE(d.strainLimiting);
  EXPECT_EQ(fromString(kSheet, {"cloth.0.garment.cg.preconditioner=gaussSeidel"}).model.pieces[0].garment.cgPreconditioner,
            CgPreconditioner::GaussSeidel);
  EXPECT_HAS(loadError(kSheet, {"cloth.0.garment.cg.warmStart=1"}), "at cloth[0].garment.cg.warmStart");
  EXPECT_HAS(loadError(kSheet, {"cloth.0.garment.strainLimiting=\"yes\""}), "at cloth[0].garment.strainLimiting");
  EXPECT_HAS(loadError(kSheet, {"cloth.0.garment.cg.preconditioner=ilu"}),
             "at cloth[0].garment.cg.preconditioner: expected one of \"blockJacobi\", \"cholesky\"");
  EXPECT_HAS(loadError(kSheet, {"cloth.0.garment.wrinkles.patchSize=2"}),
             "at cloth[0].garment.wrinkles.patchSize: expected an integer >= 3, got 2");
  EXPECT_HAS(loadError(kSheet, {"cloth.0.garment.strainLimit=1.5"}), "at cloth[0].garment.strainLimit: expected a number in");
  EXPECT_HAS(loadError(kSheet, {"cloth.0.garment.stretch.a3=1"}), "at cloth[0].garment.stretch.a3: unknown key 'a3'");
  EXPECT_HAS(loadError(kSheet, {R"(cloth.0.garment.wrinkles={"strength": 0.2, "dryStrength": 0.3})"}),
             "at cloth[0].garment.wrinkles.dryStrength: expected a fraction <= wrinkles.strength (0.2), got 0.3");
}

// the fabric sets delta and a3 (Table 1), explicit saturation keys override them; the supply is the
// drops unless "unlimited"; wetAtStart wets every vertex from t = 0 (with the drops supply: full, its
// water counted as emitted); dropsVanish false needs the unlimited supply, and has no meaning, and is
// refused, with Shao's wetting on
TEST(ChenKeys, SaturationKeysOverrideTheFabricAndWetAtStart) {
  const Scene s = fromString(kSheet, {"cloth.0.fabric=cotton", "cloth.0.saturation.delta=2",
                                      "cloth.0.saturation.wetAtStart=true", "cloth.0.saturation.supply=\"unlimited\"",
                                      "cloth.0.saturation.dropsVanish=false"});
  const ClothPiece& p = s.model.pieces[0];
  EXPECT_FLOAT_EQ(p.garment.saturation.delta, 2.0f);
  EXPECT_FLOAT_EQ(p.garment.saturation.a3, 8.844f);  // cotton's
  EXPECT_TRUE(p.garment.saturation.unlimitedSupply);
  EXPECT_FALSE(p.dropsVanish);
  ASSERT_EQ(s.state.clothWetStart.size(), size_t(s.model.numCloth));
  for (float t : s.state.clothWetStart) EXPECT_EQ(t, 0.0f);
  EXPECT_EQ(s.state.ledger.emitted, 0.0) << "an unlimited supply holds no counted water";
  const Scene soaked = fromString(kSheet, {"cloth.0.saturation.wetAtStart=true"});
  EXPECT_FALSE(soaked.model.pieces[0].garment.saturation.unlimitedSupply);
  double held = 0.0;
  for (int i = 0; i < soaked.model.numCloth; ++i) {
    EXPECT_NEAR(soaked.state.clothWater[size_t(i)], 1.24 * double(soaked.model.clothDryMass[size_t(i)]), 1e-10);
    EXPECT_EQ(soaked.state.clothSaturation[size_t(i)], 1.0f);
    held += soaked.state.clothWater[size_t(i)];
  }
  EXPECT_DOUBLE_EQ(soaked.state.ledger.emitted, held);
  const Scene dry = fromString(kSheet);
  for (float t : dry.state.clothWetStart) EXPECT_EQ(t, std::numeric_limits<float>::infinity());
  EXPECT_EQ(dry.state.clothWater, std::vector<double>(size_t(dry.model.numCloth), 0.0));
  EXPECT_HAS(loadError(kSheet, {"cloth.0.saturation.dropsVanish=false"}),
             "at cloth[0].saturation.dropsVanish: expected true, or saturation.supply \"unlimited\"");
  EXPECT_HAS(loadError(kSheet, {"cloth.0.saturation.supply=\"rain\""}),
             "at cloth[0].saturation.supply: expected one of \"drops\", \"unlimited\"");
  EXPECT_HAS(loadError(kSheet, {"wetting.enabled=true", "wetting.emission.massThreshold=1e-5",
                                "cloth.0.saturation.dropsVanish=true"}),
             "garment.json: at cloth[0].saturation.dropsVanish: expected no dropsVanish while the wetting section is on");
  EXPECT_HAS(loadError(kSheet, {"cloth.0.saturation.a3=0"}), "at cloth[0].saturation.a3: expected a number > 0, got 0");
  // a PBD piece has no saturation mass unless asked, and is then not wetted by contact
  const Scene pbd = fromString(R"({"cloth": [{"mesh": {"type": "rectangle", "size": [0.2, 0.2], "resolution": [3, 3]}}]})");
  EXPECT_FALSE(pbd.model.pieces[0].garment.saturationMass);
  EXPECT_FALSE(pbd.model.pieces[0].wetByContact);
  EXPECT_TRUE(pbd.state.clothWetStart.empty());
}

// "body" with a margin: every vertex within margin of the ball (radius 0.1 m) is refused. The 9 x 9 sheet
// has 0.05 m spacing through the ball's centre, so the vertices closer than r + margin are those with
// i^2 + j^2 < ((r + margin) / 0.05)^2: 13 at the default margin (half the 0.01 m thickness), 21 at 0.02 m
TEST(ChenKeys, BodyMarginCountsTheVerticesInside) {
  const std::string scene = R"({
    "colliders": [{"name": "ball", "type": "sphere", "radius": 0.1, "position": [0, 1, 0]}],
    "cloth": [{"mesh": {"type": "rectangle", "center": [0, 1, 0], "size": [0.4, 0.4], "resolution": [9, 9]},
               "body": {"name": "ball", "pushOut": false, "margin": 0.02}}]})";
  EXPECT_HAS(loadError(scene), "at cloth[0].mesh: expected every vertex at least 0.02 m outside \"ball\" at t = 0, "
                               "got 21 vertices inside: ");
  EXPECT_HAS(loadError(scene, {"cloth.0.body.margin=0.08"}), "got 37 vertices inside");
  EXPECT_HAS(loadError(scene, {"cloth.0.body.margin=-1"}), "at cloth[0].body.margin: expected a number >= 0, got -1");
  // a ball whose top is 0.01 m under the middle vertex (40; its neighbours are 0.0208 m away): inside a
  // 0.02 m margin, outside a 0.005 m one
  EXPECT_HAS(loadError(scene, {"colliders.0.position=[0, 0.89, 0]"}), "got 1 vertices inside: 40");
  EXPECT_EQ(loadError(scene, {"colliders.0.position=[0, 0.89, 0]", "cloth.0.body.margin=0.005"}), "");
}

// a dress: two panels (front, back); the pattern's keys are range checked, and a garment in a scene
// without a mannequin says there is none
TEST(ChenKeys, GarmentMeshKeysAndTheirRefusals) {
  const std::string dress = R"({
    "colliders": [{"name": "body", "type": "mannequin", "pose": {"shoulderAbduction": [25, 25]}}],
    "cloth": [{"solver": "implicit", "mesh": {"type": "garment", "style": "dress", "body": "body", "edgeLength": 0.05}}]})";
  const Scene s = fromString(dress);
  const ClothPiece& p = s.model.pieces[0];
  ASSERT_EQ(p.panelOfVertex.size(), size_t(p.particleCount));
  int most = 0;
  for (int id : p.panelOfVertex) most = std::max(most, id);
  EXPECT_EQ(most, 1);  // front and back only
  EXPECT_HAS(loadError(dress, {"cloth.0.mesh.style=skirt"}),
             "at cloth[0].mesh.style: expected one of \"tshirt\", \"dress\"");
  EXPECT_HAS(loadError(dress, {"cloth.0.mesh.flare=75"}), "at cloth[0].mesh.flare: expected a number in [0, 60]");
  EXPECT_HAS(loadError(dress, {"cloth.0.mesh.hem=1"}), "at cloth[0].mesh.hem: expected a number in [0, 1), got 1");
  // in range for the reader, out of range for the pattern (hem below 3/4 of the height)
  EXPECT_HAS(loadError(dress, {"cloth.0.mesh.hem=0.8"}), "garment.hem: must be a fraction of the height in [0, 0.75)");
  EXPECT_HAS(loadError(dress, {"cloth.0.mesh.sleeveLength=0"}), "at cloth[0].mesh.sleeveLength: expected a number in (0, 1]");
  EXPECT_HAS(loadError(R"({"cloth": [{"solver": "implicit", "mesh": {"type": "garment", "body": "body"}}],
                          "emitters": [{"type": "rain", "origin": [0, 2, 0], "halfExtents": [1, 1]}]})"),
             "at cloth[0].mesh.body: expected the name of a mannequin collider (the scene has none), got \"body\"");
}

// the mannequin's proportions are fractions of its height in (0, 1]; keys of other collider types are
// named as such
TEST(ChenKeys, MannequinProportionsAndForeignKeys) {
  const std::string body = R"({"colliders": [{"name": "body", "type": "mannequin", "height": 1.6,
      "proportions": {"headRadius": 0.08}}],
    "emitters": [{"type": "rain", "origin": [0, 2, 0], "halfExtents": [1, 1]}]})";
  const Scene s = fromString(body);
  const Collider* head = nullptr;
  ASSERT_EQ(s.model.colliders.size(), 1u);
  for (const Collider& c : *s.model.colliders[0].parts)
    if (c.name == "body.head") head = &c;
  ASSERT_NE(head, nullptr);
  EXPECT_FLOAT_EQ(head->radius, 0.08f * 1.6f);
  // blend 0: the parts as separate colliders
  const Scene parts = fromString(body, {"colliders.0.blend=0"});
  ASSERT_EQ(parts.model.colliders.size(), 18u);
  EXPECT_EQ(parts.model.colliders.front().name, "body.head");
  EXPECT_EQ(parts.model.colliders.front().shape, ColliderShape::Sphere);
  EXPECT_FLOAT_EQ(fromString(body, {"colliders.0.blend=0.05"}).model.colliders[0].blendRadius, 0.05f * 1.6f);
  EXPECT_HAS(loadError(body, {"colliders.0.blend=0.2"}),
             "at colliders[0].blend: expected a number in [0, 0.1], got 0.2");
  EXPECT_HAS(loadError(body, {"colliders.0.proportions.headRadius=0"}),
             "at colliders[0].proportions.headRadius: expected a number in (0, 1], got 0");
  EXPECT_HAS(loadError(body, {"colliders.0.proportions.neck=0.1"}), "at colliders[0].proportions.neck: unknown key 'neck'");
  EXPECT_HAS(loadError(body, {"colliders.0.radius=0.3"}), "'radius' is not a key of a mannequin collider");
  EXPECT_HAS(loadError(body, {"colliders.0.friction=2"}), "at colliders[0].friction: expected a number in [0, 1], got 2");
}

}  // namespace
}  // namespace soak
