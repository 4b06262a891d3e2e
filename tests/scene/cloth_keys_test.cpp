// the "cloth" entries of a scene (src/scene/cloth_keys.cpp): rectangle and OBJ meshes placed as asked,
// pins (corners, vertices, a region) on the right particles, and their errors naming file and path
#include <soak/error.hpp>
#include <soak/scene.hpp>

#include <gtest/gtest.h>

#include <filesystem>

#include "scene/cloth_piece.hpp"
#include "scene/scene_support.hpp"

namespace soak {
namespace {

using namespace soak::testing;

TEST(SceneBuild, RectangleCornersArePinnedAtTheRightParticles) {
  // a tilted rectangle: u along z, v along (1, 1, 0)/sqrt 2, so every corner sits at a distinct place
  const Scene s = fromString(R"({"cloth": [{"mesh": {"type": "rectangle", "center": [1, 2, 3], "size": [0.6, 0.4],
      "resolution": [7, 5], "axisU": [0, 0, 2], "axisV": [1, 1, 0]}, "pin": {"corners": [1, 2]}}]})");
  const Vec3 c(1, 2, 3), u(0, 0, 1), v = Vec3(1, 1, 0).normalized();
  const Vec3 corner1 = c + 0.3f * u - 0.2f * v, corner2 = c - 0.3f * u + 0.2f * v;
  int found = 0;
  for (int i = 0; i < s.model.numCloth; ++i) {
    const Vec3& x = s.state.particles.x[size_t(i)];
    const bool atCorner = (x - corner1).norm() < 1e-5f || (x - corner2).norm() < 1e-5f;
    EXPECT_EQ(s.state.particles.invMass[size_t(i)] == 0.0f, atCorner) << "particle " << i;
    found += atCorner;
  }
  EXPECT_EQ(found, 2);
}

TEST(SceneBuild, PinRegionSelectsVerticesByRestPosition) {
  // 5 x 3 grid over x in [-0.2, 0.2], z in [-0.1, 0.1]: the region x >= 0.15 holds one column (3)
  const Scene s = fromString(R"({"cloth": [{"mesh": {"type": "rectangle", "size": [0.4, 0.2], "resolution": [5, 3]},
      "pin": {"region": {"min": [0.15, -1, -1], "max": [1, 1, 1]}}}]})");
  int pinned = 0;
  for (int i = 0; i < s.model.numCloth; ++i) {
    const bool inRegion = s.model.clothRestPosition[size_t(i)].x() >= 0.15f;
    EXPECT_EQ(s.model.clothPinned[size_t(i)] == 1, inRegion);
    pinned += s.model.clothPinned[size_t(i)];
  }
  EXPECT_EQ(pinned, 3);
}

TEST(SceneBuild, ObjMeshIsScaledRotatedTranslatedRelativeToTheSceneFile) {
  TempDir dir;
  dir.write("quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n");
  const std::string path = dir.write("scene.json", R"({"cloth": [{"mesh": {"type": "obj", "path": "quad.obj",
      "scale": 2, "translate": [0, 0, 5], "rotate": {"axis": [0, 0, 1], "degrees": 90}},
      "pin": {"vertices": [2]}}]})");
  const Scene s = loadScene(path);
  ASSERT_EQ(s.model.numCloth, 4);
  // vertex 1 (1, 0, 0) -> scale (2, 0, 0) -> rotate 90 deg about z (0, 2, 0) -> translate (0, 2, 5)
  EXPECT_TRUE(s.model.clothRestPosition[1].isApprox(Vec3(0, 2, 5), 1e-5f));
  EXPECT_EQ(s.model.clothPinned[2], 1);
  EXPECT_EQ(s.name, "scene");
}

