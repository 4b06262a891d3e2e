// the Chen 2012 stages of the step (garment/stage.cpp) on their own: the wet signal of a vertex touched
// by a drop (and the drop taken in), the wetness written to the PLY, the coupling's push turned into
// velocity, the garment panels as wrinkle subdomains, the saturation mass of a PBD piece, a step too fast
// redone in smaller ones (the stages inside whole runs: tests/garment/run_test.cpp)
#include "garment/stage.hpp"

#include <soak/error.hpp>
#include <soak/output.hpp>
#include <soak/scene.hpp>
#include <soak/step.hpp>
#include <soak/threads.hpp>

#include <gtest/gtest.h>

#include "garment/saturation_mass.hpp"
#include "grid/grid.hpp"
#include "support/garment_scene.hpp"
#include "world/colliders.hpp"
#include "world/garment_mesh.hpp"

#include <cmath>
#include <set>
#include <string>
#include <vector>

namespace soak {
namespace {

using namespace soak::testing;

// the unit normal of the flat rest sheet of kSheet (11 x 11 vertices)
Vec3 sheetNormal(const Model& m) {
  return (m.clothRestPosition[1] - m.clothRestPosition[0]).cross(m.clothRestPosition[11] - m.clothRestPosition[0]).normalized();
}

// the wet-by-contact stage on its own: neighbour lists on the particles' positions, as the step
// builds them, then wetClothByContact at `time`; returns the particles taken
struct WetStage {
  NeighborGrid grid;
  NeighborLists nb;
  GarmentScratch scratch;
  std::vector<uint8_t> keep;
  DropCandidates candidates;  // the triangles near each water particle's path (none by default)
  size_t operator()(const Model& m, State& state, double time) {
    buildGrid(state.particles.x, 0.04f, grid);
    buildNeighborLists(state.particles.x, state.particles.radius, grid, nb);
    return wetClothByContact(m, state, nb, candidates, scratch, keep, time);
  }
};

// with an unlimited supply (Chen as printed) a drop within touchDistance (thickness + water spacing =
// 0.028 m) of a vertex wets that vertex, and every vertex within its reach, and vanishes into the piece
// (counted in the ledger); one 5% beyond it does nothing. Vertices are 0.04 m apart, so each drop's
// reach is known exactly
TEST(GarmentStage, WithUnlimitedSupplyADropWetsTheVerticesWithinReachAndVanishes) {
  Scene s = fromString(kSheet, {"cloth.0.saturation.supply=\"unlimited\""});
  const Model& m = s.model;
  ASSERT_EQ(m.numCloth, 121);
  const float reach = touchDistance(m, m.pieces[0]);
  EXPECT_FLOAT_EQ(reach, 0.008f + m.water.spacing);
  const Vec3 n = sheetNormal(m);
  const std::vector<Vec3>& x0 = m.clothRestPosition;
  Particles& p = s.state.particles;
  const float mass = m.water.particleMass;
  p.add(kWaterPhase, 1000, mass, 0.04f, x0[60] + 0.95f * reach * n, Vec3::Zero());                 // wets 60
  p.add(kWaterPhase, 1001, 0.5f * mass, 0.04f, x0[30] + 1.05f * reach * n, Vec3::Zero());         // too far
  p.add(kWaterPhase, 1002, 0.25f * mass, 0.04f, 0.5f * (x0[24] + x0[25]) + 0.01f * n, Vec3::Zero());  // 24, 25
  WetStage stage;
  const size_t taken = stage(m, s.state, 0.5);
  EXPECT_EQ(taken, 2u);
  for (int i = 0; i < m.numCloth; ++i) {
    const bool wet = i == 60 || i == 24 || i == 25;
    if (wet)
      EXPECT_EQ(s.state.clothWetStart[size_t(i)], 0.5f) << i;
    else
      EXPECT_FALSE(std::isfinite(s.state.clothWetStart[size_t(i)])) << i;
  }
  ASSERT_EQ(p.size(), size_t(m.numCloth) + 1);
  EXPECT_EQ(p.id.back(), 1001u);
  EXPECT_DOUBLE_EQ(s.state.ledger.takenByCloth, double(mass) + double(0.25f * mass));
  EXPECT_EQ(s.state.ledger.particlesTakenByCloth, 2u);

  // a second pass at a later time keeps the first wet times
  p.x.back() = x0[30] + 0.5f * reach * n;
  EXPECT_EQ(stage(m, s.state, 0.75), 1u);
  EXPECT_EQ(s.state.clothWetStart[30], 0.75f);
  EXPECT_EQ(s.state.clothWetStart[60], 0.5f);
  EXPECT_EQ(p.size(), size_t(m.numCloth));
}

// the drops supply (default): a drop goes into the nearest vertex within reach that holds less than
// its capacity delta m_dry (only that vertex is wet); the water is held (clothWater, heldInCloth), not
// lost; a drop whose vertices within reach are all full stays a water particle (it runs off)
TEST(GarmentStage, ADropGoesIntoTheNearestVertexWithRoomAndRunsOffAFullOne) {
  Scene s = fromString(kSheet);
  const Model& m = s.model;
  const float reach = touchDistance(m, m.pieces[0]);
  const Vec3 n = sheetNormal(m);
  const std::vector<Vec3>& x0 = m.clothRestPosition;
  Particles& p = s.state.particles;
  const double capacity = waterCapacity(m.clothDryMass[60], m.pieces[0].garment.saturation);
  const float mass = float(0.25 * capacity);  // a rain drop smaller than a vertex holds
  p.add(kWaterPhase, 1000, mass, 0.04f, x0[60] + 0.5f * reach * n, Vec3::Zero());
  p.add(kWaterPhase, 1001, mass, 0.04f, 0.4f * x0[24] + 0.6f * x0[25] + 0.01f * n, Vec3::Zero());  // nearer 25
  s.state.clothWater[25] = capacity;  // full: the drop goes into 24 instead
  WetStage stage;
  EXPECT_EQ(stage(m, s.state, 0.5), 2u);
  EXPECT_EQ(p.size(), size_t(m.numCloth));
  for (int i = 0; i < m.numCloth; ++i) {
    EXPECT_EQ(std::isfinite(s.state.clothWetStart[size_t(i)]), i == 60 || i == 24) << i;
    if (i != 60 && i != 24 && i != 25) EXPECT_EQ(s.state.clothWater[size_t(i)], 0.0) << i;
  }
  EXPECT_DOUBLE_EQ(s.state.clothWater[60], double(mass));
  EXPECT_DOUBLE_EQ(s.state.clothWater[24], double(mass));
  EXPECT_EQ(s.state.ledger.takenByCloth, 0.0);
  EXPECT_EQ(s.state.ledger.particlesTakenByCloth, 2u);
  EXPECT_NEAR(waterMass(s.state).heldInCloth, capacity + 2.0 * mass, 1e-12);

  // vertex 60 full: a drop right over it, with no other vertex within reach, stays
  s.state.clothWater[60] = capacity;
  p.add(kWaterPhase, 1002, mass, 0.04f, x0[60] + 0.3f * reach * n, Vec3::Zero());
  EXPECT_EQ(stage(m, s.state, 0.75), 0u);
  EXPECT_EQ(p.size(), size_t(m.numCloth) + 1);
  EXPECT_EQ(s.state.clothWater[60], capacity);
}

// a drop on the fabric's surface but farther than touchDistance from every vertex (over a triangle,
// within reach of its plane): the vertices alone miss it; with the triangle among its path's
// candidates it soaks in at that triangle's nearest vertex (with an unlimited supply it vanishes
// and wets that vertex). A candidate whose surface is out of reach takes nothing
TEST(GarmentStage, ADropOnATriangleFarFromItsVerticesSoaksInThroughTheTriangle) {
  Scene s = fromString(kSheet);
  const Model& m = s.model;
  const float reach = touchDistance(m, m.pieces[0]);  // 0.028 m, vertices 0.04 m apart
  const Vec3 n = sheetNormal(m);
  const std::vector<Vec3>& x0 = m.clothRestPosition;
  uint32_t t = 0;
  while (m.triangles[t][0] != 60 && m.triangles[t][1] != 60 && m.triangles[t][2] != 60) ++t;
  const auto& f = m.triangles[t];
  const Vec3 onFace = 0.4f * x0[f[0]] + 0.3f * x0[f[1]] + 0.3f * x0[f[2]];
  const Vec3 drop = onFace + 0.9f * reach * n;
  int nearest = f[0];
  for (int v : f) {
    ASSERT_GT((x0[v] - drop).norm(), reach) << v;  // no vertex within reach
    if ((x0[v] - onFace).norm() < (x0[nearest] - onFace).norm()) nearest = v;
  }
  Particles& p = s.state.particles;
  const float mass = float(0.25 * waterCapacity(m.clothDryMass[60], m.pieces[0].garment.saturation));
  p.add(kWaterPhase, 1000, mass, 0.04f, drop, Vec3::Zero());
  p.add(kWaterPhase, 1001, mass, 0.04f, onFace + 1.1f * reach * n, Vec3::Zero());  // its surface out of reach
  WetStage stage;
  EXPECT_EQ(stage(m, s.state, 0.5), 0u);  // the vertices alone
  const std::vector<uint32_t> start{0, 1, 2}, triangles{t, t};
  stage.candidates = {start, triangles};
  EXPECT_EQ(stage(m, s.state, 0.5), 1u);
  ASSERT_EQ(p.size(), size_t(m.numCloth) + 1);
  EXPECT_EQ(p.id.back(), 1001u);
  for (int i = 0; i < m.numCloth; ++i) EXPECT_EQ(s.state.clothWater[size_t(i)], i == nearest ? double(mass) : 0.0) << i;

  // with an unlimited supply the drop vanishes into the fabric and wets that vertex
  Scene u = fromString(kSheet, {"cloth.0.saturation.supply=\"unlimited\""});
  u.state.particles.add(kWaterPhase, 1000, mass, 0.04f, drop, Vec3::Zero());
  WetStage unlimited;
  unlimited.candidates = {std::span<const uint32_t>(start).first(2), std::span<const uint32_t>(triangles).first(1)};
  EXPECT_EQ(unlimited(u.model, u.state, 0.5), 1u);
  EXPECT_EQ(u.state.particles.size(), size_t(u.model.numCloth));
  for (int i = 0; i < u.model.numCloth; ++i)
    EXPECT_EQ(std::isfinite(u.state.clothWetStart[size_t(i)]), i == nearest) << i;
}

// a drop heavier than a vertex holds soaks into the spot around it: the touched vertex fills, the
// rest goes into its mesh neighbours with room, nearest ring first, and nothing is lost; a drop the
// 256 vertices around it cannot hold stays a water particle
TEST(GarmentStage, AHeavyDropSpreadsOverTheVerticesAroundIt) {
  Scene s = fromString(kSheet);
  const Model& m = s.model;
  const Vec3 n = sheetNormal(m);
  Particles& p = s.state.particles;
  const double capacity = waterCapacity(m.clothDryMass[60], m.pieces[0].garment.saturation);
  p.add(kWaterPhase, 1000, float(3.5 * capacity), 0.04f, m.clothRestPosition[60] + 0.01f * n, Vec3::Zero());
  WetStage stage;
  EXPECT_EQ(stage(m, s.state, 0.5), 1u);
  const std::set<int> ring(m.vertexNeighbors.begin() + m.vertexNeighborStart[60],
                           m.vertexNeighbors.begin() + m.vertexNeighborStart[61]);
  double total = 0.0;
  int wetInRing = 0;
  for (int i = 0; i < m.numCloth; ++i) {
    const double w = s.state.clothWater[size_t(i)];
    total += w;
    EXPECT_LE(w, capacity * (1.0 + 1e-6)) << i;
    if (w > 0.0 && i != 60) EXPECT_TRUE(ring.count(i)) << "vertex " << i << " is not next to 60";
    if (w > 0.0 && ring.count(i)) ++wetInRing;
    EXPECT_EQ(std::isfinite(s.state.clothWetStart[size_t(i)]), w > 0.0) << i;
  }
  EXPECT_NEAR(s.state.clothWater[60], capacity, 1e-6 * capacity);
  EXPECT_EQ(wetInRing, 3);  // 2.5 vertices' worth
  EXPECT_NEAR(total, double(float(3.5 * capacity)), 1e-12);
  const float flood = float(300.0 * capacity);
  p.add(kWaterPhase, 1001, flood, 0.04f, m.clothRestPosition[20] + 0.01f * n, Vec3::Zero());
  EXPECT_EQ(stage(m, s.state, 0.75), 0u);
  EXPECT_EQ(p.size(), size_t(m.numCloth) + 1);
  EXPECT_FALSE(std::isfinite(s.state.clothWetStart[20]));
}

// with an unlimited supply and dropsVanish off a drop still wets but stays; with Shao's wetting on, a vertex is wet once it holds
// water, whatever touches it, and no drop is taken
TEST(GarmentStage, DropsThatStayAndShaoWettingDecideTheWetSignalOtherwise) {
  {
    Scene s = fromString(kSheet, {"cloth.0.saturation.supply=\"unlimited\"", "cloth.0.saturation.dropsVanish=false"});
    const Model& m = s.model;
    s.state.particles.add(kWaterPhase, 1000, m.water.particleMass, 0.04f,
                          m.clothRestPosition[60] + 0.01f * sheetNormal(m), Vec3::Zero());
    WetStage stage;
    EXPECT_EQ(stage(m, s.state, 1.0), 0u);
    EXPECT_EQ(s.state.clothWetStart[60], 1.0f);
    EXPECT_EQ(s.state.particles.size(), size_t(m.numCloth) + 1);
    EXPECT_EQ(s.state.ledger.takenByCloth, 0.0);
  }
  {
    Scene s = fromString(kSheet, {"wetting.enabled=true", "wetting.emission.massThreshold=1e-5"});
    const Model& m = s.model;
    s.state.particles.add(kWaterPhase, 1000, m.water.particleMass, 0.04f,
                          m.clothRestPosition[60] + 0.01f * sheetNormal(m), Vec3::Zero());
    s.state.clothWater[7] = 1e-7;
    WetStage stage;
    EXPECT_EQ(stage(m, s.state, 2.0), 0u);
    for (int i = 0; i < m.numCloth; ++i)
      EXPECT_EQ(std::isfinite(s.state.clothWetStart[size_t(i)]), i == 7) << i;
    EXPECT_EQ(s.state.clothWetStart[7], 2.0f);
    EXPECT_EQ(s.state.particles.size(), size_t(m.numCloth) + 1);
  }
}

// the "wetness" of the cloth PLY is each vertex's saturation s = Q / delta; with Shao's wetting on,
// S / S^MAX (at most 1); 0 for a piece not wetted by contact
TEST(GarmentStage, WetnessIsTheSaturation) {
  Scene s = fromString(kSheet);
  s.state.clothSaturation[4] = 0.25f;
  s.state.clothSaturation[5] = 1.0f;
  const std::vector<float> w = clothWetness(s.model, s.state);
  ASSERT_EQ(w.size(), size_t(s.model.numCloth));
  EXPECT_EQ(w[3], 0.0f);
  EXPECT_EQ(w[4], 0.25f);
  EXPECT_EQ(w[5], 1.0f);
  Model notWetted = s.model;
  notWetted.pieces[0].wetByContact = false;
  for (float v : clothWetness(notWetted, s.state)) EXPECT_EQ(v, 0.0f);
  Scene shao = fromString(kSheet, {"wetting.enabled=true", "wetting.emission.massThreshold=1e-5"});
  shao.state.clothSaturation[4] = 0.5f * shao.model.wetting.saturationMax;
  shao.state.clothSaturation[5] = 2.0f * shao.model.wetting.saturationMax;
  const std::vector<float> ws = clothWetness(shao.model, shao.state);
  EXPECT_NEAR(ws[4], 0.5f, 1e-6f);
  EXPECT_EQ(ws[5], 1.0f);
}

// a sheet solved implicitly next to a PBD sheet that gains saturation mass
const char* kTwoPieces = R"({
  "solver": {"dt": 0.01, "domain": {"min": [-1, 0, -1], "max": [1, 2, 1]}},
  "cloth": [{"name": "implicit", "solver": "implicit", "fabric": "cotton",
             "mesh": {"type": "rectangle", "center": [0, 1, 0], "size": [0.2, 0.2], "resolution": [5, 5]},
             "material": {"particleMass": 2e-4}, "pin": {"corners": [0, 1]}},
            {"name": "pbd", "fabric": "high_absorption", "saturation": {"enabled": true},
             "mesh": {"type": "rectangle", "center": [0, 0.5, 0], "size": [0.2, 0.2], "resolution": [4, 4]},
             "material": {"particleMass": 1e-3}}],
  "emitters": [{"type": "rain", "origin": [0, 1.3, 0], "halfExtents": [0.25, 0.25]}]
})";

