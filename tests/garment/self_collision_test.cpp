// vertex-triangle and edge-edge self-collision of implicit garments (garment/self_collision.hpp)
#include "garment/self_collision.hpp"
#include "garment/self_collision_resolve.hpp"
#include "support/mesh_crossings.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstring>
#include <set>
#include <tuple>
#include <numeric>

namespace soak {
namespace {

// the triangle (0,0,0), (1,0,0), (0,1,0) in z = 0 and a vertex above its point (0.25, 0.25)
std::array<Vec3, 4> startAbove(float z) { return {Vec3(0.25f, 0.25f, z), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}; }
// the vertex's height over the (moved) triangle's point under it (barycentric 0.5, 0.25, 0.25)
float aboveTriangle(const std::array<Vec3, 4>& x) {
  return x[0].z() - (0.5f * x[1].z() + 0.25f * x[2].z() + 0.25f * x[3].z());
}

TEST(GarmentSelfCollision, AVertexThatPassedThroughIsPutBackOnItsSide) {
  const std::array<Vec3, 4> x0 = startAbove(0.02f);
  std::array<Vec3, 4> x1 = startAbove(-0.01f);  // went through during the step
  std::array<Vec3, 4> v = {Vec3(0, 0, -3), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  const std::array<float, 4> w = {1.0f, 1.0f, 1.0f, 1.0f};
  Vec3 momentum = Vec3::Zero(), moment0 = Vec3::Zero();
  for (int k = 0; k < 4; ++k) moment0 += v[k] / w[k];
  ASSERT_TRUE(pushVertexOffTriangle(x0, x1, v, w, 0.008f));
  // a push closes at most one thickness of the gap (1.8 cm here: the vertex 1 cm under the triangle)
  EXPECT_NEAR(aboveTriangle(x1), -0.002f, 1e-6f);
  // the passes that follow finish it: the vertex a thickness above the triangle, which moved down
  ASSERT_TRUE(pushVertexOffTriangle(x0, x1, v, w, 0.008f));
  ASSERT_TRUE(pushVertexOffTriangle(x0, x1, v, w, 0.008f));
  EXPECT_NEAR(aboveTriangle(x1), 0.008f, 1e-6f);
  EXPECT_FALSE(pushVertexOffTriangle(x0, x1, v, w, 0.008f));
  EXPECT_LT(x1[1].z(), 0.0f);
  for (int k = 0; k < 4; ++k) momentum += v[k] / w[k];
  EXPECT_NEAR((momentum - moment0).norm(), 0.0f, 1e-5f);  // the impulse is shared, not created
  // the approach is removed: the vertex no longer moves towards the triangle
  EXPECT_GE(v[0].z() - (0.5f * v[1].z() + 0.25f * v[2].z() + 0.25f * v[3].z()), -1e-5f);
}

TEST(GarmentSelfCollision, ClearVerticesAndPinnedPairsAreLeftAlone) {
  const std::array<float, 4> w = {1.0f, 1.0f, 1.0f, 1.0f};
  std::array<Vec3, 4> v{};
  std::array<Vec3, 4> far = startAbove(0.02f);
  EXPECT_FALSE(pushVertexOffTriangle(startAbove(0.02f), far, v, w, 0.008f));  // farther than the thickness
  std::array<Vec3, 4> beside = {Vec3(2, 2, 0.001f), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  EXPECT_FALSE(pushVertexOffTriangle(beside, beside, v, w, 0.008f));  // projects outside the triangle
  std::array<Vec3, 4> near = startAbove(0.002f);
  EXPECT_FALSE(pushVertexOffTriangle(startAbove(0.002f), near, v, {0, 0, 0, 0}, 0.008f));  // nothing may move
  std::array<Vec3, 4> below = startAbove(-0.002f);  // below stays below
  ASSERT_TRUE(pushVertexOffTriangle(startAbove(-0.002f), below, v, w, 0.008f));
  EXPECT_LT(below[0].z(), below[1].z());
}

// a triangle that flipped over during the step (two of its corners swapped sides, as in a crumpling
// fold) has no side to keep: the vertex that stayed above it is not pushed through it. Compared with
// the same vertex under a triangle that only moved, which is put back.
TEST(GarmentSelfCollision, AFlippedTriangleDoesNotPushAVertexThrough) {
  const std::array<float, 4> w = {1.0f, 1.0f, 1.0f, 1.0f};
  std::array<Vec3, 4> v{};
  const std::array<Vec3, 4> x0 = startAbove(0.005f);
  // the end: b and c swapped (the normal turned from +z to -z), the vertex still 5 mm above the plane
  std::array<Vec3, 4> flipped = {Vec3(0.25f, 0.25f, 0.005f), Vec3(0, 0, 0), Vec3(0, 1, 0), Vec3(1, 0, 0)};
  const std::array<Vec3, 4> before = flipped;
  EXPECT_FALSE(pushVertexOffTriangle(x0, flipped, v, w, 0.008f));
  EXPECT_EQ(flipped, before);
  std::array<Vec3, 4> moved = startAbove(0.005f);  // not flipped: within the thickness, pushed to it
  ASSERT_TRUE(pushVertexOffTriangle(x0, moved, v, w, 0.008f));
  EXPECT_GT(moved[0].z(), 0.005f);
}

// a vertex that went round the triangle's edge (from above and beside it to under it, as a fold
// sliding over itself does) crossed the plane outside the triangle: it is on its new side by right,
// kept there (pushed to the thickness below), not pushed up through the triangle
TEST(GarmentSelfCollision, AVertexThatWentRoundTheEdgeKeepsItsNewSide) {
  const std::array<float, 4> w = {1.0f, 1.0f, 1.0f, 1.0f};
  std::array<Vec3, 4> v{};
  const std::array<Vec3, 4> x0 = {Vec3(-0.3f, 0.25f, 0.001f), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  std::array<Vec3, 4> x1 = startAbove(-0.003f);
  ASSERT_TRUE(pushVertexOffTriangle(x0, x1, v, w, 0.008f));
  EXPECT_NEAR(aboveTriangle(x1), -0.008f, 1e-6f);  // below, at the thickness
  // the same end reached straight through the triangle is put back above it
  std::array<Vec3, 4> through = startAbove(-0.003f);
  ASSERT_TRUE(pushVertexOffTriangle(startAbove(0.01f), through, v, w, 0.008f));
  EXPECT_NEAR(aboveTriangle(through), 0.005f, 1e-6f);  // by one thickness of its 1.1 cm gap
}

TEST(GarmentSelfCollision, ASheetDroppedOnAnotherStaysOnIt) {
  // two 2 x 2 quads of the same piece: the upper one's vertices fall through the lower one's plane
  Particles p;
  const std::vector<Vec3> lower = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0)};
  for (const Vec3& x : lower) p.add(1, 0, 1.0f, 0.04f, x, Vec3::Zero());
  for (const Vec3& x : lower) p.add(1, 0, 1.0f, 0.04f, x + Vec3(0.1f, 0.2f, 0.02f), Vec3::Zero());
  p.xPred = p.x;
  for (int i = 4; i < 8; ++i) p.xPred[i].z() = -0.005f;
  const std::vector<std::array<int, 3>> tris = {{0, 1, 3}, {0, 3, 2}, {4, 5, 7}, {4, 7, 6}};
  const std::vector<float> inv(8, 1.0f);
  SelfCollisionScratch s;
  EXPECT_GT(selfCollide(buildSelfCollisionMesh(8, tris, {}), 0, 8, inv, 0.008f, p, s).vertexTriangle, 0);
  for (int i = 4; i < 8; ++i)  // every upper vertex over the lower sheet is back above it
    if (p.xPred[i].x() < 1.0f && p.xPred[i].y() < 1.0f) EXPECT_GT(p.xPred[i].z(), 0.0f) << i;
}

// a vertex that went through a triangle and 20 cm beyond in one step (far past the boxes' pads: a fast
// fold) is found by its sweep; the pushes close a thickness each, so the fail-safe's impact zone takes
// over: the four points move together by their mean displacement, the vertex stays above, momentum kept
TEST(GarmentSelfCollision, AVertexThatWentFarThroughInOneStepEndsOnItsSide) {
  Particles p;
  for (const Vec3& x : startAbove(0.02f)) p.add(1, 0, 1.0f, 0.01f, x, Vec3::Zero());
  p.v[0] = Vec3(0, 0, -13.2f);  // 22 cm in 1/60 s
  p.xPred = p.x;
  p.xPred[0].z() = -0.2f;
  const std::vector<float> inv(4, 1.0f);
  Vec3 momentum0 = Vec3::Zero(), shift0 = Vec3::Zero();
  for (int k = 0; k < 4; ++k) std::tie(momentum0, shift0) = std::pair(momentum0 + p.v[k], shift0 + (p.xPred[k] - p.x[k]));
  SelfCollisionScratch s;
  const SelfCollisionPushes pushes = selfCollide(buildSelfCollisionMesh(4, {{1, 2, 3}}, {}), 0, 4, inv, 0.008f, p, s);
  ASSERT_EQ(s.pairs.size(), 1u);  // found through its sweep
  EXPECT_EQ(pushes.reverted, 4);
  const std::array<Vec3, 4> end{p.xPred[0], p.xPred[1], p.xPred[2], p.xPred[3]};
  EXPECT_NEAR(aboveTriangle(end), 0.02f, 1e-6f);  // the shape it started the step with
  Vec3 momentum = Vec3::Zero(), shift = Vec3::Zero();
  for (int k = 0; k < 4; ++k) std::tie(momentum, shift) = std::pair(momentum + p.v[k], shift + (p.xPred[k] - p.x[k]));
  EXPECT_NEAR((momentum - momentum0).norm(), 0.0f, 1e-5f);
  EXPECT_NEAR((shift - shift0).norm(), 0.0f, 1e-5f);  // the zone moves by the points' mean displacement
}

// two 20 x 20 sheets of one piece, 1 cm apart and wavy, the upper moved 2 cm down through the lower
struct TwoSheets {
  Particles start;
  std::vector<std::array<int, 3>> tris;
  int n = 0;
};
TwoSheets twoWavySheets() {
  constexpr int kSide = 20;
  TwoSheets t;
  for (int layer = 0; layer < 2; ++layer) {
    const int base = layer * kSide * kSide;
    for (int j = 0; j < kSide; ++j)
      for (int i = 0; i < kSide; ++i) {
        const float wave = 0.004f * std::sin(1.3f * i + 0.7f * j);
        t.start.add(1, 0, 1.0f, 0.01f, Vec3(0.01f * i + 0.003f * layer, 0.01f * j, 0.012f * layer + wave), Vec3::Zero());
      }
    for (int j = 0; j + 1 < kSide; ++j)
      for (int i = 0; i + 1 < kSide; ++i) {
        const int a = base + j * kSide + i;
        t.tris.push_back({a, a + 1, a + kSide + 1});
        t.tris.push_back({a, a + kSide + 1, a + kSide});
      }
  }
  t.n = 2 * kSide * kSide;
  t.start.xPred = t.start.x;
  for (int i = kSide * kSide; i < t.n; ++i) t.start.xPred[i].z() -= 0.02f;  // 8 mm through the lower sheet
  return t;
}

// the proximity pairs are found by chunks in parallel, and the pushes come out the same for any
// thread count
TEST(GarmentSelfCollision, SameResultForAnyThreadCount) {
  constexpr int kSide = 20;
  const TwoSheets sheets = twoWavySheets();
  const Particles& start = sheets.start;
  const int n = sheets.n;
  const SelfCollisionMesh mesh = buildSelfCollisionMesh(n, sheets.tris, {});
  const std::vector<float> inv(n, 1.0f);
  auto run = [&](int threads) {
    const int before = omp_get_max_threads();
    omp_set_num_threads(threads);
    Particles p = start;
    SelfCollisionScratch s;
    const SelfCollisionPushes pushes = selfCollide(mesh, 0, n, inv, 0.008f, p, s);
    omp_set_num_threads(before);
    return std::pair{pushes, p};
  };
  const auto [pushes1, a] = run(1);
  const auto [pushes2, b] = run(2);
  EXPECT_GT(pushes1.vertexTriangle, kSide * kSide);  // every upper vertex over the lower sheet, at least once
  EXPECT_GT(pushes1.edgeEdge, 0);
  EXPECT_EQ(pushes1.vertexTriangle, pushes2.vertexTriangle);
  EXPECT_EQ(pushes1.edgeEdge, pushes2.edgeEdge);
  EXPECT_EQ(std::memcmp(a.xPred.data(), b.xPred.data(), n * sizeof(Vec3)), 0);
  EXPECT_EQ(std::memcmp(a.v.data(), b.v.data(), n * sizeof(Vec3)), 0);
}

// the passes (pushPairs) skip a pair found clear until one of its points moves: the pushes are those
// of testing every pair in every one of the three passes, in the same order (the reference below)
TEST(GarmentSelfCollision, SkippingPairsThatDidNotMoveGivesTheSamePushes) {
  const TwoSheets sheets = twoWavySheets();
  const int n = sheets.n;
  const SelfCollisionMesh mesh = buildSelfCollisionMesh(n, sheets.tris, {});
  const std::vector<float> inv(n, 1.0f);
  constexpr float kThickness = 0.008f;
  Particles p = sheets.start;
  SelfCollisionScratch s;
  selfCollide(mesh, 0, n, inv, kThickness, p, s);  // the step's pairs, into s
  p = sheets.start;
  s.moved.assign(static_cast<size_t>(n), 0);
  const SelfCollisionPushes pushes = pushPairs(mesh, inv, kThickness, p.x.data(), p.xPred.data(), p.v.data(), s);
  Particles q = sheets.start;
  int vertexTriangle = 0, edgeEdge = 0, later = 0;  // later: pushes after the first pass
  const auto test = [&](const std::array<int, 4>& id, auto&& push) {
    std::array<Vec3, 4> x0, x1, v;
    std::array<float, 4> w;
    for (int k = 0; k < 4; ++k) std::tie(x0[k], x1[k], v[k], w[k]) = std::tuple(q.x[id[k]], q.xPred[id[k]], q.v[id[k]], inv[id[k]]);
    if (!push(x0, x1, v, w)) return 0;
    for (int k = 0; k < 4; ++k) std::tie(q.xPred[id[k]], q.v[id[k]]) = std::tuple(x1[k], v[k]);
    return 1;
  };
  for (int pass = 0; pass < 3; ++pass) {
    const int before = vertexTriangle + edgeEdge;
    for (const auto& [i, t] : s.pairs)
      vertexTriangle += test({i, sheets.tris[t][0], sheets.tris[t][1], sheets.tris[t][2]}, [&](auto& x0, auto& x1, auto& v, auto& w) {
        return pushVertexOffTriangle(x0, x1, v, w, kThickness);
      });
    for (const auto& [a, b] : s.edgePairs)
      edgeEdge += test({mesh.edges[a][0], mesh.edges[a][1], mesh.edges[b][0], mesh.edges[b][1]},
                       [&](auto& x0, auto& x1, auto& v, auto& w) { return pushEdgeOffEdge(x0, x1, v, w, kThickness); });
    if (pass > 0) later += vertexTriangle + edgeEdge - before;
  }
  EXPECT_GT(later, 0);  // the later passes push too: the skipping is exercised
  EXPECT_EQ(pushes.vertexTriangle, vertexTriangle);
  EXPECT_EQ(pushes.edgeEdge, edgeEdge);
  EXPECT_EQ(std::memcmp(p.xPred.data(), q.xPred.data(), n * sizeof(Vec3)), 0);
  EXPECT_EQ(std::memcmp(p.v.data(), q.v.data(), n * sizeof(Vec3)), 0);
}

// the edges' closest points, p0 + s (p1 - p0) and q0 + t (q1 - q0), in double precision, when
// inside both; their distance, else infinity
double edgeDistance(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  const Vec3d e1 = (p1 - p0).cast<double>(), e2 = (q1 - q0).cast<double>(), r = (q0 - p0).cast<double>();
  const double a = e1.squaredNorm(), b = e1.dot(e2), c = e2.squaredNorm(), det = a * c - b * b;
  if (det <= 0.02 * a * c) return 1e30;  // near parallel: not the edge-edge test's
  const double s = (e1.dot(r) * c - b * e2.dot(r)) / det, t = (b * e1.dot(r) - a * e2.dot(r)) / det;
  if (s < 0.0 || s > 1.0 || t < 0.0 || t > 1.0) return 1e30;
  return (r + t * e2 - s * e1).norm();
}

// every edge pair closer than the thickness at the end of the step (closest points inside both, not
// sharing a triangle) is among the step's edge pairs, and each pair is there once: the broad phase
// misses nothing and reports a pair seen in several cells once
TEST(GarmentSelfCollision, EveryEdgePairWithinTheThicknessIsFoundOnce) {
  const TwoSheets sheets = twoWavySheets();
  const Particles& start = sheets.start;
  const int n = sheets.n;
  const SelfCollisionMesh mesh = buildSelfCollisionMesh(n, sheets.tris, {});
  Particles p = start;
  SelfCollisionScratch s;
  selfCollide(mesh, 0, n, std::vector<float>(n, 1.0f), 0.008f, p, s);
  std::set<std::array<int, 2>> found(s.edgePairs.begin(), s.edgePairs.end());
  EXPECT_EQ(found.size(), s.edgePairs.size());
  size_t near = 0;
  const auto& e = mesh.edges;
  for (size_t i = 0; i < e.size(); ++i)
    for (size_t j = i + 1; j < e.size(); ++j) {
      bool close = false;  // sharing a vertex or a triangle
      for (int a : e[i])
        for (int b : e[j]) close = close || a == b || mesh.neighbours(a, b);
      if (close) continue;
      const auto& x = start.xPred;
      if (edgeDistance(x[e[i][0]], x[e[i][1]], x[e[j][0]], x[e[j][1]]) >= 0.008) continue;
      ++near;
      EXPECT_TRUE(found.count({int(i), int(j)})) << i << " " << j;
    }
  EXPECT_GT(near, 100u);  // measured: the sheets meet in many places
}

// a 3 x 2 grid (0 1 2 / 3 4 5) whose right column is seamed to a second quad's left (6 7 / 8 9)
TEST(GarmentSelfCollision, TheMeshJoinsSeamedVerticesAndKnowsTheirNeighbours) {
  const std::vector<std::array<int, 3>> tris = {{0, 1, 4}, {0, 4, 3}, {1, 2, 5}, {1, 5, 4}, {6, 7, 9}, {6, 9, 8}};
  const SelfCollisionMesh m = buildSelfCollisionMesh(10, tris, {{2, 6}, {8, 5}});
  EXPECT_EQ(m.edges.size(), 9u + 5u);
  EXPECT_TRUE(std::is_sorted(m.edges.begin(), m.edges.end()));
  EXPECT_EQ(m.group, (std::vector<int>{0, 1, 2, 3, 4, 5, 2, 7, 5, 9}));
  EXPECT_TRUE(m.neighbours(0, 4));   // across the diagonal
  EXPECT_FALSE(m.neighbours(0, 5));  // two triangles apart
  EXPECT_TRUE(m.neighbours(1, 2));
  EXPECT_TRUE(m.neighbours(2, 7));   // through the seam: 6 is 2's group
  EXPECT_TRUE(m.neighbours(2, 9));   // 6 shares (6, 9, 8) with 9
  EXPECT_TRUE(m.neighbours(9, 5));   // 8 is 5's group
  EXPECT_FALSE(m.neighbours(7, 5));  // 7's one triangle is (6, 7, 9)
  EXPECT_FALSE(m.neighbours(1, 7));
}

// edge A along x in z = 0, edge B along y at height z over its middle (points A0, A1, B0, B1)
std::array<Vec3, 4> edgesCrossingAt(float z, float bx = 0.0f) {
  return {Vec3(-0.5f, 0, 0), Vec3(0.5f, 0, 0), Vec3(bx, -0.5f, z), Vec3(bx, 0.5f, z)};
}
// the height of B's middle over A's point under it, at the fraction s along A
float bOverA(const std::array<Vec3, 4>& x, float s = 0.5f) {
  return 0.5f * (x[2].z() + x[3].z()) - ((1.0f - s) * x[0].z() + s * x[1].z());
}

TEST(GarmentSelfCollision, AnEdgeThatPassedThroughAnEdgeIsPutBack) {
  std::array<Vec3, 4> x1 = edgesCrossingAt(-0.003f);
  std::array<Vec3, 4> v{Vec3::Zero(), Vec3::Zero(), Vec3(0, 0, -1), Vec3(0, 0, -1)};
  const std::array<float, 4> w{1, 1, 1, 1};
  ASSERT_TRUE(pushEdgeOffEdge(edgesCrossingAt(0.01f), x1, v, w, 0.008f));
  EXPECT_NEAR(bOverA(x1), 0.005f, 1e-6f);  // back over A by one thickness of the 1.1 cm gap
  EXPECT_NEAR(x1[0].z() + x1[1].z() + x1[2].z() + x1[3].z(), -0.006f, 1e-6f);  // equal masses: momentum kept
  EXPECT_NEAR(v[2].z() - v[0].z(), 0.0f, 1e-6f);                           // no longer approaching
  EXPECT_NEAR(v[0].z() + v[1].z() + v[2].z() + v[3].z(), -2.0f, 1e-6f);
  ASSERT_TRUE(pushEdgeOffEdge(edgesCrossingAt(0.01f), x1, v, w, 0.008f));
  EXPECT_NEAR(bOverA(x1), 0.008f, 1e-6f);
  EXPECT_FALSE(pushEdgeOffEdge(edgesCrossingAt(0.01f), x1, v, w, 0.008f));  // clear now
  std::array<Vec3, 4> pinnedA = edgesCrossingAt(0.002f);  // only B moves: all of the push is B's
  ASSERT_TRUE(pushEdgeOffEdge(edgesCrossingAt(0.01f), pinnedA, v, {0, 0, 1, 1}, 0.008f));
  EXPECT_NEAR(pinnedA[2].z(), 0.008f, 1e-6f);
  EXPECT_EQ(pinnedA[0].z(), 0.0f);
}

TEST(GarmentSelfCollision, EdgesPastEachOthersEndsParallelOrInOneSheetAreLeftAlone) {
  std::array<Vec3, 4> v{};
  const std::array<float, 4> w{1, 1, 1, 1};
  std::array<Vec3, 4> beyond = edgesCrossingAt(0.002f, 0.6f);  // B over the line of A, past its end
  EXPECT_FALSE(pushEdgeOffEdge(beyond, beyond, v, w, 0.008f));
  std::array<Vec3, 4> parallel = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0.001f, 0.002f), Vec3(1, 0.001f, 0.002f)};
  EXPECT_FALSE(pushEdgeOffEdge(parallel, parallel, v, w, 0.008f));
  // two edges of one flat sheet: their lines meet outside them
  std::array<Vec3, 4> sheet = {Vec3(0, 0, 0), Vec3(0.02f, 0, 0), Vec3(0.02f, 0.02f, 0), Vec3(0.04f, 0.04f, 0)};
  EXPECT_FALSE(pushEdgeOffEdge(sheet, sheet, v, w, 0.008f));
  std::array<Vec3, 4> near = edgesCrossingAt(0.002f);
  EXPECT_FALSE(pushEdgeOffEdge(edgesCrossingAt(0.01f), near, v, {0, 0, 0, 0}, 0.008f));  // nothing may move
  // B slid down past A's end (x from 1.5 to 0.4: it crossed A's line at x = 0.65, beyond A's end at 0.5)
  // and under it: it keeps its new side, pushed to a thickness below
  std::array<Vec3, 4> under = edgesCrossingAt(-0.003f, 0.4f);
  ASSERT_TRUE(pushEdgeOffEdge(edgesCrossingAt(0.01f, 1.5f), under, v, w, 0.008f));
  EXPECT_NEAR(bOverA(under, 0.9f), -0.008f, 1e-6f);
}

// two 2 cm wide strips of one piece at right angles, 1 cm apart: the lower (vertices 0-3) along x in
// z = 0, the upper (4-7) along y moving down at `speed`, its end at y = -0.5 lowered by `drop` in the step
Particles crossedStrips(float speed, float drop) {
  Particles p;
  for (float y : {-0.01f, 0.01f})
    for (float x : {-0.5f, 0.5f}) p.add(1, 0, 1.0f, 0.01f, Vec3(x, y, 0), Vec3::Zero());
  for (float y : {-0.5f, 0.5f})
    for (float x : {-0.01f, 0.01f}) p.add(1, 0, 1.0f, 0.01f, Vec3(x, y, 0.01f), Vec3(0, 0, -speed));
  p.xPred = p.x;
  for (int i = 4; i < 6; ++i) p.xPred[i].z() -= drop;
  return p;
}
const std::vector<std::array<int, 3>> kStripTriangles = {{0, 1, 3}, {0, 3, 2}, {4, 5, 7}, {4, 7, 6}};

// the upper strip tilts, one end 2 cm down, through the lower: no vertex of either lies over the
// other's triangles, only their edges cross
TEST(GarmentSelfCollision, StripsCrossingOnlyAtTheirEdgesAreKeptApart) {
  const Particles start = crossedStrips(1.0f, 0.02f);
  const std::vector<std::array<int, 3>>& tris = kStripTriangles;
  const SelfCollisionMesh mesh = buildSelfCollisionMesh(8, tris, {});
  const std::vector<float> inv(8, 1.0f);
  const auto crossings = [&](const Particles& p) { return testing::countCrossingTriangles(p.xPred, tris); };
  ASSERT_GT(crossings(start), 0u);
  SelfCollisionScratch s;
  Particles vertexOnly = start;
  SelfCollisionMesh noEdges = mesh;
  noEdges.edges.clear();
  EXPECT_EQ(selfCollide(noEdges, 0, 8, inv, 0.008f, vertexOnly, s).vertexTriangle, 0);  // no vertex over a triangle
  EXPECT_GT(crossings(vertexOnly), 0u);
  Particles p = start;
  const SelfCollisionPushes pushes = selfCollide(mesh, 0, 8, inv, 0.008f, p, s);
  EXPECT_EQ(pushes.vertexTriangle, 0);
  EXPECT_GT(pushes.edgeEdge, 0);
  EXPECT_EQ(crossings(p), 0u);
  const auto middleHeight = [&](int a, int b) { return 0.5f * (p.xPred[a].z() + p.xPred[b].z()); };
  EXPECT_GT(middleHeight(4, 7), middleHeight(0, 3));  // the upper strip's middle is back over the lower's
}

// the strips of the test above, the upper one's end moved 40 cm down in one step: its middle passes
// 20 cm through the lower strip, far past the pads, and only their edges meet. The edge-edge sweep
// finds them and the fail-safe keeps the upper strip's middle over the lower (where it started)
TEST(GarmentSelfCollision, StripsPassingFarThroughEachOtherInOneStepKeepTheirSides) {
  Particles p = crossedStrips(12.0f, 0.4f);
  const auto middleHeight = [&](int a, int b) { return 0.5f * (p.xPred[a].z() + p.xPred[b].z()); };
  ASSERT_LT(middleHeight(4, 7), middleHeight(0, 3) - 0.1f);  // the upper strip's middle ends 20 cm under
  SelfCollisionScratch s;
  const SelfCollisionPushes pushes =
      selfCollide(buildSelfCollisionMesh(8, kStripTriangles, {}), 0, 8, std::vector<float>(8, 1.0f), 0.008f, p, s);
  EXPECT_GT(s.edgePairs.size(), 0u);
  EXPECT_EQ(pushes.reverted, 8);  // every point joins the zone
  EXPECT_GT(middleHeight(4, 7), middleHeight(0, 3));
  EXPECT_EQ(testing::countCrossingTriangles(p.xPred, kStripTriangles), 0u);
}

}  // namespace
}  // namespace soak