TEST(SceneErrors, PinOutOfRange) {
  EXPECT_HAS(errorWith("cloth.0.pin.vertices=[0, 12]"),
             "test.json: at cloth[0].pin.vertices[1]: expected an integer in [0, 11], got 12");
  EXPECT_HAS(errorWith("cloth.0.pin.corners=[4]"), "at cloth[0].pin.corners[0]: expected an integer in [0, 3], got 4");
  EXPECT_HAS(errorWith("cloth.0.pin.region={\"min\": [5, 5, 5], \"max\": [6, 6, 6]}"),
             "at cloth[0].pin.region: expected a box containing at least one vertex");
}

TEST(SceneErrors, MissingObjNamesThePathItTried) {
  TempDir dir;
  const std::string text = R"({"cloth": [{"mesh": {"type": "obj", "path": "nowhere/shirt.obj"}}]})";
  const std::string msg = loadError(text, {}, dir.path.string());
  EXPECT_HAS(msg, "test.json: at cloth[0].mesh.path: expected the path of an existing OBJ file, got \"nowhere/shirt.obj\"");
  EXPECT_HAS(msg, "(tried \"" + (dir.path / "nowhere/shirt.obj").string() + "\")");
  EXPECT_HAS(loadError(R"({"cloth": [{"mesh": {"type": "obj", "path": "a.obj"}, "pin": {"corners": [0]}}]})", {},
                       (fs::path(SOAK_SOURCE_DIR) / "scenes").string()),
             "at cloth[0].mesh.path: expected the path of an existing OBJ file");
}

TEST(SceneErrors, CornersAreOnlyForRectangles) {
  TempDir dir;
  dir.write("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const std::string text = R"({"cloth": [{"mesh": {"type": "obj", "path": "tri.obj"}, "pin": {"corners": [0]}}]})";
  EXPECT_HAS(loadError(text, {}, dir.path.string()), "at cloth[0].pin.corners: expected no corners on an obj mesh");
}

TEST(SceneErrors, NonManifoldObjIsRefusedWithFileAndPath) {
  TempDir dir;
  // three triangles share the edge (1, 2): a fin that no cloth can be
  dir.write("fin.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n");
  const std::string scene = dir.write("fin.json", R"({"cloth": [{"name": "fin", "mesh": {"type": "obj", "path": "fin.obj"}}]})");
  try {
    loadScene(scene);
    FAIL() << "a non-manifold mesh loaded";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_HAS(msg, scene + ": at cloth[0].mesh");
    EXPECT_HAS(msg, "shared by 3 triangles");
  }
}

TEST(ClothKeys, MaterialKeysReachThePieceAndPbdKeysAreRefusedOnAnImplicitOne) {
  const Scene s = fromString(R"({"cloth": [{"mesh": {"type": "rectangle", "size": [0.3, 0.2], "resolution": [4, 3]},
      "material": {"particleMass": 0.004, "restDensity": 650, "stretchCompliance": 1e-7, "bendCompliance": 2e-4,
                   "damping": 0.3, "thickness": 0.003, "friction": 0.6, "selfCollision": false, "tetherSlack": 0.05}}]})");
  const ClothMaterial& m = s.model.pieces.at(0).material;
  EXPECT_FLOAT_EQ(m.particleMass, 0.004f);
  EXPECT_FLOAT_EQ(m.restDensity, 650.0f);
  EXPECT_FLOAT_EQ(m.stretchCompliance, 1e-7f);
  EXPECT_FLOAT_EQ(m.bendCompliance, 2e-4f);
  EXPECT_FLOAT_EQ(m.damping, 0.3f);
  EXPECT_FLOAT_EQ(m.thickness, 0.003f);
  EXPECT_FLOAT_EQ(m.friction, 0.6f);
  EXPECT_FALSE(m.selfCollision);
  EXPECT_FLOAT_EQ(m.tetherSlack, 0.05f);
  EXPECT_FLOAT_EQ(s.state.particles.mass.at(0), 0.004f);  // a dry cloth particle has the material's mass
  const std::string msg = loadError(R"({"cloth": [{"mesh": {"type": "rectangle", "size": [0.3, 0.2],
      "resolution": [4, 3]}, "solver": "implicit", "material": {"damping": 0.3, "selfCollision": true}}]})");
  EXPECT_HAS(msg, "test.json: at cloth[0].material.damping: expected no damping on a piece with \"solver\": \"implicit\"");
  EXPECT_EQ(msg.find("selfCollision"), std::string::npos);  // both solvers have one
  EXPECT_HAS(errorWith("cloth.0.material.friction=-0.5"), "at cloth[0].material.friction: expected a number >= 0, got -0.5");
  // static friction defaults to the kinetic coefficient and may not be below it, on a collider as on cloth
  EXPECT_HAS(loadError(kSmall, {"cloth.0.material.friction=0.6", "cloth.0.material.staticFriction=0.5"}),
             "at cloth[0].material.staticFriction: expected a number >= friction (0.6), got 0.5");
  const Scene u = fromString(kSmall, {"cloth.0.material.friction=0.6"});
  EXPECT_FLOAT_EQ(u.model.pieces[0].material.staticFriction, 0.6f);
  const Scene t = fromString(kSmall, {"cloth.0.material.friction=0.6", "cloth.0.material.staticFriction=0.8"});
  EXPECT_FLOAT_EQ(t.model.pieces[0].material.friction, 0.6f);
  EXPECT_FLOAT_EQ(t.model.pieces[0].material.staticFriction, 0.8f);
}

}  // namespace
}  // namespace soak