// solveGarments: one implicit solve per implicit piece (counted), its result remembered in `solved`; a
// PBD piece with saturation mass (unlimited supply) gets m_dry (1 + Q) from its own wet times at the
// end of the step and is not moved
TEST(GarmentStage, SolveGarmentsSolvesImplicitPiecesAndWeighsPbdOnes) {
  Scene s = fromString(kTwoPieces, {"cloth.1.saturation.supply=\"unlimited\""});
  const Model& m = s.model;
  ASSERT_EQ(m.numCloth, 25 + 16);
  ASSERT_EQ(s.state.clothWetStart.size(), size_t(m.numCloth));
  Particles& p = s.state.particles;
  p.xPred = p.x;
  s.state.time = 3.0;
  s.state.clothWetStart[25] = 1.0f;  // the PBD piece's vertex 0, wet for 2 s
  const std::vector<Vec3> pbdBefore(p.xPred.begin() + 25, p.xPred.end());
  GarmentScratch gs;
  StepStats stats;
  std::vector<ColliderPose> poses;
  solveGarments(m, s.state, gs, poses, {}, 0.01f, stats);
  EXPECT_EQ(stats.garment.solves, 1u);
  EXPECT_EQ(stats.garment.halvedSteps, 0u);  // nothing near solver.maxSpeed
  EXPECT_GT(stats.garment.cgIterations, 0u);
  ASSERT_EQ(gs.solved.size(), size_t(m.numCloth));
  for (int i = 0; i < 25; ++i) EXPECT_EQ(gs.solved[size_t(i)], p.xPred[size_t(i)]) << i;
  EXPECT_LT(p.xPred[12].y(), p.x[12].y()) << "the implicit sheet falls under gravity";
  for (int i = 25; i < m.numCloth; ++i) EXPECT_EQ(p.xPred[size_t(i)], pbdBefore[size_t(i - 25)]) << i;
  const double q = 2.492 * (1.0 - std::exp(-2.01 / 3.3803));
  EXPECT_NEAR(p.mass[25], m.clothDryMass[25] * (1.0 + q), 1e-6 * p.mass[25]);
  EXPECT_EQ(p.mass[26], m.clothDryMass[26]);
}

