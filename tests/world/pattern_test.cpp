// sewing patterns (world/pattern.hpp): outline sampling, seam pairing, triangulation, placement, errors
#include "world/pattern.hpp"

#include <soak/error.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

namespace soak {
namespace {

PatternPanel rectanglePanel(const std::string& name, double w, double h, Vec3d origin, double yaw) {
  PatternPanel p;
  p.name = name;
  p.outline = {{-w / 2, 0}, {w / 2, 0}, {w / 2, h}, {-w / 2, h}};
  p.origin = origin;
  p.yaw = yaw;
  return p;
}

// a tube: front and back rectangles facing out, sewn along both sides
SewingPattern tube(double w, double h, double depth) {
  SewingPattern s;
  s.panels = {rectanglePanel("front", w, h, {0, 0, depth}, 0.0), rectanglePanel("back", w, h, {0, 0, -depth}, M_PI)};
  // the front's right side (corner 1 -> 2, at +x) meets the back's left side (corner 3 -> 0, also at +x)
  s.seams = {{{0, 1, 2}, {1, 3, 0}, false}, {{0, 3, 0}, {1, 1, 2}, false}};
  return s;
}

std::map<std::pair<int, int>, int> edgeUse(const TriangleMesh& m) {
  std::map<std::pair<int, int>, int> use;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) ++use[{std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])}];
  return use;
}

TEST(SewingPattern, TriangulatesAtTheEdgeLength) {
  const SewnGarment g = sewPattern(tube(0.5, 0.6, 0.2), 0.03, "tube");
  std::vector<double> len;
  double area = 0.0;
  for (const auto& t : g.mesh.triangles) {
    const Vec3 a = g.mesh.vertices[t[0]], b = g.mesh.vertices[t[1]], c = g.mesh.vertices[t[2]];
    area += 0.5 * double((b - a).cross(c - a).norm());
    for (int k = 0; k < 3; ++k) len.push_back((g.mesh.vertices[t[k]] - g.mesh.vertices[t[(k + 1) % 3]]).norm());
  }
  std::sort(len.begin(), len.end());
  EXPECT_NEAR(area, 2 * 0.5 * 0.6, 1e-4);  // the panels' area, exactly: no Steiner point leaves the outline
  // measured: median 1.01, p10 0.86, extremes 0.70 and 1.55 edge lengths
  EXPECT_NEAR(len[len.size() / 2], 0.03, 0.1 * 0.03);
  EXPECT_GE(len[len.size() / 10], 0.03 * 0.75);
  EXPECT_GE(len.front(), 0.03 * 0.5);
  EXPECT_LE(len.back(), 0.03 * 1.6);
  const double estimate = estimatedPatternVertices(tube(0.5, 0.6, 0.2), 0.03);
  EXPECT_NEAR(double(g.mesh.vertices.size()), estimate, 0.15 * estimate);
  // each edge in one or two triangles, and every triangle faces out of its panel (+z front, -z back)
  for (const auto& [e, n] : edgeUse(g.mesh)) EXPECT_TRUE(n == 1 || n == 2);
  for (const auto& t : g.mesh.triangles) {
    const Vec3 nrm = (g.mesh.vertices[t[1]] - g.mesh.vertices[t[0]]).cross(g.mesh.vertices[t[2]] - g.mesh.vertices[t[0]]);
    const float side = g.panelOfVertex[t[0]] == 0 ? 1.0f : -1.0f;
    EXPECT_GT(side * nrm.z(), 0.0f);
  }
}

TEST(SewingPattern, SeamsPairTheSidesPointForPoint) {
  const SewnGarment g = sewPattern(tube(0.5, 0.6, 0.2), 0.03, "tube");
  // 0.6 m sides at 0.03 m: 21 points a side, two sides
  ASSERT_EQ(g.seamPairs.size(), 2u * 21u);
  std::set<int> used;
  for (const auto& [a, b] : g.seamPairs) {
    EXPECT_NE(g.panelOfVertex[a], g.panelOfVertex[b]);
    const Vec3 pa = g.mesh.vertices[a], pb = g.mesh.vertices[b];
    EXPECT_NEAR(pa.y(), pb.y(), 1e-5);             // the same height: a's bottom meets b's bottom
    EXPECT_NEAR(std::abs(pa.x()), 0.25f, 1e-5);    // on the sides
    EXPECT_NEAR(pa.x(), pb.x(), 1e-5);             // the same side of the body
    EXPECT_NEAR(std::abs(pa.z() - pb.z()), 0.4f, 1e-5);
    EXPECT_TRUE(used.insert(a).second);
    EXPECT_TRUE(used.insert(b).second);
  }
}