namespace soak {
namespace {

using namespace soak::testing;

// material.arealDensity: a vertex weighs the density times its mixed Voronoi area on the rest mesh,
// so interior, edge and corner vertices of a grid weigh 1, 1/2 and 1/4 of a cell (whichever way the
// rectangle splits its cells), and the sheet weighs density x area at any resolution
TEST(ClothKeys, ArealDensityGivesTheSameWeightAtAnyResolution) {
  const double density = 0.2, width = 0.5, depth = 0.4;
  for (int n : {6, 21, 61}) {
    const Scene s = fromString(R"({"cloth": [{"mesh": {"type": "rectangle", "size": [0.5, 0.4], "resolution": [)" +
                               std::to_string(n) + "," + std::to_string(n) +
                               R"(]}, "material": {"arealDensity": 0.2}}]})");
    double total = 0.0;
    for (float m : s.model.clothDryMass) total += m;
    EXPECT_NEAR(total, density * width * depth, 1e-5 * density * width * depth) << n << " x " << n;
    const double cell = density * (width / (n - 1)) * (depth / (n - 1));
    EXPECT_NEAR(s.model.clothDryMass[0], cell / 4, 1e-5 * cell);                            // a corner
    EXPECT_NEAR(s.model.clothDryMass[1], cell / 2, 1e-5 * cell);                            // an edge
    EXPECT_NEAR(s.model.clothDryMass[size_t(n + 1)], cell, 1e-5 * cell);                    // inside
    EXPECT_FLOAT_EQ(s.state.particles.mass[size_t(n + 1)], s.model.clothDryMass[size_t(n + 1)]);
  }
  // without it the default, Table 1's 0.0066 kg particle on its 0.02 m spacing: 16.5 kg/m^2
  const Scene byDefault = fromString(R"({"cloth": [{"mesh": {"type": "rectangle", "size": [0.3, 0.3], "resolution": [16, 16]}}]})");
  EXPECT_FLOAT_EQ(byDefault.model.clothDryMass[17], 0.0066f);  // an inner vertex: a 0.02 m cell
  // with particleMass, every particle weighs it, whatever its area
  const Scene table1 = fromString(R"({"cloth": [{"mesh": {"type": "rectangle", "size": [0.3, 0.3], "resolution": [4, 4]},
      "material": {"particleMass": 0.0066}}]})");
  for (float m : table1.model.clothDryMass) EXPECT_FLOAT_EQ(m, 0.0066f);
}