// the water coupling's push on an implicit piece: with drops vanishing (no Shao wetting) it is undone (the
// drops do not push the garment); otherwise it becomes velocity, (x* - solved) / h. PBD cloth is left alone
TEST(GarmentStage, CouplingPushBecomesVelocityUnlessDropsVanish) {
  Scene s = fromString(kTwoPieces);
  Model& m = s.model;
  Particles& p = s.state.particles;
  p.xPred = p.x;
  GarmentScratch gs;
  gs.solved = p.xPred;
  const Vec3 push(0.001f, -0.002f, 0.0005f);
  for (Vec3& x : p.xPred) x += push;
  const std::vector<Vec3> v0 = p.v, pushed = p.xPred;
  const float h = 0.005f;
  addCouplingVelocity(m, p, gs, h);
  for (int i = 0; i < 25; ++i) {
    EXPECT_EQ(p.xPred[size_t(i)], gs.solved[size_t(i)]) << i;
    EXPECT_EQ(p.v[size_t(i)], v0[size_t(i)]) << i;
  }
  for (int i = 25; i < m.numCloth; ++i) EXPECT_EQ(p.xPred[size_t(i)], pushed[size_t(i)]) << "PBD cloth, " << i;
  m.pieces[0].dropsVanish = false;
  p.xPred = pushed;
  addCouplingVelocity(m, p, gs, h);
  for (int i = 0; i < 25; ++i) {
    EXPECT_EQ(p.xPred[size_t(i)], pushed[size_t(i)]) << i;
    EXPECT_LT((p.v[size_t(i)] - (v0[size_t(i)] + push / h)).norm(), 1e-4f) << i;
  }
  for (int i = 25; i < m.numCloth; ++i) EXPECT_EQ(p.v[size_t(i)], v0[size_t(i)]) << "PBD cloth, " << i;
}

