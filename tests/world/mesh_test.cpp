// triangle meshes (src/world/mesh.cpp): generated rectangles and OBJ loading
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <set>

#include "support/mesh_checks.hpp"
#include "scene/cloth_piece.hpp"
#include "world/mesh.hpp"

namespace soak {
namespace {

using testing::edgeUse;
using testing::errorOf;
using testing::TempFile;

TEST(MeshRectangle, CountsPositionsWindingAndEdgeLengths) {
  const Vec3 center(1.0f, 2.0f, 3.0f), u(1, 0, 0), v(0, 0, -1);
  const int rx = 5, ry = 4;
  const TriangleMesh m = makeRectangle(center, u, v, 0.4f, 0.3f, rx, ry);
  ASSERT_EQ(m.vertices.size(), 20u);
  ASSERT_EQ(m.triangles.size(), 2u * 4u * 3u);
  for (int j = 0; j < ry; ++j)
    for (int i = 0; i < rx; ++i) {
      const Vec3 expect = center + (i / 4.0f - 0.5f) * 0.4f * u + (j / 3.0f - 0.5f) * 0.3f * v;
      EXPECT_LT((m.vertices[j * rx + i] - expect).norm(), 1e-6f);
    }
  const Vec3 normal = u.cross(v);
  for (const auto& t : m.triangles) {
    const Vec3 n = (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]);
    EXPECT_NEAR(n.normalized().dot(normal), 1.0f, 1e-5f);
    EXPECT_NEAR(0.5f * n.norm(), 0.5f * 0.1f * 0.1f, 1e-6f);
  }
  // horizontal, vertical and diagonal edges only; both diagonal directions appear (alternating)
  const auto use = edgeUse(m.triangles);
  EXPECT_EQ(use.size(), static_cast<size_t>(4 * 4 + 5 * 3 + 4 * 3));
  int diagUp = 0, diagDown = 0;
  for (const auto& [e, count] : use) {
    const float len = (m.vertices[e.first] - m.vertices[e.second]).norm();
    const bool axis = std::abs(len - 0.1f) < 1e-5f;
    const bool diag = std::abs(len - std::sqrt(0.02f)) < 1e-5f;
    EXPECT_TRUE(axis || diag) << "edge length " << len;
    if (diag) (e.second - e.first == rx + 1 ? diagUp : diagDown)++;
    EXPECT_LE(count, 2);
  }
  EXPECT_EQ(diagUp, 6);
  EXPECT_EQ(diagDown, 6);
  EXPECT_THROW(makeRectangle(center, u, v, 1.0f, 1.0f, 1, 5), Error);
}

TEST(MeshObj, LoadsAndTriangulatesQuads) {
  TempFile f("soak_mesh_quads",
             "# two quads\nv 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\n"
             "f 1 2 5 4\nf 2 3 6 5\n");
  const TriangleMesh m = loadObjMesh(f.path.string());
  ASSERT_EQ(m.vertices.size(), 6u);
  ASSERT_EQ(m.triangles.size(), 4u);
  EXPECT_TRUE(m.vertices[5].isApprox(Vec3(2, 1, 0)));
  float area = 0.0f;
  for (const auto& t : m.triangles)
    area += 0.5f * (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]).norm();
  EXPECT_NEAR(area, 2.0f, 1e-6f);
  Model model;
  addClothPiece(model, "quads", m, ClothMaterial{}, {}, f.path.string());
  EXPECT_EQ(model.numCloth, 6);
  EXPECT_EQ(model.stretch.ids.size(), 9u);
  EXPECT_EQ(model.bend.ids.size(), 3u);
}

