// procedural garments (world/garment_mesh.cpp): T-shirt and dress manifold, outside the body by the margin
// and close to it, with their panels; the body's distance, the vertices inside it and pushing them out;
// and every bad pattern refused naming the key
#include "world/garment_mesh.hpp"

#include "scene/cloth_piece.hpp"
#include "world/colliders.hpp"
#include "world/mannequin.hpp"

#include <soak/error.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

namespace soak {
namespace {

MannequinPose aPose(float abduction) {
  MannequinPose p;
  p.shoulderAbduction = {abduction, abduction};
  return p;
}

Collider sphereAt(const Vec3& centre, float radius) {
  Collider c;
  c.shape = ColliderShape::Sphere;
  c.radius = radius;
  c.keys = {Keyframe{0.0f, centre, Quat::Identity()}};
  return c;
}

// the checks every garment must pass: accepted as cloth, every edge in one or two triangles, panels
// on every vertex, every vertex outside the body by the margin and most of them near it
void checkGarment(const Garment& g, const MannequinParams& mp, const GarmentPattern& gp, int panels) {
  ASSERT_GT(g.mesh.vertices.size(), 200u);
  Model model;
  EXPECT_NO_THROW(addClothPiece(model, "garment", g.mesh, ClothMaterial{}, {}, "garment"));
  std::map<std::pair<int, int>, int> edgeUse;
  for (const auto& t : g.mesh.triangles)
    for (int k = 0; k < 3; ++k) ++edgeUse[std::minmax(t[k], t[(k + 1) % 3])];
  int open = 0;
  for (const auto& [edge, n] : edgeUse) {
    EXPECT_LE(n, 2);
    open += n == 1;
  }
  EXPECT_GT(open, 20);  // hem, neck and sleeve / arm openings
  ASSERT_EQ(g.panelOfVertex.size(), g.mesh.vertices.size());
  ASSERT_EQ(static_cast<int>(g.panelNames.size()), panels);
  std::vector<int> count(panels, 0);
  for (int p : g.panelOfVertex) {
    ASSERT_GE(p, 0);
    ASSERT_LT(p, panels);
    ++count[p];
  }
  for (int p = 0; p < panels; ++p) EXPECT_GT(count[p], 20) << g.panelNames[p];
  // seams: edges whose two triangles lie on different panels exist (front and back are sewn)
  const std::vector<Collider> body = buildMannequin(mp, {}, 0.5f);
  EXPECT_TRUE(verticesInsideBody(g.mesh, body, 0.0, gp.margin).empty());
  int near = 0;
  for (const Vec3& x : g.mesh.vertices) near += bodyDistance(body, 0.0, x, nullptr) < 3.0f * (gp.margin + gp.ease);
  EXPECT_GT(near, static_cast<int>(g.mesh.vertices.size()) / 2);  // it hugs the body
}

TEST(MannequinGarment, TShirtIsManifoldOutsideTheBodyWithFourPanels) {
  MannequinParams mp;
  mp.position = Vec3(0.5f, 0.0f, -1.0f);
  mp.yaw = 0.4f;
  const MannequinPose pose = aPose(0.8f);
  mp.pose = pose;
  GarmentPattern gp;
  const Garment g = buildGarment(mp, pose, gp);
  checkGarment(g, mp, gp, 4);
  // the shirt spans from the hem to above the shoulders
  const MannequinJoints j = mannequinJoints(mp, pose);
  float lo = 1e30f, hi = -1e30f;
  for (const Vec3& x : g.mesh.vertices) lo = std::min(lo, x.y()), hi = std::max(hi, x.y());
  EXPECT_NEAR(lo, 0.48f * mp.height, 0.01f);
  EXPECT_GT(hi, j.shoulder[kLeft].y());
  // sleeve vertices sit around the upper arms
  for (size_t v = 0; v < g.mesh.vertices.size(); ++v) {
    if (g.panelOfVertex[v] != kPanelLeftSleeve) continue;
    const Vec3 a = j.shoulder[kLeft], b = j.elbow[kLeft], x = g.mesh.vertices[v];
    const float s = std::clamp((x - a).dot(b - a) / (b - a).squaredNorm(), 0.0f, 1.0f);
    EXPECT_LT((x - (a + s * (b - a))).norm(), 0.15f);
  }
}

TEST(MannequinGarment, DressIsManifoldOutsideTheBodyDownToTheKnees) {
  MannequinParams mp;
  MannequinPose pose = aPose(0.4f);
  pose.kneeFlexion = {0.2f, 0.0f};
  mp.pose = pose;
  GarmentPattern gp;
  gp.style = GarmentStyle::Dress;
  gp.edgeLength = 0.035f;
  const Garment g = buildGarment(mp, pose, gp);
  checkGarment(g, mp, gp, 2);
  const MannequinJoints j = mannequinJoints(mp, pose);
  float lo = 1e30f, widest = 0.0f;
  for (const Vec3& x : g.mesh.vertices) lo = std::min(lo, x.y()), widest = std::max(widest, std::fabs(x.x()));
  EXPECT_LT(lo, j.knee[kLeft].y());
  EXPECT_GT(widest, 0.5f * mp.hipWidth * mp.height);  // the skirt flares past the hips
}

TEST(MannequinGarment, ArmsAtTheSidesAreRefused) {
  MannequinParams mp;
  const MannequinPose pose;  // arms hanging straight down
  EXPECT_THROW(buildGarment(mp, pose, GarmentPattern{}), Error);
  GarmentPattern bad;
  bad.edgeLength = -0.01f;
  EXPECT_THROW(buildGarment(mp, aPose(0.8f), bad), Error);
}

TEST(MannequinGarment, PushOutMovesInsideVerticesToTheMargin) {
  MannequinParams mp;
  const std::vector<Collider> body = buildMannequin(mp, {}, 0.5f);
  TriangleMesh m;
  m.vertices = {Vec3(0.0f, 1.2f, 0.0f), Vec3(0.05f, 0.9f, 0.02f), Vec3(1.0f, 1.0f, 1.0f)};
  EXPECT_EQ(verticesInsideBody(m, body, 0.0, 0.01f), (std::vector<int>{0, 1}));
  EXPECT_EQ(pushOutOfBody(m, body, 0.0, 0.01f), 0u);
  EXPECT_TRUE(verticesInsideBody(m, body, 0.0, 0.01f).empty());
  EXPECT_EQ(m.vertices[2], Vec3(1.0f, 1.0f, 1.0f));
}

// the union's distance is the nearest part's, with that part's normal; a point inside two parts takes the
// deeper one (the smaller signed distance)
TEST(GarmentMesh, BodyDistanceIsTheNearestPartWithItsNormal) {
  const std::vector<Collider> body = {sphereAt(Vec3(0, 1, 0), 0.1f), sphereAt(Vec3(0.3f, 1, 0), 0.05f)};
  Vec3 n;
  EXPECT_NEAR(bodyDistance(body, 0.0, Vec3(0, 1.3f, 0), &n), 0.2f, 1e-6f);
  EXPECT_LT((n - Vec3(0, 1, 0)).norm(), 1e-6f);
  EXPECT_NEAR(bodyDistance(body, 0.0, Vec3(0.4f, 1, 0), &n), 0.05f, 1e-6f);  // 0.3 from the big one
  EXPECT_LT((n - Vec3(1, 0, 0)).norm(), 1e-6f);
  EXPECT_NEAR(bodyDistance(body, 0.0, Vec3(0.02f, 1, 0), &n), -0.08f, 1e-6f);
  EXPECT_GT(bodyDistance({}, 0.0, Vec3::Zero(), nullptr), 1e29f);  // no body: nothing near
  // within the margin by less than the 1e-5 m rounding allowance is not inside
  TriangleMesh m;
  m.vertices = {Vec3(0, 1.11f, 0), Vec3(0, 1.109f, 0), Vec3(0, 1.5f, 0)};
  EXPECT_EQ(verticesInsideBody(m, body, 0.0, 0.01f), (std::vector<int>{1}));
}

// a vertex the normal pushes cannot free (no iterations) takes the shortest of the 26 lattice directions
// in 2 mm steps: from 5 cm inside a 0.1 m ball along +x that is +x, ending within one step past the
// margin; a vertex too deep for the half-metre search stays where it is and is counted
TEST(GarmentMesh, PushOutFallsBackToTheShortestLatticeDirection) {
  const std::vector<Collider> ball = {sphereAt(Vec3::Zero(), 0.1f)};
  TriangleMesh m;
  m.vertices = {Vec3(0.05f, 0, 0)};
  EXPECT_EQ(pushOutOfBody(m, ball, 0.0, 0.01f, 0), 0u);
  EXPECT_GE(m.vertices[0].x(), 0.11f - 1e-5f);
  EXPECT_LE(m.vertices[0].x(), 0.11f + 0.002f + 1e-5f);
  EXPECT_EQ(m.vertices[0].y(), 0.0f);
  EXPECT_EQ(m.vertices[0].z(), 0.0f);
  const std::vector<Collider> huge = {sphereAt(Vec3::Zero(), 2.0f)};
  TriangleMesh deep;
  deep.vertices = {Vec3(0.1f, 0.2f, 0.3f)};
  EXPECT_EQ(pushOutOfBody(deep, huge, 0.0, 0.01f, 0), 1u);
  EXPECT_EQ(deep.vertices[0], Vec3(0.1f, 0.2f, 0.3f));
  // with its iterations the normal push alone frees it: radially out to the margin
  EXPECT_EQ(pushOutOfBody(deep, huge, 0.0, 0.01f), 0u);
  EXPECT_NEAR(deep.vertices[0].norm(), 2.01f, 1e-4f);
  EXPECT_LT((deep.vertices[0].normalized() - Vec3(0.1f, 0.2f, 0.3f).normalized()).norm(), 1e-5f);
}

// each pattern key out of range is refused before anything is built, naming the source and the key
TEST(GarmentMesh, BadPatternsAreRefusedNamingTheKey) {
  const MannequinParams mp;
  const MannequinPose pose = aPose(0.8f);
  const auto errorOf = [&](const GarmentPattern& g) {
    try {
      buildGarment(mp, pose, g, "scene.json");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  GarmentPattern g;
  g.edgeLength = 0.0f;
  EXPECT_EQ(errorOf(g), "scene.json: at garment.edgeLength: must be a positive length in m");
  g = GarmentPattern{};
  g.margin = -0.01f;
  EXPECT_EQ(errorOf(g), "scene.json: at garment.margin: must be >= 0 m");
  g = GarmentPattern{};
  g.ease = -1.0f;
  EXPECT_EQ(errorOf(g), "scene.json: at garment.ease: must be >= 0 m");
  g = GarmentPattern{};
  g.hem = 0.75f;
  EXPECT_EQ(errorOf(g), "scene.json: at garment.hem: must be a fraction of the height in [0, 0.75)");
  g = GarmentPattern{};
  g.sleeveLength = 1.5f;
  EXPECT_EQ(errorOf(g), "scene.json: at garment.sleeveLength: must be a fraction of the upper arm in (0, 1]");
  g = GarmentPattern{};
  g.neckOpening = -0.1f;
  EXPECT_EQ(errorOf(g), "scene.json: at garment.neckOpening: must be >= 0 m");
  g = GarmentPattern{};
  g.flare = 1.2f;
  EXPECT_EQ(errorOf(g), "scene.json: at garment.flare: must be an angle in [0, 1.2) rad");
  g = GarmentPattern{};
  g.margin = NAN;
  EXPECT_EQ(errorOf(g), "scene.json: at garment.margin: must be >= 0 m");
  // arms down: the message says what to change
  try {
    buildGarment(mp, MannequinPose{}, GarmentPattern{}, "scene.json");
    FAIL() << "arms at the sides were accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("scene.json: at garment: the arms hang too close to the body"),
              std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("shoulderAbduction"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace soak
