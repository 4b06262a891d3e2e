// shared fixtures of the io tests (tests/io/*_test.cpp): a temp folder, a hand-made Model/State with two
// cloth pieces and five water particles, and a text split into lines
#pragma once
#include <soak/model.hpp>
#include <soak/state.hpp>

#include <unistd.h>

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

namespace soak::testing {

namespace fs = std::filesystem;

// a fresh folder under the system temp folder (the caller removes it)
inline fs::path tempDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("soak_io_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// appends an (nx x ny) grid piece in the y = height plane, with a slight bump so normals differ
inline void addGridPiece(Model& m, State& s, const std::string& name, int nx, int ny, float height, float pinnedY) {
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
inline Fixture makeFixture() {
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

inline std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream ss(text);
  for (std::string l; std::getline(ss, l);) out.push_back(l);
  return out;
}

}  // namespace soak::testing