TEST(MeshObj, MissingFileAndNoTrianglesAreNamed) {
  const std::string missing = "/nonexistent/soak_no_such_mesh.obj";
  const std::string msg = errorOf([&] { loadObjMesh(missing); });
  EXPECT_NE(msg.find(missing), std::string::npos) << msg;

  TempFile f("soak_mesh_points", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  const std::string msg2 = errorOf([&] { loadObjMesh(f.path.string()); });
  EXPECT_NE(msg2.find(f.path.string()), std::string::npos) << msg2;
  EXPECT_NE(msg2.find("no triangles"), std::string::npos) << msg2;
}

// the OBJ's numbers are read strictly: tinyobjloader alone reads "nan" or "abc" as 0
TEST(MeshObj, NumbersAreParsedStrictlyWithFileAndLine) {
  const auto errorFor = [](const std::string& text) { return errorOf([&] { parseObjMesh(text, "cloth.obj"); }); };
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  EXPECT_EQ(errorFor("v 1 2 3\n" + tri + "v nan nan nan\nf 1 2 3\n"),
            "cloth.obj: at line 5: expected 3 finite numbers (x y z, optionally w or r g b) after 'v', got 'nan'");
  EXPECT_EQ(errorFor(tri + "v abc def ghi\nf 1 2 3\n"),
            "cloth.obj: at line 4: expected 3 finite numbers (x y z, optionally w or r g b) after 'v', got 'abc'");
  EXPECT_EQ(errorFor("v 1 2 inf\n"), "cloth.obj: at line 1: expected 3 finite numbers (x y z, optionally w or r g b) "
                                      "after 'v', got 'inf'");
  EXPECT_EQ(errorFor("v 1 2\n"), "cloth.obj: at line 1: expected 3 finite numbers (x y z, optionally w or r g b) after "
                                  "'v', got 2 values");
  EXPECT_EQ(errorFor("v 1.5e2 2x 3\n"), "cloth.obj: at line 1: expected 3 finite numbers (x y z, optionally w or r g "
                                         "b) after 'v', got '2x'");
  EXPECT_EQ(errorFor(tri + "vn 0 nan 1\n"), "cloth.obj: at line 4: expected 3 finite numbers after 'vn', got 'nan'");
  EXPECT_EQ(errorFor(tri + "f 1 2 x\n"), "cloth.obj: at line 4: expected face vertices of non-zero integer indices "
                                          "(i, i/j, i//k or i/j/k) after 'f', got 'x'");
  EXPECT_EQ(errorFor(tri + "f 1 2 0\n"), "cloth.obj: at line 4: expected face vertices of non-zero integer indices "
                                          "(i, i/j, i//k or i/j/k) after 'f', got '0'");
  EXPECT_EQ(errorFor(tri + "f 1 2 99999999999\n"), "cloth.obj: at line 4: expected face vertices of non-zero "
                                                    "integer indices (i, i/j, i//k or i/j/k) after 'f', got "
                                                    "'99999999999'");
  EXPECT_EQ(errorFor(tri + "f 1 2\n"), "cloth.obj: at line 4: expected at least 3 vertices after 'f', got 2");
  // a control character in a bad token is not echoed into the message
  EXPECT_EQ(errorFor("v 1 2 \x1b[2J\n"), "cloth.obj: at line 1: expected 3 finite numbers (x y z, optionally w or r g "
                                          "b) after 'v', got '?[2J'");
  // well-formed: comments, CRLF, tabs, '+', colours, negative and slashed indices
  const TriangleMesh m = parseObjMesh("# c\r\nv +1\t0 0 # end\r\nv 1 1 0 0.5 0.5 0.5\r\nv 0 1 0\r\nvt 0 0\r\n"
                                      "vn 0 0 1\r\nf -3/1/1 2//1 3/1\r\n",
                                      "ok.obj");
  ASSERT_EQ(m.vertices.size(), 3u);
  EXPECT_TRUE(m.vertices[0].isApprox(Vec3(1, 0, 0)));
  ASSERT_EQ(m.triangles.size(), 1u);
}

TEST(MeshObj, OversizedFileIsRefusedBeforeReading) {
  // a sparse file: its size is known without writing a gigabyte
  TempFile f("soak_mesh_huge", "v 0 0 0\n");
  std::filesystem::resize_file(f.path, kMaxObjBytes + 1);
  EXPECT_EQ(errorOf([&] { loadObjMesh(f.path.string()); }),
            f.path.string() + ": expected an OBJ file of at most 1024 MiB, got 1073741825 bytes");
}

}  // namespace
}  // namespace soak