// material.bendRigidity (default) or bendCompliance sets Eq. 9's hinges: one excludes the other, the
// rigidity must be positive, an implicit piece refuses both, and the model's hinges get the compliance
TEST(ClothKeys, BendRigidityOrBendComplianceSetsTheHinges) {
  const char* sheet = R"({"cloth": [{"mesh": {"type": "rectangle", "size": [0.3, 0.3], "resolution": [4, 4]}}]})";
  const Scene byDefault = fromString(sheet);
  EXPECT_FLOAT_EQ(byDefault.model.pieces[0].material.bendRigidity, ClothMaterial{}.bendRigidity);
  EXPECT_LT(byDefault.model.pieces[0].material.bendCompliance, 0.0f);
  // a 0.1 m lattice: a hinge across a leg has (A1 + A2) / |e|^2 = 1, across a diagonal 1/2
  const Scene rigid = fromString(sheet, {"cloth.0.material.bendRigidity=0.01"});
  ASSERT_FALSE(rigid.model.bend.compliance.empty());
  for (float c : rigid.model.bend.compliance) EXPECT_TRUE(std::abs(c - 100.0f) < 0.01f || std::abs(c - 50.0f) < 0.01f) << c;
  const Scene given = fromString(sheet, {"cloth.0.material.bendCompliance=0.25"});
  for (float c : given.model.bend.compliance) EXPECT_FLOAT_EQ(c, 0.25f);
  EXPECT_HAS(loadError(sheet, {"cloth.0.material.bendCompliance=0.25", "cloth.0.material.bendRigidity=0.01"}),
             "at cloth[0].material.bendRigidity: expected either bendCompliance (1/(N m) a hinge) or bendRigidity");
  EXPECT_HAS(loadError(sheet, {"cloth.0.material.bendRigidity=0"}),
             "at cloth[0].material.bendRigidity: expected a number > 0");
  EXPECT_HAS(loadError(R"({"cloth": [{"mesh": {"type": "rectangle", "size": [0.3, 0.2], "resolution": [4, 3]},
      "solver": "implicit", "material": {"bendRigidity": 0.01}}]})"),
             "at cloth[0].material.bendRigidity: expected no bendRigidity on a piece with \"solver\": \"implicit\"");
}

TEST(ClothKeys, ArealDensityAndParticleMassExcludeEachOtherAndEveryVertexNeedsATriangle) {
  EXPECT_HAS(loadError(R"({"cloth": [{"mesh": {"type": "rectangle", "size": [0.3, 0.3], "resolution": [4, 4]},
      "material": {"arealDensity": 0.2, "particleMass": 0.001}}]})"),
             "at cloth[0].material.arealDensity: expected either particleMass (kg a particle) or arealDensity");
  EXPECT_HAS(loadError(R"({"cloth": [{"mesh": {"type": "rectangle", "size": [0.3, 0.3], "resolution": [4, 4]},
      "material": {"arealDensity": -1}}]})"),
             "at cloth[0].material.arealDensity: expected a number > 0");
  const TriangleMesh stray{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(5, 5, 5)}, {{0, 1, 2}}};
  ClothMaterial material;
  material.arealDensity = 0.2f;
  Model model;
  try {
    addClothPiece(model, "sheet", stray, material, {}, "scenes/stray.json");
    ADD_FAILURE() << "a vertex in no triangle was given a mass";
  } catch (const Error& e) {
    EXPECT_HAS(std::string(e.what()), "scenes/stray.json: cloth 'sheet': vertex 3 (0-based) belongs to no triangle");
  }
  material.particleMass = 0.0066f;  // with particleMass such a vertex keeps its mass
  Model plain;
  addClothPiece(plain, "sheet", stray, material, {}, "scenes/stray.json");
  EXPECT_FLOAT_EQ(plain.clothDryMass[3], 0.0066f);
}

}  // namespace
}  // namespace soak
