// the plain stages of the PBD solver (src/pbd/integrate.cpp): the particles it moves, prediction and
// velocity update of those only
#include "support/run_scene.hpp"

#include "pbd/integrate.hpp"
#include "sim/diagnostics.hpp"

#include <gtest/gtest.h>

using namespace soak;
using namespace soak::testing;

namespace {

// a PBD sheet, an implicit sheet, another PBD sheet, and a block of water
Scene threePieces() {
  const auto sheet = [](const char* name, const char* solver, float y) {
    return std::string(R"({"name": ")") + name + R"(", "solver": ")" + solver +
           R"(", "mesh": {"type": "rectangle", "center": [0, )" + std::to_string(y) +
           R"(, 0], "size": [0.2, 0.2], "resolution": [5, 5]}})";
  };
  return sceneFromJson(R"({"solver": {"domain": {"min": [-1, -1, -1], "max": [1, 2, 1]}}, "cloth": [)" +
                       sheet("a", "pbd", 0.2f) + ", " + sheet("b", "implicit", 0.5f) + ", " + sheet("c", "pbd", 0.8f) +
                       R"(], "emitters": [{"type": "block", "min": [-0.05, 1.2, -0.05], "max": [0.05, 1.3, 0.05]}]})");
}

}  // namespace

TEST(Integrate, PbdParticlesAreThePbdPiecesAndTheWater) {
  Scene s = threePieces();
  const Model& m = s.model;
  runSteps(s, 1);  // the block is emitted
  const size_t n = s.state.particles.size();
  ASSERT_GT(n, size_t(m.numCloth));
  std::vector<IndexRange> ranges;
  pbdParticles(m, n, ranges);
  ASSERT_EQ(ranges.size(), 2u);  // piece a; then piece c and the water, which follow each other
  EXPECT_EQ(ranges[0].begin, m.pieces[0].firstParticle);
  EXPECT_EQ(ranges[0].end, m.pieces[0].firstParticle + m.pieces[0].particleCount);
  EXPECT_EQ(ranges[1].begin, m.pieces[2].firstParticle);
  EXPECT_EQ(ranges[1].end, int64_t(n));
}

TEST(Integrate, PredictionAndVelocitiesLeaveTheImplicitPieceAlone) {
  Scene s = threePieces();
  const Model& m = s.model;
  Particles& p = s.state.particles;
  std::vector<IndexRange> ranges;
  pbdParticles(m, p.size(), ranges);
  const ClothPiece& b = m.pieces[1];
  for (size_t i = 0; i < p.size(); ++i) p.xPred[i] = Vec3(9, 9, 9), p.v[i] = Vec3(1, 0, 0);
  predictPositions(m, ranges, p, 0.01f);
  for (int i = 0; i < m.numCloth; ++i) {
    const bool implicit = i >= b.firstParticle && i < b.firstParticle + b.particleCount;
    EXPECT_EQ(p.xPred[size_t(i)] == Vec3(9, 9, 9), implicit) << i;
  }
  for (size_t i = 0; i < p.size(); ++i) p.xPred[i] = p.x[i] + Vec3(0, 0.01f, 0);
  updateVelocities(m, ranges, p, 0.01f);
  for (int i = 0; i < m.numCloth; ++i) {
    const bool implicit = i >= b.firstParticle && i < b.firstParticle + b.particleCount;
    EXPECT_EQ(p.v[size_t(i)] == Vec3(1, 0, 0), implicit) << i;
  }
}
