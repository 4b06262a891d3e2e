// cloth pieces appended to a Model (src/scene/cloth_piece.cpp): the mesh checks (Shao 2017 section
// 3.2), the offsets, adjacency and constraints of two pieces, a curved rest shape
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "support/mesh_checks.hpp"
#include "pbd/cloth.hpp"
#include "scene/cloth_piece.hpp"

namespace soak {
namespace {

using testing::edgeUse;
using testing::errorOf;
using testing::TempFile;

TEST(MeshPiece, RefusesAnEdgeSharedByThreeTriangles) {
  // a "book" with three pages on the spine 1-2
  TempFile f("soak_mesh_book", "v 0 0 0\nv 0 1 0\nv 1 0 0\nv -1 0 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n");
  const TriangleMesh mesh = loadObjMesh(f.path.string());
  Model model;
  const std::string msg = errorOf([&] { addClothPiece(model, "book", mesh, ClothMaterial{}, {}, f.path.string()); });
  EXPECT_NE(msg.find(f.path.string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("vertices 0 and 1"), std::string::npos) << msg;
  EXPECT_NE(msg.find("each edge may be shared by at most two triangles (Shao 2017, section 3.2)"), std::string::npos)
      << msg;
  // a refused piece leaves the model as it was
  EXPECT_EQ(model.numCloth, 0);
  EXPECT_TRUE(model.pieces.empty());
  EXPECT_TRUE(model.triangles.empty());
}

TEST(MeshPiece, RefusesDegenerateTrianglesBadIndicesAndBadPins) {
  const std::string src = "scenes/broken.json";
  Model model;
  TriangleMesh collinear{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(0, 1, 0)}, {{0, 1, 3}, {0, 1, 2}}};
  std::string msg = errorOf([&] { addClothPiece(model, "flat", collinear, ClothMaterial{}, {}, src); });
  EXPECT_NE(msg.find(src), std::string::npos) << msg;
  EXPECT_NE(msg.find("triangle 1"), std::string::npos) << msg;
  EXPECT_NE(msg.find("zero area"), std::string::npos) << msg;

  TriangleMesh repeated{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}, {{0, 1, 1}}};
  msg = errorOf([&] { addClothPiece(model, "rep", repeated, ClothMaterial{}, {}, src); });
  EXPECT_NE(msg.find("zero area"), std::string::npos) << msg;

  TriangleMesh outOfRange{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}, {{0, 1, 3}}};
  msg = errorOf([&] { addClothPiece(model, "oor", outOfRange, ClothMaterial{}, {}, src); });
  EXPECT_NE(msg.find(src), std::string::npos) << msg;
  EXPECT_NE(msg.find("vertex index 3 is out of range"), std::string::npos) << msg;

  const TriangleMesh good = makeRectangle(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 1.0f, 1.0f, 3, 3);
  msg = errorOf([&] { addClothPiece(model, "pins", good, ClothMaterial{}, {0, 9}, src); });
  EXPECT_NE(msg.find(src), std::string::npos) << msg;
  EXPECT_NE(msg.find("pinned vertex 1"), std::string::npos) << msg;
  EXPECT_NE(msg.find("vertex index 9 is out of range"), std::string::npos) << msg;
  msg = errorOf([&] { addClothPiece(model, "pins", good, ClothMaterial{}, {-1}, src); });
  EXPECT_NE(msg.find("out of range"), std::string::npos) << msg;

  TriangleMesh empty{{Vec3(0, 0, 0)}, {}};
  msg = errorOf([&] { addClothPiece(model, "empty", empty, ClothMaterial{}, {}, src); });
  EXPECT_NE(msg.find("no triangles"), std::string::npos) << msg;
  EXPECT_EQ(model.numCloth, 0);

  EXPECT_NO_THROW(addClothPiece(model, "pins", good, ClothMaterial{}, {0, 8}, src));
  EXPECT_EQ(model.numCloth, 9);
}