// section 3.5: a procedural garment's panels are its wrinkle subdomains (one per panel, each holding
// exactly that panel's vertices); a plain sheet gets patches covering every vertex once
TEST(GarmentStage, GarmentPanelsAreTheWrinkleSubdomains) {
  const Scene s = fromString(R"({
    "colliders": [{"name": "body", "type": "mannequin", "pose": {"shoulderAbduction": [45, 45]}}],
    "cloth": [{"name": "shirt", "solver": "implicit", "mesh": {"type": "garment", "body": "body", "edgeLength": 0.05}}],
    "emitters": [{"type": "rain", "origin": [0, 2, 0], "halfExtents": [0.5, 0.3]}]})");
  const ClothPiece& piece = s.model.pieces[0];
  ASSERT_TRUE(piece.implicit);
  const std::vector<std::vector<int>>& sub = piece.implicit->subdomains;
  ASSERT_EQ(sub.size(), 4u);  // front, back, two sleeves
  size_t covered = 0;
  for (size_t k = 0; k < sub.size(); ++k) {
    for (int v : sub[k]) EXPECT_EQ(piece.panelOfVertex[size_t(v)], int(k)) << v;
    covered += sub[k].size();
  }
  EXPECT_EQ(covered, size_t(piece.particleCount));

  const Scene sheet = fromString(kSheet);
  std::set<int> seen;
  size_t total = 0;
  for (const std::vector<int>& patch : sheet.model.pieces[0].implicit->subdomains) {
    total += patch.size();
    seen.insert(patch.begin(), patch.end());
  }
  EXPECT_EQ(total, 121u);
  EXPECT_EQ(seen.size(), 121u);
}

