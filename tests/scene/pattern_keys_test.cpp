// "type": "pattern" cloth meshes (scene/pattern_keys.hpp): the shipped garments sew shut on the body,
// the keys reach the model, and bad patterns are refused naming the file and the place
#include <soak/error.hpp>
#include <soak/scene.hpp>

#include "garment/implicit.hpp"
#include "support/garment_scene.hpp"
#include "support/mesh_crossings.hpp"
#include "world/garment_mesh.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <tuple>
#include <vector>

namespace soak {
namespace {

using testing::fromString;
using testing::loadError;

// a mannequin in the T-shirt's pose and one implicit piece whose mesh is `mesh` (JSON)
std::string sceneWith(const std::string& mesh, const std::string& solver = "implicit") {
  return R"({"solver": {"dt": 0.0166667, "domain": {"min": [-1.5, 0, -1.5], "max": [1.5, 2.5, 1.5]}},
  "colliders": [{"name": "body", "type": "mannequin", "pose": {"shoulderAbduction": [45, 45]}}],
  "cloth": [{"name": "shirt", "solver": ")" + solver + R"(", "mesh": )" + mesh + "}]}";
}

// a tube of two 0.5 x 0.4 m panels around the waist, sewn at both sides
const std::string kTube = R"({"type": "pattern", "body": "body", "edgeLength": 0.05, "pattern": {
  "panels": [{"name": "front", "origin": [0, 0.9, 0.2], "outline": [[-0.25, 0], [0.25, 0], [0.25, 0.4], [-0.25, 0.4]]},
             {"name": "back", "origin": [0, 0.9, -0.2], "yaw": 180,
              "outline": [[-0.25, 0], [0.25, 0], [0.25, 0.4], [-0.25, 0.4]]}],
  "seams": [{"a": {"panel": "front", "from": 1, "to": 2}, "b": {"panel": "back", "from": 3, "to": 0}},
            {"a": {"panel": "front", "from": 3, "to": 0}, "b": {"panel": "back", "from": 1, "to": 2}}]}})";

TEST(PatternScene, KeysReachTheModel) {
  const Scene s = fromString(sceneWith(kTube), {"cloth.0.garment.seams.closeTime=0.3"});
  const ClothPiece& piece = s.model.pieces[0];
  EXPECT_EQ(piece.seams.size(), 2u * 9u);  // 0.4 m sides at 0.05 m: 9 points each
  ASSERT_EQ(piece.panelOfVertex.size(), size_t(piece.particleCount));
  EXPECT_FLOAT_EQ(piece.garment.seams.closeTime, 0.3f);
  EXPECT_FLOAT_EQ(piece.garment.laws.seamStiffness, piece.garment.laws.stretch.a1);  // an edge's, by default
  ASSERT_TRUE(piece.implicit);
  EXPECT_EQ(piece.implicit->springs.kindStart[4] - piece.implicit->springs.kindStart[3], 18);
  EXPECT_FLOAT_EQ(piece.garment.seams.settleTime, 0.25f);
  const Scene k = fromString(sceneWith(kTube), {"cloth.0.garment.seams.stiffness=500", "cloth.0.garment.seams.settleTime=0"});
  EXPECT_FLOAT_EQ(k.model.pieces[0].garment.laws.seamStiffness, 500.0f);
  EXPECT_FLOAT_EQ(k.model.pieces[0].garment.seams.settleTime, 0.0f);
  EXPECT_HAS(loadError(sceneWith(kTube), {"cloth.0.garment.seams.settleTime=-1"}), "settleTime");
}

// pairs of the first piece's triangles through each other (mesh_crossings.hpp), its seams joined
size_t crossingPairs(const Scene& s) {
  const auto& x = s.state.particles.x;
  const std::vector<Vec3> cloth(x.begin(), x.begin() + s.model.numCloth);
  return testing::countCrossingTriangles(cloth, s.model.triangles, s.model.pieces[0].seams);
}

// the shipped garments: their seams close, no vertex ends inside the body, and the garment stays on
struct ShippedGarment {
  const char* scene;
  double lowest;  // m, the lowest point after 1 s stays above this (measured 3 to 4 cm above; falling off
                  // would take it 1 m lower)
  size_t crossings;  // triangle pairs through each other after 1 s, at most
  bool layersMeet;   // its self-collision pushes vertices off its triangles in that second
  const char* set = nullptr;  // one more override of the scene, or none
};

