// the output writers on hand-made Model/State objects: OBJ and PLY round trips, stats lines, errors
#include <gtest/gtest.h>

#include "io/file.hpp"
#include "io/obj.hpp"
#include "io/output.hpp"
#include "io/ply.hpp"
#include "io/stats.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

#include <unistd.h>

namespace soak {
namespace {

namespace fs = std::filesystem;

fs::path tempDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("soak_io_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// appends an (nx x ny) grid piece in the y = height plane, with a slight bump so normals differ
void addGridPiece(Model& m, State& s, const std::string& name, int nx, int ny, float height, float pinnedY) {
  ClothPiece piece;
  piece.name = name;
  piece.firstParticle = m.numCloth;
  piece.particleCount = nx * ny;
  piece.firstTriangle = static_cast<int>(m.triangles.size());
  const int pieceIndex = static_cast<int>(m.pieces.size());
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const Vec3 x(0.1f * i, height + 0.01f * i * j, 0.1f * j);
      s.particles.add(pieceIndex + 1, s.nextId++, 0.0066f, 0.04f, x, Vec3(0.5f * i, -1.0f, 0.25f * j));
      m.clothRestPosition.push_back(x);
      m.clothDryMass.push_back(0.0066f);
      m.clothPinned.push_back(j == 0 && x.y() >= pinnedY ? 1 : 0);
    }
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const int a = m.numCloth + j * nx + i, b = a + 1, c = a + nx, d = c + 1;
      m.triangles.push_back({a, c, b});
      m.triangles.push_back({b, c, d});
    }
  piece.triangleCount = static_cast<int>(m.triangles.size()) - piece.firstTriangle;
  m.numCloth += nx * ny;
  m.pieces.push_back(piece);
}

struct Fixture {
  Model model;
  State state;
};

// two cloth pieces (3x3 and 2x2) followed by five water particles
Fixture makeFixture() {
  Fixture f;
  addGridPiece(f.model, f.state, "sheet", 3, 3, 1.0f, 0.0f);
  addGridPiece(f.model, f.state, "patch", 2, 2, 0.5f, 1.0e9f);
  for (int k = 0; k < 5; ++k)
    f.state.particles.add(kWaterPhase, 100 + 7 * k, 0.0082f - 0.001f * k, 0.04f - 0.002f * k,
                          Vec3(0.02f * k, 2.0f, -0.5f), Vec3(0, -0.3f * k, 1.5f));
  f.state.time = 0.03;
  f.state.stepCount = 2;
  return f;
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream ss(text);
  for (std::string l; std::getline(ss, l);) out.push_back(l);
  return out;
}

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

TEST(IoPly, ClothRoundTripsThroughReader) {
  const Fixture f = makeFixture();
  const fs::path dir = tempDir("clothply");
  const std::string path = (dir / "cloth_0001.ply").string();
  std::vector<float> saturation(13);
  for (int i = 0; i < 13; ++i) saturation[i] = 0.05f * i;
  const PlyFloatAttribute extra[] = {{"saturation", saturation}};
  writeClothPly(path, f.model, f.state, {}, extra);
  const PlyData ply = readPly(path);
  EXPECT_EQ(ply.format, "binary_little_endian");
  const PlyElement& v = ply.element("vertex");
  ASSERT_EQ(v.count, 13u);
  EXPECT_EQ(v.propertyNames, (std::vector<std::string>{"x", "y", "z", "nx", "ny", "nz", "vx", "vy", "vz", "piece",
                                                       "pinned", "saturation"}));
  EXPECT_EQ(v.propertyType.at("piece"), "int");
  EXPECT_EQ(v.propertyType.at("pinned"), "uchar");
  const std::vector<Vec3> normals = clothVertexNormals(f.model, f.state.particles.x);
  for (int i = 0; i < 13; ++i) {
    EXPECT_EQ(v.scalar("x")[i], f.state.particles.x[i].x());
    EXPECT_EQ(v.scalar("y")[i], f.state.particles.x[i].y());
    EXPECT_EQ(v.scalar("z")[i], f.state.particles.x[i].z());
    EXPECT_EQ(v.scalar("nx")[i], normals[i].x());
    EXPECT_EQ(v.scalar("ny")[i], normals[i].y());
    EXPECT_EQ(v.scalar("vx")[i], f.state.particles.v[i].x());
    EXPECT_EQ(v.scalar("vz")[i], f.state.particles.v[i].z());
    EXPECT_EQ(v.scalar("piece")[i], i < 9 ? 0 : 1);
    EXPECT_EQ(v.scalar("pinned")[i], f.model.clothPinned[i]);
    EXPECT_EQ(v.scalar("saturation")[i], saturation[i]);
  }
  // the fixture pins the first row of the sheet only
  EXPECT_EQ(v.scalar("pinned")[0], 1);
  EXPECT_EQ(v.scalar("pinned")[9], 0);
  const PlyElement& faces = ply.element("face");
  ASSERT_EQ(faces.count, f.model.triangles.size());
  EXPECT_EQ(faces.propertyType.at("vertex_indices"), "list uchar int");
  const auto& start = faces.listStart.at("vertex_indices");
  const auto& idx = faces.listValues.at("vertex_indices");
  for (size_t t = 0; t < faces.count; ++t) {
    ASSERT_EQ(start[t + 1] - start[t], 3u);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(idx[start[t] + k], f.model.triangles[t][k]);  // 0-based
  }
  fs::remove_all(dir);
}

TEST(IoPly, WaterRoundTripsThroughReader) {
  const Fixture f = makeFixture();
  const fs::path dir = tempDir("waterply");
  const std::string path = (dir / "water_0001.ply").string();
  writeWaterPly(path, f.state);
  const PlyData ply = readPly(path);
  ASSERT_EQ(ply.elements.size(), 1u);
  const PlyElement& v = ply.element("vertex");
  ASSERT_EQ(v.count, 5u);  // only water particles
  EXPECT_EQ(v.propertyNames,
            (std::vector<std::string>{"x", "y", "z", "vx", "vy", "vz", "mass", "radius", "id"}));
  EXPECT_EQ(v.propertyType.at("id"), "uint");
  EXPECT_EQ(v.propertyType.at("mass"), "float");
  for (int k = 0; k < 5; ++k) {
    const size_t i = 13 + k;
    EXPECT_EQ(v.scalar("id")[k], 100 + 7 * k);
    EXPECT_EQ(v.scalar("x")[k], f.state.particles.x[i].x());
    EXPECT_EQ(v.scalar("y")[k], 2.0f);
    EXPECT_EQ(v.scalar("vy")[k], f.state.particles.v[i].y());
    EXPECT_EQ(v.scalar("vz")[k], 1.5f);
    EXPECT_EQ(v.scalar("mass")[k], f.state.particles.mass[i]);
    EXPECT_EQ(v.scalar("radius")[k], f.state.particles.radius[i]);
  }
  // an empty water set is still a valid file
  State empty;
  writeWaterPly(path, empty);
  EXPECT_EQ(readPly(path).element("vertex").count, 0u);
  fs::remove_all(dir);
}

TEST(IoPly, ReaderReadsAsciiAndRejectsTruncatedFiles) {
  const fs::path dir = tempDir("plyread");
  const std::string ascii = (dir / "a.ply").string();
  writeTextFile(ascii,
                "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty uint id\n"
                "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                "0.5 7\n-1.25 9\n3 0 1 1\n");
  const PlyData a = readPly(ascii);
  EXPECT_EQ(a.element("vertex").scalar("x"), (std::vector<double>{0.5, -1.25}));
  EXPECT_EQ(a.element("vertex").scalar("id"), (std::vector<double>{7, 9}));
  EXPECT_EQ(a.element("face").listValues.at("vertex_indices"), (std::vector<int64_t>{0, 1, 1}));

  const Fixture f = makeFixture();
  const std::string path = (dir / "water.ply").string();
  writeWaterPly(path, f.state);
  std::string bytes = readTextFile(path);
  writeTextFile(path, bytes.substr(0, bytes.size() - 10));
  try {
    readPly(path);
    FAIL() << "a truncated PLY was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  writeTextFile(path, "not a ply\n");
  EXPECT_THROW(readPly(path), Error);
  fs::remove_all(dir);
}

// every writer names the path it could not open
TEST(IoErrors, UnwritablePathThrowsNamingIt) {
  const Fixture f = makeFixture();
  const std::string missing = (fs::temp_directory_path() / "soak_no_such_dir_io" / "sub").string();
  fs::remove_all(fs::temp_directory_path() / "soak_no_such_dir_io");
  const auto expectNamed = [&](const std::string& path, auto&& write) {
    try {
      write(path);
      ADD_FAILURE() << "no error writing " << path;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  };
  expectNamed(missing + "/cloth_0000.obj", [&](const std::string& p) { writeClothObj(p, f.model, f.state); });
  expectNamed(missing + "/cloth_0000.ply", [&](const std::string& p) { writeClothPly(p, f.model, f.state); });
  expectNamed(missing + "/water_0000.ply", [&](const std::string& p) { writeWaterPly(p, f.state); });
  expectNamed(missing + "/stats.jsonl", [&](const std::string& p) { JsonLinesWriter w(p); });
  expectNamed(missing + "/water_0000.ply", [&](const std::string& p) { readPly(p); });
  expectNamed(missing, [&](const std::string& p) { writeFrameFiles(p, f.model, f.state, OutputSettings{}, 0); });
}

TEST(IoErrors, ExtraAttributeMustMatchClothAndHaveAFreshName) {
  const Fixture f = makeFixture();
  const fs::path dir = tempDir("extras");
  const std::string path = (dir / "c.ply").string();
  std::vector<float> shortValues(4), ok(13);
  const PlyFloatAttribute wrongSize[] = {{"saturation", shortValues}};
  EXPECT_THROW(writeClothPly(path, f.model, f.state, {}, wrongSize), Error);
  const PlyFloatAttribute clash[] = {{"x", ok}};
  EXPECT_THROW(writeClothPly(path, f.model, f.state, {}, clash), Error);
  const PlyFloatAttribute badName[] = {{"wet ness", ok}};
  EXPECT_THROW(writeClothPly(path, f.model, f.state, {}, badName), Error);
  fs::remove_all(dir);
}

TEST(IoStats, FrameLineSumsStepsAndAccountsWater) {
  Fixture f = makeFixture();
  f.state.ledger.emitted = 0.05;
  f.state.ledger.removedAtBounds = 0.0123;
  f.state.ledger.particlesRemovedAtBounds = 3;
  FrameStats fs;
  StepStats a, b;
  a.substeps = 2;
  a.ms.neighbors = 1.0;
  a.ms.part(StagePart::neighborsLists) = 0.75;
  a.ms.total = 4.0;
  a.couplingContacts = 10;
  a.meanDensityRatio = 0.9f;
  a.maxSpeed = 2.0f;
  a.removedParticles = 1;
  b.substeps = 2;
  b.ms.neighbors = 0.5;
  b.ms.part(StagePart::neighborsLists) = 0.25;
  b.ms.part(StagePart::wettingEmission) = 0.5;
  b.ms.total = 2.0;
  b.couplingContacts = 5;
  b.meanDensityRatio = 1.1f;
  b.maxSpeed = 3.0f;
  b.removedParticles = 2;
  fs.add(a);
  fs.add(b);
  const auto j = frameStatsJson(f.model, f.state, 1, fs);
  EXPECT_EQ(j["frame"], 1);
  EXPECT_DOUBLE_EQ(j["time"].get<double>(), 0.03);
  EXPECT_EQ(j["step"], 2);
  EXPECT_EQ(j["steps"], 2);
  EXPECT_EQ(j["substeps"], 4);
  EXPECT_EQ(j["counts"]["water"], 5);
  EXPECT_EQ(j["counts"]["cloth"], 13);
  EXPECT_EQ(j["couplingContacts"], 15);
  EXPECT_EQ(j["removedAtBounds"]["frame"], 3);
  EXPECT_EQ(j["removedAtBounds"]["total"], 3);
  EXPECT_NEAR(j["meanDensityRatio"].get<double>(), 1.0, 1e-6);
  EXPECT_FLOAT_EQ(j["maxSpeed"].get<float>(), 3.0f);
  EXPECT_DOUBLE_EQ(j["ms"]["neighbors"].get<double>(), 1.5);
  EXPECT_DOUBLE_EQ(j["ms"]["total"].get<double>(), 6.0);
  EXPECT_DOUBLE_EQ(j["msPerStep"].get<double>(), 3.0);
  for (const char* stage : {"emit", "predict", "neighbors", "water", "cloth", "coupling", "colliders", "velocities"})
    EXPECT_TRUE(j["ms"].contains(stage)) << stage;
  // the stages' parts, summed over the frame's steps, every one named
  ASSERT_EQ(j["msParts"].size(), static_cast<size_t>(kStagePartCount));
  EXPECT_DOUBLE_EQ(j["msParts"]["neighbors.lists"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(j["msParts"]["wetting.emission"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(j["msParts"]["wetting.absorption"].get<double>(), 0.0);
  // free = sum of water masses (0.0082 + 0.0072 + ... + 0.0042) in float
  double free = 0.0;
  for (int k = 0; k < 5; ++k) free += 0.0082f - 0.001f * k;
  EXPECT_NEAR(j["waterMass"]["free"].get<double>(), free, 1e-9);
  EXPECT_NEAR(j["waterMass"]["total"].get<double>(), free + 0.0123, 1e-9);
  EXPECT_DOUBLE_EQ(j["waterMass"]["emitted"].get<double>(), 0.05);

  // frame 0: no steps, max speed measured on the state, no density ratio yet
  const auto j0 = frameStatsJson(f.model, f.state, 0, FrameStats{});
  EXPECT_TRUE(j0["meanDensityRatio"].is_null());
  // the fastest particle is water particle 4 with v = (0, -1.2, 1.5)
  EXPECT_NEAR(j0["maxSpeed"].get<double>(), std::sqrt(1.2 * 1.2 + 1.5 * 1.5), 1e-5);
  EXPECT_EQ(j0["msPerStep"], 0.0);
}

TEST(IoStats, JsonLinesAreOneObjectPerLine) {
  const fs::path dir = tempDir("jsonl");
  const std::string path = (dir / "stats.jsonl").string();
  {
    JsonLinesWriter w(path);
    w.write({{"frame", 0}});
    w.write({{"frame", 1}, {"error", "boom"}});
  }
  const auto ls = lines(readTextFile(path));
  ASSERT_EQ(ls.size(), 2u);
  EXPECT_EQ(nlohmann::json::parse(ls[1])["error"], "boom");
  fs::remove_all(dir);
}

TEST(IoOutput, FrameFilesFollowSettingsAndNumbering) {
  const Fixture f = makeFixture();
  const fs::path dir = tempDir("frames");
  OutputSettings s;
  auto files = writeFrameFiles(dir.string(), f.model, f.state, s, 7);
  ASSERT_EQ(files.size(), 3u);
  EXPECT_TRUE(fs::exists(dir / "cloth_0007.obj"));
  EXPECT_TRUE(fs::exists(dir / "cloth_0007.ply"));
  EXPECT_TRUE(fs::exists(dir / "water_0007.ply"));
  s.clothObj = false;
  s.water = false;
  files = writeFrameFiles(dir.string(), f.model, f.state, s, 12345);
  ASSERT_EQ(files.size(), 1u);
  EXPECT_EQ(fs::path(files[0]).filename(), "cloth_12345.ply");
  EXPECT_EQ(frameFileName("water", 3, "ply"), "water_0003.ply");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace soak
