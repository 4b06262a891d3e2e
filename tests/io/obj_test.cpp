// cloth as Wavefront OBJ (io/obj.cpp): one group per piece, 1-based faces with matching normal indices,
// vertex colours, area-weighted normals, and the size checks that keep face indices right
#include "io/obj.hpp"

#include <gtest/gtest.h>

#include <soak/error.hpp>
#include <soak/output.hpp>

#include "io/io_support.hpp"

#include <sstream>
#include <string>
#include <vector>

namespace soak {
namespace {

using namespace soak::testing;

TEST(IoObj, OneGroupPerPieceFaceCountAndOneBasedIndices) {
  const Fixture f = makeFixture();
  const fs::path dir = tempDir("obj");
  const std::string path = (dir / "cloth_0000.obj").string();
  writeClothObj(path, f.model, f.state);
  int v = 0, vn = 0, faces = 0, minIndex = 1 << 30, maxIndex = 0;
  std::vector<std::string> groups;
  for (const std::string& l : lines(readTextFile(path))) {
    std::istringstream ss(l);
    std::string tag;
    ss >> tag;
    if (tag == "v") {
      float x, y, z;
      ss >> x >> y >> z;
      EXPECT_FLOAT_EQ(x, f.state.particles.x[v].x());
      EXPECT_FLOAT_EQ(y, f.state.particles.x[v].y());
      EXPECT_FLOAT_EQ(z, f.state.particles.x[v].z());
      ++v;
    } else if (tag == "vn") {
      ++vn;
    } else if (tag == "o") {
      std::string name;
      ss >> name;
      groups.push_back(name);
    } else if (tag == "f") {
      int corners = 0;
      for (std::string tok; ss >> tok; ++corners) {
        const size_t slash = tok.find("//");
        ASSERT_NE(slash, std::string::npos) << tok;
        const int vi = std::stoi(tok.substr(0, slash));
        EXPECT_EQ(vi, std::stoi(tok.substr(slash + 2)));  // normal index matches vertex index
        minIndex = std::min(minIndex, vi);
        maxIndex = std::max(maxIndex, vi);
      }
      EXPECT_EQ(corners, 3);
      const auto& tri = f.model.triangles[faces];
      std::istringstream again(l.substr(2));
      std::string first;
      again >> first;
      EXPECT_EQ(std::stoi(first.substr(0, first.find('/'))), tri[0] + 1);
      ++faces;
    }
  }
  EXPECT_EQ(v, 13);
  EXPECT_EQ(vn, 13);
  EXPECT_EQ(faces, 8 + 2);
  EXPECT_EQ(minIndex, 1);   // 1-based
  EXPECT_EQ(maxIndex, 13);  // last cloth particle
  EXPECT_EQ(groups, (std::vector<std::string>{"sheet", "patch"}));
  fs::remove_all(dir);
}

TEST(IoObj, VertexColoursAreWrittenAfterPositions) {
  const Fixture f = makeFixture();
  const fs::path dir = tempDir("objcolor");
  const std::string path = (dir / "c.obj").string();
  std::vector<Vec3> colour(13);
  for (int i = 0; i < 13; ++i) colour[i] = Vec3(i / 12.0f, 0.5f, 1.0f - i / 12.0f);
  writeClothObj(path, f.model, f.state, {}, colour);
  int v = 0;
  for (const std::string& l : lines(readTextFile(path))) {
    if (l.rfind("v ", 0) != 0) continue;
    std::istringstream ss(l.substr(2));
    float x, y, z, r, g, b;
    ASSERT_TRUE(ss >> x >> y >> z >> r >> g >> b) << l;
    EXPECT_FLOAT_EQ(r, colour[v].x());
    EXPECT_FLOAT_EQ(g, 0.5f);
    EXPECT_FLOAT_EQ(b, colour[v].z());
    ++v;
  }
  EXPECT_EQ(v, 13);
  std::vector<Vec3> wrong(5);
  EXPECT_THROW(writeClothObj(path, f.model, f.state, {}, wrong), Error);
  fs::remove_all(dir);
}

TEST(IoObj, NormalsAreAreaWeighted) {
  // vertex 0 is shared by a large triangle facing +z and a small one facing +x
  Model m;
  m.numCloth = 5;
  m.triangles = {{0, 1, 2}, {0, 3, 4}};
  std::vector<Vec3> x = {Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 2, 0), Vec3(0, 0.5f, 0), Vec3(0, 0, 0.5f)};
  const std::vector<Vec3> n = clothVertexNormals(m, x);
  // area normals: (0,0,4) from the first triangle, (0.25,0,0) from the second
  const Vec3 expected = Vec3(0.25f, 0, 4).normalized();
  EXPECT_NEAR((n[0] - expected).norm(), 0.0f, 1e-6f);
  EXPECT_NEAR((n[1] - Vec3(0, 0, 1)).norm(), 0.0f, 1e-6f);
  EXPECT_NEAR((n[3] - Vec3(1, 0, 0)).norm(), 0.0f, 1e-6f);
}

// the writer's checks: pieces must tile [0, numCloth) in order (else face index = particle + 1 breaks),
// normals and colours must be one per cloth particle, and the state must hold the cloth; each error names
// the file and what was expected
TEST(IoObj, SizeAndPieceLayoutErrorsNameTheFileAndTheNumbers) {
  const fs::path dir = tempDir("objchecks");
  const std::string path = (dir / "c.obj").string();
  const auto errorOf = [&](const Model& m, const State& s, std::span<const Vec3> normals) {
    try {
      writeClothObj(path, m, s, normals);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  Fixture f = makeFixture();
  std::vector<Vec3> two(2, Vec3::UnitY());
  EXPECT_EQ(errorOf(f.model, f.state, two), path + ": expected 13 normals, got 2");
  Model swapped = f.model;
  std::swap(swapped.pieces[0], swapped.pieces[1]);
  EXPECT_EQ(errorOf(swapped, f.state, {}), path + ": cloth piece 'patch' starts at particle 9, expected 0");
  Model partial = f.model;
  partial.pieces.pop_back();
  EXPECT_EQ(errorOf(partial, f.state, {}), path + ": cloth pieces cover 9 particles, expected 13");
  State small;
  small.particles = f.state.particles;
  small.particles.resize(10);
  EXPECT_EQ(errorOf(f.model, small, {}), path + ": state has 10 particles, model has 13 cloth particles");
  EXPECT_FALSE(fs::exists(path)) << "nothing is written when a check fails";
  fs::remove_all(dir);
}

// normals given by the caller are written as they are (not recomputed); a piece without a name is "cloth"
TEST(IoObj, GivenNormalsAreWrittenAsTheyAreAndAnUnnamedPieceIsCloth) {
  Fixture f = makeFixture();
  f.model.pieces[1].name.clear();
  const fs::path dir = tempDir("objnormals");
  const std::string path = (dir / "c.obj").string();
  std::vector<Vec3> normals(13);
  for (int i = 0; i < 13; ++i) normals[i] = Vec3(0.5f, -0.25f, 0.125f * i);
  writeClothObj(path, f.model, f.state, normals);
  int vn = 0;
  std::vector<std::string> groups;
  for (const std::string& l : lines(readTextFile(path))) {
    std::istringstream ss(l);
    std::string tag;
    ss >> tag;
    if (tag == "o") {
      std::string name;
      ss >> name;
      groups.push_back(name);
    }
    if (tag != "vn") continue;
    float x, y, z;
    ASSERT_TRUE(ss >> x >> y >> z) << l;
    EXPECT_EQ(Vec3(x, y, z), normals[vn]) << vn;
    ++vn;
  }
  EXPECT_EQ(vn, 13);
  EXPECT_EQ(groups, (std::vector<std::string>{"sheet", "cloth"}));
  fs::remove_all(dir);
}

// a vertex in no triangle, or only in degenerate ones, has a zero normal (not NaN); the others are unit
TEST(IoObj, AVertexWithoutAnAreaHasAZeroNormal) {
  Model m;
  m.numCloth = 7;
  m.triangles = {{0, 1, 2}, {3, 4, 5}};
  const std::vector<Vec3> xs = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, -1),   // faces +y
                                Vec3(0, 1, 0), Vec3(1, 1, 0), Vec3(2, 1, 0),    // collinear: no area
                                Vec3(5, 5, 5)};                                 // in no triangle
  const std::vector<Vec3> n = clothVertexNormals(m, xs);
  ASSERT_EQ(n.size(), 7u);
  for (int i = 0; i < 3; ++i) EXPECT_LT((n[i] - Vec3(0, 1, 0)).norm(), 1e-6f) << i;
  for (int i = 3; i < 7; ++i) EXPECT_EQ(n[i], Vec3::Zero()) << i;
}

// a piece name that reached the writer with a newline (the loader refuses one) cannot add lines
TEST(IoObj, PieceNamesAreEscapedNotTrusted) {
  Fixture f = makeFixture();
  f.model.pieces[0].name = "evil\nv 9 9 9\nf 1 2 3\\";
  const fs::path dir = tempDir("obj_escape");
  const std::string path = (dir / "cloth_0000.obj").string();
  writeClothObj(path, f.model, f.state);
  int v = 0, objects = 0;
  std::string first;
  for (const std::string& l : lines(readTextFile(path))) {
    v += l.rfind("v ", 0) == 0 ? 1 : 0;
    if (l.rfind("o ", 0) == 0 && objects++ == 0) first = l;
  }
  EXPECT_EQ(v, f.model.numCloth);
  EXPECT_EQ(objects, 2);
  EXPECT_EQ(first, "o evil\\x0av 9 9 9\\x0af 1 2 3\\\\");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace soak