class ShippedGarments : public ::testing::TestWithParam<ShippedGarment> {};

TEST_P(ShippedGarments, SewShutOnTheBodyAndStayOn) {
  std::vector<std::string> sets = {"cloth.0.mesh.edgeLength=0.04", "emitters=[]"};
  if (GetParam().set) sets.push_back(GetParam().set);
  Scene s = loadScene(std::string(SOAK_SOURCE_DIR) + "/scenes/" + GetParam().scene, sets);
  const Model& m = s.model;
  const ClothPiece& piece = m.pieces[0];
  ASSERT_GT(piece.seams.size(), 20u);
  const auto& x = s.state.particles.x;
  float widest = 0.0f;
  for (const auto& [a, b] : piece.seams) widest = std::max(widest, (x[a] - x[b]).norm());
  EXPECT_GT(widest, 0.25f);  // the panels start 0.28 m apart
  StepStats total;
  testing::run(m, s.state, 60, &total);  // 1 s: sewn by 0.5 s, then 0.5 s under gravity
  float gap = 0.0f;
  for (const auto& [a, b] : piece.seams) gap = std::max(gap, (x[a] - x[b]).norm());
  EXPECT_LT(gap, 0.001f);  // measured 0.06 to 0.36 mm
  const float thickness = piece.material.thickness;
  double lowest = 1e30;
  for (int i = 0; i < m.numCloth; ++i) lowest = std::min(lowest, double(x[size_t(i)].y()));
  EXPECT_GT(testing::deepestClothVertex(s), 0.5f * thickness - 5e-4f);  // every vertex outside the contact margin (measured at it)
  EXPECT_GT(total.garment.contacts, 0u);         // it rests on the body
  EXPECT_GT(lowest, GetParam().lowest);
  EXPECT_EQ(total.garment.unconverged, 0u);
  EXPECT_LE(crossingPairs(s), GetParam().crossings);
  if (GetParam().layersMeet) EXPECT_GT(total.garment.selfContacts, 0u) << "a weak case: the layers never met";
}

INSTANTIATE_TEST_SUITE_P(PatternScene, ShippedGarments,
                         // none has triangles through each other (measured); the 4 cm
                         // garments' layers do not meet in their first second at the scenes' substeps,
                         // the dress's do at 4 substeps (94 pushes): that case checks the crossings
                         // where the self-collision acts
                         ::testing::Values(ShippedGarment{"chen_fig9_garment_rain_dry.json", 0.72, 0, false},
                                           ShippedGarment{"garment_dress_rain.json", 0.45, 0, false},
                                           ShippedGarment{"garment_dress_rain.json", 0.45, 0, true, "solver.substeps=4"},
                                           ShippedGarment{"garment_skirt.json", 0.44, 0, false}));

// issue 23 point 3 on the garment scenes in rain as they ship (full resolution, their rain, their
// solver): after 1.5 s (sewn by 0.5 s, the rain on the fabric from about 0.7 s) no vertex is inside
// the body's contact margin, no triangle passes through another, every solve converged, the layers
// met (the self-collision pushed) and the fabric took water. Measured: every vertex at the margin,
// none crossing; 31 and 5,353 pushes, 204 and 160 drops taken. Without the self-collision the dress has
// 100 crossing pairs by then
class ShippedRainScenes : public ::testing::TestWithParam<const char*> {};

TEST_P(ShippedRainScenes, AsShippedNoVertexInTheBodyAndNoTriangleThroughAnother) {
  Scene s = loadScene(std::string(SOAK_SOURCE_DIR) + "/scenes/" + GetParam());
  const Model& m = s.model;
  StepStats total;
  testing::run(m, s.state, 90, &total);
  EXPECT_GT(testing::deepestClothVertex(s), 0.5f * m.pieces[0].material.thickness - 5e-4f);  // measured at the margin
  EXPECT_EQ(crossingPairs(s), 0u);
  EXPECT_EQ(total.garment.unconverged, 0u);
  EXPECT_GT(total.garment.selfContacts, 0u) << "a weak case: the layers never met";
  EXPECT_GT(total.garment.dropsTaken, 50u);
}