TEST(MeshPiece, TwoPiecesAppendOffsetsAdjacencyAndConstraints) {
  Model model;
  ClothMaterial a, b;
  a.particleMass = 0.01f;
  a.stretchCompliance = 1e-6f;
  a.bendCompliance = 0.5f;
  b.particleMass = 0.02f;
  b.stretchCompliance = 2e-6f;
  b.bendCompliance = 0.25f;
  const TriangleMesh ma = makeRectangle(Vec3(0, 1, 0), Vec3::UnitX(), Vec3::UnitZ(), 0.4f, 0.3f, 5, 4);
  const TriangleMesh mb = makeRectangle(Vec3(0, 2, 0), Vec3::UnitX(), Vec3::UnitY(), 0.2f, 0.2f, 3, 3);
  addClothPiece(model, "a", ma, a, {0, 4}, "a.obj");
  addClothPiece(model, "b", mb, b, {8}, "b.obj");

  ASSERT_EQ(model.pieces.size(), 2u);
  EXPECT_EQ(model.pieces[1].firstParticle, 20);
  EXPECT_EQ(model.pieces[1].particleCount, 9);
  EXPECT_EQ(model.pieces[1].firstTriangle, 24);
  EXPECT_EQ(model.pieces[1].triangleCount, 8);
  EXPECT_EQ(model.numCloth, 29);
  ASSERT_EQ(model.clothRestPosition.size(), 29u);
  EXPECT_TRUE(model.clothRestPosition[20 + 4].isApprox(mb.vertices[4]));
  EXPECT_EQ(model.triangles[24][0], mb.triangles[0][0] + 20);
  EXPECT_FLOAT_EQ(model.clothDryMass[3], 0.01f);
  EXPECT_FLOAT_EQ(model.clothDryMass[25], 0.02f);
  int pinned = 0;
  for (int i = 0; i < 29; ++i) pinned += model.clothPinned[i];
  EXPECT_EQ(pinned, 3);
  EXPECT_EQ(model.clothPinned[0] + model.clothPinned[4] + model.clothPinned[28], 3);

  // constraints over both pieces: one stretch per unique edge, one bend per interior edge
  const auto use = edgeUse(model.triangles);
  size_t interior = 0;
  for (const auto& [e, count] : use) interior += (count == 2);
  EXPECT_EQ(model.stretch.ids.size(), use.size());
  EXPECT_EQ(model.bend.ids.size(), interior);
  std::set<std::pair<int, int>> stretchEdges;
  for (size_t k = 0; k < model.stretch.ids.size(); ++k) {
    const auto [i, j] = model.stretch.ids[k];
    EXPECT_TRUE(stretchEdges.insert({std::min(i, j), std::max(i, j)}).second) << "duplicate edge";
    EXPECT_TRUE(use.count({std::min(i, j), std::max(i, j)}));
    EXPECT_NEAR(model.stretch.restLength[k], (model.clothRestPosition[i] - model.clothRestPosition[j]).norm(), 1e-7f);
    EXPECT_FLOAT_EQ(model.stretch.compliance[k], i < 20 ? a.stretchCompliance : b.stretchCompliance);
    EXPECT_EQ(i < 20, j < 20) << "an edge across pieces";
  }
  for (size_t k = 0; k < model.bend.ids.size(); ++k) {
    const auto& id = model.bend.ids[k];
    EXPECT_EQ(use.at({std::min(id[0], id[1]), std::max(id[0], id[1])}), 2);
    EXPECT_NEAR(model.bend.restAngle[k], 0.0f, 1e-5f);  // both sheets are flat
    EXPECT_FLOAT_EQ(model.bend.compliance[k], id[0] < 20 ? a.bendCompliance : b.bendCompliance);
    // c and d are the opposite vertices of the two triangles of edge (a, b)
    int found = 0;
    for (const auto& t : model.triangles) {
      const bool hasEdge = std::count(t.begin(), t.end(), id[0]) && std::count(t.begin(), t.end(), id[1]);
      if (hasEdge) found += std::count(t.begin(), t.end(), id[2]) + 2 * std::count(t.begin(), t.end(), id[3]);
    }
    EXPECT_EQ(found, 3);
  }

  // 1-ring: sorted, symmetric, exactly the edges
  ASSERT_EQ(model.vertexNeighborStart.size(), 30u);
  size_t ringEntries = 0;
  for (int i = 0; i < 29; ++i) {
    const auto begin = model.vertexNeighbors.begin() + model.vertexNeighborStart[i];
    const auto end = model.vertexNeighbors.begin() + model.vertexNeighborStart[i + 1];
    EXPECT_TRUE(std::is_sorted(begin, end));
    for (auto it = begin; it != end; ++it) {
      EXPECT_TRUE(use.count({std::min(i, *it), std::max(i, *it)}));
      ++ringEntries;
    }
  }
  EXPECT_EQ(ringEntries, 2 * use.size());
  // triangles around a vertex: each listed triangle contains it, and the counts add up
  ASSERT_EQ(model.vertexTriangleStart.size(), 30u);
  EXPECT_EQ(model.vertexTriangles.size(), 3 * model.triangles.size());
  for (int i = 0; i < 29; ++i)
    for (int s = model.vertexTriangleStart[i]; s < model.vertexTriangleStart[i + 1]; ++s) {
      const auto& t = model.triangles[model.vertexTriangles[s]];
      EXPECT_TRUE(t[0] == i || t[1] == i || t[2] == i);
    }
  // alternating diagonals: interior vertices with i + j even lie in 8 triangles, the others in 4
  EXPECT_EQ(model.vertexTriangleStart[1] - model.vertexTriangleStart[0], 2);
  EXPECT_EQ(model.vertexTriangleStart[7] - model.vertexTriangleStart[6], 8);
  EXPECT_EQ(model.vertexTriangleStart[8] - model.vertexTriangleStart[7], 4);
}

TEST(MeshPiece, CurvedRestShapeKeepsItsDihedralAngles) {
  // a sheet folded 60 degrees along its middle column: the hinge edges rest at +-60 degrees, C = 0 at rest
  TriangleMesh m = makeRectangle(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 0.4f, 0.4f, 5, 5);
  const float angle = kPi / 3.0f;
  for (Vec3& x : m.vertices)
    if (x.x() > 1e-6f) x = Vec3(x.x() * std::cos(angle), x.y(), x.x() * std::sin(angle));
  Model model;
  addClothPiece(model, "fold", m, ClothMaterial{}, {}, "test");
  int hinges = 0;
  for (size_t k = 0; k < model.bend.ids.size(); ++k) {
    const auto& id = model.bend.ids[k];
    const auto& x = model.clothRestPosition;
    Vec3 g[4];
    EXPECT_NEAR(bendConstraint(x[id[0]], x[id[1]], x[id[2]], x[id[3]], model.bend.restAngle[k], g), 0.0f, 1e-6f);
    const bool onHinge = std::abs(x[id[0]].x()) < 1e-6f && std::abs(x[id[1]].x()) < 1e-6f;
    if (onHinge) {
      ++hinges;
      EXPECT_NEAR(std::abs(model.bend.restAngle[k]), angle, 1e-5f);
    } else {
      EXPECT_NEAR(model.bend.restAngle[k], 0.0f, 1e-5f);
    }
  }
  EXPECT_EQ(hinges, 4);
}

}  // namespace
}  // namespace soak
