// wrinkle disturbances of Chen 2012 section 3.5: three-sphere intersection (Eq. 25), curvature
// (Eq. 26), the choice rules, disturbances on a compressed sheet, and patches for meshes without panels
#include "garment/wrinkles.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <set>

#include "scene/cloth_piece.hpp"

namespace soak {
namespace {

TEST(GarmentWrinkles, ThreeSpheresMatchHandComputedCases) {
  const Vec3 c1(0, 0, 0), c2(1, 0, 0), c3(0, 1, 0);
  // unit spheres: (0.5, 0.5, +-sqrt(0.5)), the + one first ((c2 - c1) x (c3 - c1) = +z)
  SphereIntersection two = intersectThreeSpheres(c1, 1.0f, c2, 1.0f, c3, 1.0f, 1e-6f);
  ASSERT_EQ(two.count, 2);
  EXPECT_LT((two.point[0] - Vec3(0.5f, 0.5f, std::sqrt(0.5f))).norm(), 1e-6f);
  EXPECT_LT((two.point[1] - Vec3(0.5f, 0.5f, -std::sqrt(0.5f))).norm(), 1e-6f);
  // radius sqrt(0.5): the spheres touch at the circumcentre (0.5, 0.5, 0) only
  const float r = std::sqrt(0.5f);
  SphereIntersection one = intersectThreeSpheres(c1, r, c2, r, c3, r, 1e-4f);
  ASSERT_EQ(one.count, 1);
  EXPECT_LT((one.point[0] - Vec3(0.5f, 0.5f, 0.0f)).norm(), 1e-5f);
  // too small: none
  EXPECT_EQ(intersectThreeSpheres(c1, 0.3f, c2, 0.3f, c3, 0.3f, 1e-6f).count, 0);
  // collinear centres: no unique answer
  const SphereIntersection line = intersectThreeSpheres(c1, 1.0f, c2, 1.0f, Vec3(2, 0, 0), 1.0f, 1e-6f);
  EXPECT_EQ(line.count, 0);
  EXPECT_TRUE(line.degenerate);
  // a general case: radii 3, 4, 5 from (1, 2, 3), (5, 2, 3), (1, 7, 3)... both points at those distances
  const Vec3 a(1, 2, 3), b(4, 2.5f, 3), c(1.5f, 6, 2);
  const SphereIntersection g = intersectThreeSpheres(a, 3.0f, b, 3.5f, c, 4.0f, 1e-6f);
  ASSERT_EQ(g.count, 2);
  for (int k = 0; k < 2; ++k) {
    EXPECT_NEAR((g.point[k] - a).norm(), 3.0f, 1e-4f);
    EXPECT_NEAR((g.point[k] - b).norm(), 3.5f, 1e-4f);
    EXPECT_NEAR((g.point[k] - c).norm(), 4.0f, 1e-4f);
  }
  EXPECT_GT((g.point[0] - a).dot((b - a).cross(c - a)), 0.0f);
}

TEST(GarmentWrinkles, CurvatureOfEq26) {
  // path D -> A' -> B turning by 90 degrees over two unit segments: k = 2 / 2 * pi / 2
  EXPECT_NEAR(disturbanceCurvature(Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 0, 0)), kPi / 2.0f, 1e-6f);
  EXPECT_NEAR(disturbanceCurvature(Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(0, 0, 0)), 0.0f, 1e-3f);  // straight
  // 60 degree turn over segments 1 and 3: 2 / 4 * pi / 3
  EXPECT_NEAR(disturbanceCurvature(Vec3(1, 0, 0), Vec3(1 + 1.5f, 1.5f * std::sqrt(3.0f), 0), Vec3(0, 0, 0)),
              0.5f * kPi / 3.0f, 1e-5f);
}

TEST(GarmentWrinkles, ChoiceFollowsSection352Steps) {
  const Vec3 a(0, 0, 0);
  SphereIntersection one;
  one.count = 1;
  one.point[0] = Vec3(0, 0, 1);
  EXPECT_EQ(chooseDisturbance(a, one, {false, false}, Vec3(1, 0, 0), Vec3(-1, 0, 0), 1e-3f, 0), 0);
  EXPECT_EQ(chooseDisturbance(a, one, {true, false}, Vec3(1, 0, 0), Vec3(-1, 0, 0), 1e-3f, 0), -1);
  SphereIntersection two;
  two.count = 2;
  two.point = {Vec3(0, 0, 1), Vec3(0, 0, -0.5f)};
  const Vec3 b(1, 0, 1), d(-1, 0, 0);
  EXPECT_EQ(chooseDisturbance(a, two, {true, false}, b, d, 1e-3f, 0), 1);   // step 3
  EXPECT_EQ(chooseDisturbance(a, two, {false, true}, b, d, 1e-3f, 1), 0);
  EXPECT_EQ(chooseDisturbance(a, two, {true, true}, b, d, 1e-3f, 0), -1);
  EXPECT_EQ(chooseDisturbance(a, two, {false, false}, b, d, 1e-3f, 0), 1);  // step 4: the nearer
  // step 5: equally near; point 1 turns the path D -> A' -> B by 108 degrees, point 0 by 45
  two.point = {Vec3(0, 0, 1), Vec3(0, 0, -1)};
  EXPECT_EQ(chooseDisturbance(a, two, {false, false}, b, d, 1e-3f, 0), 1);
  // step 6: equal curvature too (mirror-symmetric B and D): the coin decides
  EXPECT_EQ(chooseDisturbance(a, two, {false, false}, Vec3(1, 0, 0), d, 1e-3f, 0), 0);
  EXPECT_EQ(chooseDisturbance(a, two, {false, false}, Vec3(1, 0, 0), d, 1e-3f, 1), 1);
}

struct Sheet {
  Model model;
  Particles p;
  SpringSet springs;
  std::vector<std::vector<int>> patches;
};

// a 12 x 12 sheet in the plane y = 1, squeezed to 85% along x
void makeSqueezedSheet(Sheet& s) {
  const TriangleMesh mesh = makeRectangle(Vec3(0, 1, 0), Vec3::UnitX(), Vec3::UnitZ(), 0.55f, 0.55f, 12, 12);
  addClothPiece(s.model, "sheet", mesh, ClothMaterial{}, {0}, "<test>");
  for (int i = 0; i < s.model.numCloth; ++i) {
    Vec3 x = s.model.clothRestPosition[i];
    x.x() *= 0.85f;
    s.p.add(1, uint32_t(i), s.model.clothDryMass[i], 0.04f, x, Vec3::Zero());
  }
  s.springs = buildPieceSprings(s.model, 0);
  s.patches = splitIntoPatches(s.model.numCloth, s.model.triangles, 36);
}

TEST(GarmentWrinkles, CompressedSheetGetsOutOfPlaneTargetsAtRestLength) {
  Sheet s;
  makeSqueezedSheet(s);
  WrinkleParams wp;
  wp.enabled = true;
  const std::vector<PositionConstraint> c = computeDisturbances(s.model, 0, s.springs, s.patches, s.p, {}, wp, 0);
  EXPECT_GE(c.size(), s.patches.size() - 1);
  EXPECT_LE(c.size(), s.patches.size());
  int up = 0, down = 0;
  std::set<int> seen;
  for (const PositionConstraint& k : c) {
    EXPECT_TRUE(seen.insert(k.vertex).second);
    EXPECT_NE(k.vertex, 0) << "a pinned vertex is never disturbed";
    const float l0 = 0.05f;
    EXPECT_GT(std::abs(k.target.y() - 1.0f), 0.2f * l0) << "the buckle leaves the plane";
    (k.target.y() > 1.0f ? up : down)++;
    // at least three stretch springs of the vertex are exactly at rest length at the target
    int atRest = 0;
    for (int e = s.springs.vertexStart[k.vertex]; e < s.springs.vertexStart[k.vertex + 1]; ++e) {
      const int sp = s.springs.vertexSpring[e];
      if (s.springs.kind(sp) != SpringKind::Stretch) continue;
      const float len = (k.target - s.p.x[s.springs.other(sp, k.vertex)]).norm();
      if (std::abs(len - s.springs.restLength[sp]) < 1e-4f * s.springs.restLength[sp]) ++atRest;
    }
    EXPECT_GE(atRest, 3) << "vertex " << k.vertex;
  }
  // a flat sheet gives mirror-equal candidates: the reproducible coin sends some each way
  EXPECT_GT(up, 0);
  EXPECT_GT(down, 0);

  // the same call again gives the same answer
  const std::vector<PositionConstraint> again = computeDisturbances(s.model, 0, s.springs, s.patches, s.p, {}, wp, 0);
  ASSERT_EQ(again.size(), c.size());
  for (size_t k = 0; k < c.size(); ++k) EXPECT_EQ(again[k].target, c[k].target);
}

// the disturbance follows the water: a vertex of saturation s moves dryStrength + (strength -
// dryStrength) s of the way to A'; a dry sheet with dryStrength 0 gets no disturbance at all, a half
// saturated one the same vertices as a saturated one, half as far
TEST(GarmentWrinkles, DisturbancesGrowWithTheSaturation) {
  WrinkleParams wp;
  wp.enabled = true;
  wp.strength = 0.8f;
  wp.dryStrength = 0.2f;
  EXPECT_FLOAT_EQ(disturbanceStrength(wp, 0.0f), 0.2f);
  EXPECT_FLOAT_EQ(disturbanceStrength(wp, 0.5f), 0.5f);
  EXPECT_FLOAT_EQ(disturbanceStrength(wp, 1.0f), 0.8f);
  EXPECT_FLOAT_EQ(disturbanceStrength(wp, 2.0f), 0.8f);
  EXPECT_FLOAT_EQ(disturbanceStrength(wp, NAN), 0.2f);
  Sheet s;
  makeSqueezedSheet(s);
  wp.strength = 1.0f;
  wp.dryStrength = 0.0f;
  const std::vector<float> dry(size_t(s.model.numCloth), 0.0f), half(size_t(s.model.numCloth), 0.5f);
  EXPECT_TRUE(computeDisturbances(s.model, 0, s.springs, s.patches, s.p, {}, wp, 0, dry).empty());
  const std::vector<PositionConstraint> full = computeDisturbances(s.model, 0, s.springs, s.patches, s.p, {}, wp, 0);
  const std::vector<PositionConstraint> halfway =
      computeDisturbances(s.model, 0, s.springs, s.patches, s.p, {}, wp, 0, half);
  ASSERT_FALSE(full.empty());
  ASSERT_EQ(halfway.size(), full.size());
  for (size_t k = 0; k < full.size(); ++k) {
    ASSERT_EQ(halfway[k].vertex, full[k].vertex);
    const Vec3& a = s.p.x[size_t(full[k].vertex)];
    EXPECT_LT((halfway[k].target - (a + 0.5f * (full[k].target - a))).norm(), 1e-6f) << k;
  }
}

TEST(GarmentWrinkles, ColliderBelowSendsEveryBuckleUp) {
  Sheet s;
  Collider floor;
  floor.shape = ColliderShape::Plane;
  floor.keys = {Keyframe{0.0f, Vec3(0, 0.999f, 0), Quat::Identity()}};
  s.model.colliders.push_back(floor);
  makeSqueezedSheet(s);
  const std::vector<ColliderPose> poses{colliderPose(s.model.colliders[0], 0.0)};
  WrinkleParams wp;
  wp.enabled = true;
  const std::vector<PositionConstraint> c = computeDisturbances(s.model, 0, s.springs, s.patches, s.p, poses, wp, 0);
  ASSERT_FALSE(c.empty());
  for (const PositionConstraint& k : c) EXPECT_GT(k.target.y(), 1.0f);
}

TEST(GarmentWrinkles, NothingWhenOffMovingOutOfTurnOrUncompressed) {
  Sheet s;
  makeSqueezedSheet(s);
  WrinkleParams wp;
  EXPECT_TRUE(computeDisturbances(s.model, 0, s.springs, s.patches, s.p, {}, wp, 0).empty());  // disabled
  wp.enabled = true;
  EXPECT_TRUE(computeDisturbances(s.model, 0, s.springs, s.patches, s.p, {}, wp, 3).empty());  // interval 10
  EXPECT_FALSE(computeDisturbances(s.model, 0, s.springs, s.patches, s.p, {}, wp, 20).empty());
  Particles moving = s.p;
  for (Vec3& v : moving.v) v = Vec3(0, 1, 0);  // far from equilibrium
  EXPECT_TRUE(computeDisturbances(s.model, 0, s.springs, s.patches, moving, {}, wp, 0).empty());
  wp.compressionThreshold = 0.2f;  // squeezed by 15% only
  EXPECT_TRUE(computeDisturbances(s.model, 0, s.springs, s.patches, s.p, {}, wp, 0).empty());
}

bool connected(const std::vector<int>& patch, const std::vector<std::array<int, 3>>& tris) {
  const std::set<int> in(patch.begin(), patch.end());
  std::set<int> reached{patch[0]};
  std::deque<int> q{patch[0]};
  while (!q.empty()) {
    const int v = q.front();
    q.pop_front();
    for (const auto& t : tris)
      for (int k = 0; k < 3; ++k)
        if (t[k] == v)
          for (int w : {t[(k + 1) % 3], t[(k + 2) % 3]})
            if (in.count(w) && reached.insert(w).second) q.push_back(w);
  }
  return reached.size() == patch.size();
}

TEST(GarmentWrinkles, PatchesCoverTheMeshConnectedAndOfSimilarSize) {
  TriangleMesh mesh = makeRectangle(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), 1.0f, 1.0f, 30, 30);
  // a second, small component (a separate 3 x 3 square)
  const TriangleMesh extra = makeRectangle(Vec3(3, 0, 0), Vec3::UnitX(), Vec3::UnitZ(), 0.1f, 0.1f, 3, 3);
  const int offset = int(mesh.vertices.size());
  for (const Vec3& v : extra.vertices) mesh.vertices.push_back(v);
  for (auto t : extra.triangles) mesh.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  const auto patches = splitIntoPatches(int(mesh.vertices.size()), mesh.triangles, 50);
  std::vector<int> count(mesh.vertices.size(), 0);
  for (const auto& p : patches) {
    ASSERT_FALSE(p.empty());
    EXPECT_TRUE(std::is_sorted(p.begin(), p.end()));
    EXPECT_TRUE(connected(p, mesh.triangles));
    for (int v : p) ++count[v];
    if (p[0] >= offset) {
      EXPECT_EQ(p.size(), 9u) << "the small component stays whole";
    } else {
      EXPECT_GE(p.size(), 25u);
      EXPECT_LE(p.size(), 100u);
    }
  }
  for (int c : count) EXPECT_EQ(c, 1);
  EXPECT_GE(patches.size(), 12u);
  EXPECT_LE(patches.size(), 25u);
}

}  // namespace
}  // namespace soak