INSTANTIATE_TEST_SUITE_P(PatternScene, ShippedRainScenes,
                         ::testing::Values("chen_fig9_garment_rain_wet.json", "garment_dress_rain.json"));

// the shipped moving-body scene (scenes/garment_tshirt_moving.json, without its rain), the shirt at
// 4 cm: the mannequin raises its arms to 70 degrees (1.5 s to 3 s) and lowers them (to 4.5 s). Every
// solve converges, no vertex ends inside the moving body, the shirt rides up with the arms and comes
// back down, and none of its triangles passes through another (at 4 cm its layers do not meet; the
// dress above has the self-collision pushes)
TEST(PatternScene, TheShirtFollowsTheMovingBody) {
  Scene s = loadScene(std::string(SOAK_SOURCE_DIR) + "/scenes/garment_tshirt_moving.json",
                      {"cloth.0.mesh.edgeLength=0.04", "emitters=[]"});
  const Model& m = s.model;
  const ClothPiece& piece = m.pieces[0];
  const auto& x = s.state.particles.x;
  const auto look = [&] {
    double mean = 0.0;
    for (int i = 0; i < m.numCloth; ++i) mean += x[size_t(i)].y();
    return std::tuple{mean / m.numCloth, testing::deepestClothVertex(s), crossingPairs(s)};
  };
  StepStats total;
  testing::run(m, s.state, 90, &total);  // 1.5 s: sewn and settled, arms still down
  const auto [before, deepBefore, crossBefore] = look();
  testing::run(m, s.state, 90, &total);  // 3 s: arms up
  const auto [raised, deepRaised, crossRaised] = look();
  testing::run(m, s.state, 90, &total);  // 4.5 s: arms down again
  const auto [after, deepAfter, crossAfter] = look();
  EXPECT_EQ(total.garment.unconverged, 0u);
  const float margin = 0.5f * piece.material.thickness - 5e-4f;  // measured at the margin, 0.5 thickness
  EXPECT_GT(deepBefore, margin);
  EXPECT_GT(deepRaised, margin);
  EXPECT_GT(deepAfter, margin);
  EXPECT_GT(raised, before + 0.05);  // measured 1.166 m, 1.230 m and 1.176 m mean height
  EXPECT_LT(after, raised - 0.02);
  EXPECT_EQ(crossBefore, 0u);  // measured none at each
  EXPECT_EQ(crossRaised, 0u);
  EXPECT_EQ(crossAfter, 0u);
}

// the counter the garment test uses: a triangle pierced by another counts, one touching it through a
// shared or seam-joined vertex does not
TEST(PatternScene, CrossingCounterSeesTrianglesThroughEachOther) {
  std::vector<Vec3> x = {Vec3(0, 0, 0),     Vec3(1, 0, 0),      Vec3(0, 1, 0),  // in z = 0
                         Vec3(0.2f, 0.2f, -0.5f), Vec3(0.3f, 0.2f, 0.5f), Vec3(0.2f, 0.4f, 0.5f)};  // through it
  const std::vector<std::array<int, 3>> tris = {{0, 1, 2}, {3, 4, 5}};
  EXPECT_EQ(testing::countCrossingTriangles(x, tris), 1u);
  EXPECT_EQ(testing::countCrossingTriangles(x, tris, {{{0, 3}}}), 0u);  // joined by a seam
  x[3].z() = 0.1f;  // lifted above the plane: clear
  EXPECT_EQ(testing::countCrossingTriangles(x, tris), 0u);
  x.push_back(Vec3(0.3f, 0.3f, -0.5f));  // 6 and 7: an edge through the first triangle
  x.push_back(Vec3(0.3f, 0.3f, 0.5f));
  EXPECT_EQ(testing::countCrossingTriangles(x, {{0, 1, 2}, {3, 6, 7}}), 1u);
  EXPECT_EQ(testing::countCrossingTriangles(x, {{0, 1, 2}, {0, 6, 7}}), 0u);  // sharing a vertex: not compared
}