TEST(SewingPattern, UnequalSidesKeepEveryCornerOfBoth) {
  SewingPattern s;
  PatternPanel a = rectanglePanel("a", 0.3, 0.4, {0, 0, 0.1}, 0.0);
  PatternPanel b;  // a kinked side: corners 1 -> 2 -> 3 run up the right at x 0.15, 0.2, 0.15
  b.name = "b";
  b.outline = {{-0.15, 0}, {0.15, 0}, {0.2, 0.25}, {0.15, 0.5}, {-0.15, 0.5}};
  b.origin = {0, 0, -0.1};
  b.yaw = M_PI;
  s.panels = {a, b};
  s.seams = {{{0, 3, 0}, {1, 1, 3}, false}};
  const SewnGarment g = sewPattern(s, 0.05, "kink");
  size_t onSeam = 0;
  bool kinkKept = false;
  for (const auto& [u, v] : g.seamPairs) {
    ++onSeam;
    for (int w : {u, v})
      if (g.panelOfVertex[w] == 1 && std::abs(g.mesh.vertices[w].y() - 0.25f) < 1e-5f &&
          std::abs(std::abs(g.mesh.vertices[w].x()) - 0.2f) < 1e-5f)
        kinkKept = true;
  }
  EXPECT_TRUE(kinkKept);
  // b's side is 0.51 m: 11 segments at 0.05 m (12 points), and the kink at half way between two of them
  EXPECT_EQ(onSeam, 13u);
}

TEST(SewingPattern, BentPanelsWrapAroundTheAxis) {
  SewingPattern s;
  s.panels = {rectanglePanel("front", 0.6, 0.3, {0, 0, 0.2}, 0.0)};
  s.panels[0].bend = 0.2;
  const SewnGarment g = sewPattern(s, 0.03, "bent");
  for (const Vec3& x : g.mesh.vertices)  // on the cylinder of radius 0.2 about the y axis
    EXPECT_NEAR(std::hypot(x.x(), x.z()), 0.2f, 1e-5f);
}

void expectError(SewingPattern s, const std::string& part) {
  try {
    sewPattern(s, 0.05, "pat");
    FAIL() << "no error, expected one containing " << part;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST(SewingPattern, RefusesBadPatternsNamingThePlace) {
  SewingPattern cw = tube(0.5, 0.6, 0.2);
  std::reverse(cw.panels[1].outline.begin(), cw.panels[1].outline.end());
  expectError(cw, "pat.panels[1].outline: expected counter-clockwise");
  SewingPattern bow = tube(0.5, 0.6, 0.2);
  std::swap(bow.panels[0].outline[2], bow.panels[0].outline[3]);
  expectError(bow, "pat.panels[0].outline: expected a simple polygon");
  SewingPattern corner = tube(0.5, 0.6, 0.2);
  corner.seams[0].b.to = 7;
  expectError(corner, "pat.seams[0].b.to: expected a corner index in [0, 3]");
  SewingPattern twice = tube(0.5, 0.6, 0.2);
  twice.seams.push_back(twice.seams[0]);
  expectError(twice, "expected each outline segment in at most one seam");
  SewingPattern same = tube(0.5, 0.6, 0.2);
  same.panels[1].name = "front";
  expectError(same, "pat.panels[1].name: expected a name no other panel has");
  SewingPattern wrap = tube(0.5, 0.6, 0.2);
  wrap.panels[0].bend = 0.05;
  expectError(wrap, "pat.panels[0].bend: expected a radius that wraps the panel at most half way");
}

}  // namespace
}  // namespace soak