// an implicit sheet hung by two corners, no water
const char* kHung = R"({
  "solver": {"dt": 0.01, "domain": {"min": [-1, 0, -1], "max": [1, 2, 1]}},
  "cloth": [{"name": "sheet", "solver": "implicit", "fabric": "cotton",
             "mesh": {"type": "rectangle", "center": [0, 1, 0], "size": [0.2, 0.2], "resolution": [5, 5]},
             "material": {"particleMass": 2e-4}, "pin": {"corners": [0, 1]}}]
})";

// A step that leaves a vertex faster than solver.maxSpeed is redone from its start as 2, 4, then 8
// steps: with maxSpeed 5 cm/s every try of the first step's fall from rest is too fast (about g h =
// 9.8 cm/s), so all three halvings run, and what is left is exactly 8 steps of h/8 chained from the
// start, the positions at the start kept for the commit
TEST(GarmentStage, AStepFasterThanMaxSpeedIsRedoneInSmallerSteps) {
  Scene s = fromString(kHung, {"solver.maxSpeed=0.05"});
  Scene ref = fromString(kHung, {"solver.maxSpeed=0.05"});
  const Model& m = s.model;
  Particles& p = s.state.particles;
  p.xPred = p.x;
  const std::vector<Vec3> x0 = p.x;
  GarmentScratch gs;
  StepStats stats;
  const std::vector<ColliderPose> poses;
  const float h = 0.01f;
  solveGarments(m, s.state, gs, poses, {}, h, stats);
  EXPECT_EQ(stats.garment.halvedSteps, unsigned(kMaxHalvings));
  EXPECT_EQ(stats.garment.solves, 8u);  // the steps kept
  EXPECT_EQ(p.x, x0);

  Particles& q = ref.state.particles;
  ImplicitScratch w;
  const ClothPiece& piece = ref.model.pieces[0];
  uint64_t iterations = 0;  // of the kept steps; the CG count has the dropped ones' too
  for (int part = 0; part < 8; ++part) {
    if (part > 0) q.x = q.xPred;
    iterations += garmentSubstep(ref.model, *piece.implicit, piece.garment, {}, h / 8, part * double(h / 8), 0, poses,
                                 q, w, {}).cgIterations;
  }
  EXPECT_GT(stats.garment.cgIterations, iterations);
  for (int i = 0; i < m.numCloth; ++i) {
    EXPECT_EQ(p.xPred[size_t(i)], q.xPred[size_t(i)]) << i;
    EXPECT_EQ(p.v[size_t(i)], q.v[size_t(i)]) << i;
  }
  EXPECT_GT(p.v[12].norm(), 0.05f);  // still too fast after the last halving: the run's check ends it
}

}  // namespace
}  // namespace soak