// point 2 of issue 23: the shipped patterns at their scenes' edge length have 5k to 20k vertices
TEST(PatternScene, ShippedGarmentsHaveFiveToTwentyThousandVertices) {
  for (const char* scene : {"chen_fig9_garment_rain_dry.json", "garment_dress_rain.json", "garment_skirt.json"}) {
    const Scene s = loadScene(std::string(SOAK_SOURCE_DIR) + "/scenes/" + scene);
    EXPECT_GE(s.model.numCloth, 5000) << scene;
    EXPECT_LE(s.model.numCloth, 20000) << scene;
  }
}

std::string writePatternFile(const std::string& name, const std::string& text) {
  const std::string path = (std::filesystem::path(::testing::TempDir()) / name).string();
  std::ofstream(path) << text;
  return path;
}

TEST(PatternSceneErrors, BadPatternsAreRefusedNamingTheFileAndThePlace) {
  // a clockwise panel inline: the scene's path
  std::string cw = kTube;
  cw.replace(cw.find("[[-0.25, 0], [0.25, 0], [0.25, 0.4], [-0.25, 0.4]]"), 50,
             "[[-0.25, 0.4], [0.25, 0.4], [0.25, 0], [-0.25, 0]]");
  EXPECT_HAS(loadError(sceneWith(cw)),
             "garment.json: at cloth[0].mesh.pattern.panels[0].outline: expected counter-clockwise corners");
  // a seam naming a panel the pattern lacks, in a pattern file: that file's path
  std::string pattern = kTube.substr(kTube.find("\"pattern\": ") + 11);
  pattern.pop_back();  // the mesh object's closing brace
  std::string badSeam = pattern;
  badSeam.replace(badSeam.find("\"panel\": \"back\""), 15, "\"panel\": \"bak\"");
  const std::string file = writePatternFile("bad_seam.json", badSeam);
  EXPECT_HAS(loadError(sceneWith(R"({"type": "pattern", "path": ")" + file + R"("})")),
             file + ": at seams[0].b.panel: expected the name of a panel (front, back), got \"bak\"");
  EXPECT_HAS(loadError(sceneWith(R"({"type": "pattern", "path": "/nonexistent/p.json"})")),
             "at cloth[0].mesh.path: expected a readable pattern file");
  const std::string good = writePatternFile("tube.json", pattern);
  EXPECT_HAS(loadError(sceneWith(R"({"type": "pattern", "path": ")" + good + R"(", "pattern": {}})")),
             "expected either \"pattern\" (the pattern inline) or \"path\" (a pattern file), got both");
  EXPECT_HAS(loadError(sceneWith(R"({"type": "pattern", "path": ")" + good + R"("})", "pbd")),
             "expected \"solver\": \"implicit\" on the piece");
  EXPECT_HAS(loadError(sceneWith(R"({"type": "pattern", "path": ")" + good + R"(", "resolution": [3, 3]})")),
             "'resolution' is not a key of a pattern mesh");
  // a fine edge length is refused from the panels' area, before any meshing
  EXPECT_HAS(loadError(sceneWith(R"({"type": "pattern", "path": ")" + good + R"(", "edgeLength": 0.002})"),
                       {"solver.maxParticles=100000"}),
             "at cloth[0].mesh.edgeLength: expected at most 100000 vertices");
  EXPECT_TRUE(loadError(sceneWith(R"({"type": "pattern", "path": ")" + good + R"("})")).empty());
}

// the sewn mesh is the same in any process: the mesher's own triangulation depended on where CGAL
// allocated its handles, and an unrelated override (another heap history) gave the T-shirt other
// triangles, so a resumed run or a sweep's variant simulated another mesh
TEST(PatternScene, TheSameScenesSewTheSameMesh) {
  const std::string path = std::string(SOAK_SOURCE_DIR) + "/scenes/chen_fig9_garment_rain_wet.json";
  const Scene a = loadScene(path, {"emitters=[]"});
  std::vector<std::vector<double>> clutter;  // another heap history for the second load
  for (int k = 1; k < 200; ++k) clutter.emplace_back(size_t(37 * k), 1.0);
  const Scene b = loadScene(path, {"cloth.0.garment.cg.preconditioner=multigrid", "cloth.0.garment.cg.tolerance=1e-5"});
  ASSERT_GT(a.model.triangles.size(), 10000u);
  EXPECT_EQ(a.model.triangles, b.model.triangles);
  EXPECT_EQ(a.model.clothRestPosition, b.model.clothRestPosition);
}

}  // namespace
}  // namespace soak
