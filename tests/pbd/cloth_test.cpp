// PBD cloth: the constraints of Eq. 8 and 9 (values and gradients), the XPBD solver on a hanging sheet
// (Shao 2017 section 3.2), determinism across thread counts, and self-collision.
#include "pbd/cloth.hpp"
#include "scene/cloth_piece.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

namespace soak {
namespace {

// the dihedral angle in double, as the reference for finite differences
double refAngle(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d) {
  const Vec3d e = b - a;
  const Vec3d n1 = e.cross(c - a), n2 = (d - a).cross(e);
  return std::atan2(n1.cross(n2).dot(e.normalized()), n1.dot(n2));
}

// a random hinge whose triangles are far from degenerate and whose angle is away from +-pi
bool randomHinge(std::mt19937& rng, Vec3 x[4]) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int k = 0; k < 4; ++k) x[k] = Vec3(u(rng), u(rng), u(rng));
  const Vec3 e = x[1] - x[0];
  const float l2 = e.squaredNorm();
  if (l2 < 0.1f) return false;
  const float h1 = e.cross(x[2] - x[0]).norm() / l2, h2 = e.cross(x[3] - x[0]).norm() / l2;
  if (h1 < 0.2f || h2 < 0.2f) return false;
  return std::abs(refAngle(x[0].cast<double>(), x[1].cast<double>(), x[2].cast<double>(), x[3].cast<double>())) < 2.8;
}

TEST(ClothConstraint, StretchValueAndGradientMatchFiniteDifferences) {
  for (unsigned seed : {1u, 2u, 3u, 4u, 5u}) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (int trial = 0; trial < 50; ++trial) {
      const Vec3 x1(u(rng), u(rng), u(rng)), x2(u(rng), u(rng), u(rng));
      if ((x1 - x2).norm() < 0.1f) continue;
      const float l0 = 0.5f * (u(rng) + 1.0f);
      Vec3 g1, g2;
      const float C = stretchConstraint(x1, x2, l0, g1, g2);
      EXPECT_NEAR(C, (x1 - x2).norm() - l0, 1e-6f);
      const double h = 1e-5;
      for (int k = 0; k < 3; ++k) {
        Vec3d p = x1.cast<double>(), m = x1.cast<double>();
        p[k] += h;
        m[k] -= h;
        const double fd1 = ((p - x2.cast<double>()).norm() - (m - x2.cast<double>()).norm()) / (2 * h);
        EXPECT_NEAR(g1[k], fd1, 1e-4) << "seed " << seed;
        p = x2.cast<double>();
        m = x2.cast<double>();
        p[k] += h;
        m[k] -= h;
        const double fd2 = ((x1.cast<double>() - p).norm() - (x1.cast<double>() - m).norm()) / (2 * h);
        EXPECT_NEAR(g2[k], fd2, 1e-4) << "seed " << seed;
      }
      EXPECT_NEAR(g1.norm(), 1.0f, 1e-6f);
    }
  }
}

TEST(ClothConstraint, BendGradientsMatchFiniteDifferences) {
  int tested = 0;
  for (unsigned seed : {11u, 12u, 13u, 14u, 15u, 16u}) {
    std::mt19937 rng(seed);
    for (int trial = 0; trial < 200; ++trial) {
      Vec3 x[4];
      if (!randomHinge(rng, x)) continue;
      ++tested;
      const float phi0 = 0.3f;
      Vec3 g[4];
      const float C = bendConstraint(x[0], x[1], x[2], x[3], phi0, g);
      Vec3d xd[4];
      for (int k = 0; k < 4; ++k) xd[k] = x[k].cast<double>();
      EXPECT_NEAR(C, refAngle(xd[0], xd[1], xd[2], xd[3]) - phi0, 1e-5) << "seed " << seed;
      float scale = 0.0f;
      for (int k = 0; k < 4; ++k) scale = std::max(scale, g[k].norm());
      const double h = 1e-6;
      for (int v = 0; v < 4; ++v) {
        Vec3d fd;
        for (int k = 0; k < 3; ++k) {
          Vec3d p[4], m[4];
          std::copy(xd, xd + 4, p);
          std::copy(xd, xd + 4, m);
          p[v][k] += h;
          m[v][k] -= h;
          fd[k] = (refAngle(p[0], p[1], p[2], p[3]) - refAngle(m[0], m[1], m[2], m[3])) / (2 * h);
        }
        EXPECT_LE((g[v].cast<double>() - fd).norm(), 1e-2 * std::max<double>(fd.norm(), scale))
            << "seed " << seed << " vertex " << v << " analytic " << g[v].transpose() << " fd " << fd.transpose();
      }
    }
  }
  EXPECT_GT(tested, 300);
}

TEST(ClothConstraint, BendGradientsAreTranslationAndRotationInvariant) {
  std::mt19937 rng(7);
  int tested = 0;
  for (int trial = 0; trial < 300; ++trial) {
    Vec3 x[4];
    if (!randomHinge(rng, x)) continue;
    ++tested;
    Vec3 g[4];
    bendConstraint(x[0], x[1], x[2], x[3], 0.0f, g);
    float scale = 0.0f;
    Vec3 sum = Vec3::Zero(), torque = Vec3::Zero();
    for (int k = 0; k < 4; ++k) {
      scale = std::max(scale, g[k].norm());
      sum += g[k];
      torque += x[k].cross(g[k]);
    }
    EXPECT_LT(sum.norm(), 1e-5f * scale);     // moving all four together leaves the angle
    EXPECT_LT(torque.norm(), 1e-4f * scale);  // so does turning them together
  }
  EXPECT_GT(tested, 50);
}

TEST(ClothConstraint, BendAngleIsZeroWhenFlatAndSignedByFoldDirection) {
  // edge a-b along x; c on +y, d on -y: both triangles have normal +z
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0.4f, 1, 0);
  Vec3 g[4];
  EXPECT_NEAR(bendConstraint(a, b, c, Vec3(0.6f, -1, 0), 0.0f, g), 0.0f, 1e-7f);
  // d lifted towards +z (the side of the normal) and lowered: equal and opposite angles
  const float t = 0.7f;
  const float up = bendConstraint(a, b, c, Vec3(0.6f, -std::cos(t), std::sin(t)), 0.0f, g);
  const float down = bendConstraint(a, b, c, Vec3(0.6f, -std::cos(t), -std::sin(t)), 0.0f, g);
  EXPECT_NEAR(up, -t, 1e-5f);
  EXPECT_NEAR(down, t, 1e-5f);
  // a right-angle fold, and |C| agrees with Eq. 9's acos of the normals' dot product
  const Vec3 d90(0.6f, 0, -1);
  const float right = bendConstraint(a, b, c, d90, 0.0f, g);
  EXPECT_NEAR(right, kPi / 2, 1e-5f);
  const Vec3 n1 = (b - a).cross(c - a).normalized(), n2 = (d90 - a).cross(b - a).normalized();
  EXPECT_NEAR(std::abs(right), std::acos(n1.dot(n2)), 1e-5f);
  // nearly closed (folded flat onto itself): finite, and the gradient of the wing is 1/height
  const float closed = bendConstraint(a, b, c, Vec3(0.6f, 0.999f, -0.01f), 0.0f, g);
  EXPECT_GT(std::abs(closed), 3.1f);
  EXPECT_NEAR(g[2].norm(), 1.0f, 1e-5f);
  // the short way round: rest 3.0 rad, now -3.0 rad is 2 pi - 6 away, not -6
  EXPECT_NEAR(bendConstraint(a, b, c, Vec3(0.6f, -std::cos(3.0f), std::sin(3.0f)), 3.0f, g), 2 * kPi - 6.0f, 1e-4f);
}

TEST(ClothConstraint, BendAngleMatchesLibmAtan2AllRoundTheEdge) {
  // the solver's polynomial atan2 against std::atan2 for folds in every octant, -pi to pi
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0.4f, 1, 0);
  Vec3 g[4];
  float worst = 0.0f;
  for (int k = -1000; k <= 1000; ++k) {
    const float t = 3.14f * static_cast<float>(k) / 1000.0f;
    const Vec3 d(0.6f, -std::cos(t), std::sin(t));
    const Vec3 n1 = (b - a).cross(c - a), n2 = (d - a).cross(b - a);
    const float exact = std::atan2(n1.cross(n2).dot(b - a), n1.dot(n2));
    worst = std::max(worst, std::abs(bendConstraint(a, b, c, d, 0.0f, g) - exact));
  }
  EXPECT_LT(worst, 2e-5f);
}

// a 0.5 m x 0.5 m horizontal sheet at 21 x 21, corners pinned, particles filled as the scene loader would
struct Sheet {
  Model model;
  Particles p;
  std::vector<int> pins;
};

Sheet makeSheet(int pinnedCorners, float stretchCompliance, float bendCompliance, int res = 21) {
  Sheet s;
  ClothMaterial mat;
  mat.stretchCompliance = stretchCompliance;
  mat.bendCompliance = bendCompliance;
  const TriangleMesh mesh = makeRectangle(Vec3(0, 1, 0), Vec3::UnitX(), Vec3::UnitZ(), 0.5f, 0.5f, res, res);
  s.pins = {0, res - 1};
  if (pinnedCorners == 4) s.pins.insert(s.pins.end(), {res * (res - 1), res * res - 1});
  addClothPiece(s.model, "sheet", mesh, mat, s.pins, "test");
  const int n = s.model.numCloth;
  for (int i = 0; i < n; ++i) {
    s.p.add(1, static_cast<uint32_t>(i), s.model.clothDryMass[i], 0.04f, s.model.clothRestPosition[i], Vec3::Zero());
    if (s.model.clothPinned[i]) s.p.invMass[i] = 0.0f;
  }
  return s;
}

// simple PBD substeps: predict, solve, velocity from the position change with a little damping
void simulate(Sheet& s, int substeps, float dt, int iterations, float keep) {
  ClothScratch scratch;
  const Vec3 g = s.model.solver.gravity;
  const int n = static_cast<int>(s.p.size());
  for (int step = 0; step < substeps; ++step) {
    for (int i = 0; i < n; ++i) {
      if (s.p.invMass[i] > 0.0f) s.p.v[i] += g * dt;
      s.p.xPred[i] = s.p.x[i] + s.p.v[i] * dt;
    }
    solveCloth(s.model, s.p, scratch, dt, iterations);
    for (int i = 0; i < n; ++i) {
      s.p.v[i] = (s.p.xPred[i] - s.p.x[i]) / dt * keep;
      s.p.x[i] = s.p.xPred[i];
    }
  }
}

float maxStrain(const Sheet& s) {
  float worst = 0.0f;
  for (size_t k = 0; k < s.model.stretch.ids.size(); ++k) {
    const auto [i, j] = s.model.stretch.ids[k];
    const float l0 = s.model.stretch.restLength[k];
    worst = std::max(worst, std::abs((s.p.x[i] - s.p.x[j]).norm() - l0) / l0);
  }
  return worst;
}

float maxSpeed(const Sheet& s) {
  float v = 0.0f;
  for (const Vec3& vi : s.p.v) v = std::max(v, vi.norm());
  return v;
}

TEST(ClothSolver, SheetPinnedAtFourCornersSagsInextensibleAndComesToRest) {
  // an inextensible sheet pinned at its corners can only sag by its residual strain, which PBD drives
  // down with small steps (Gauss-Seidel error grows like g dt^2 per step)
  Sheet s = makeSheet(4, 0.0f, 1.0f);
  simulate(s, 300, 1.0e-3f, 40, 0.98f);
  for (int pin : s.pins) EXPECT_EQ(s.p.x[pin], s.model.clothRestPosition[pin]);  // pinned never move
  EXPECT_LT(maxStrain(s), 0.01f);
  const float pinY = s.model.clothRestPosition[0].y();
  const float centreY = s.p.x[10 * 21 + 10].y();
  EXPECT_LT(centreY, pinY - 0.005f);
  EXPECT_GT(centreY, pinY - 0.05f);
  EXPECT_LT(maxSpeed(s), 0.05f);  // against about 0.3 m/s of free fall over the run
}

// one triangle hanging from its two pinned top vertices: with compliance alpha the two edges obey
// Hooke's law, l - l0 = alpha T (XPBD), whatever the iteration count or the step
TEST(ClothSolver, StretchComplianceIsHookesLawIndependentOfIterationsAndStep) {
  const float alpha = 0.2f;  // m/N
  ClothMaterial mat;
  mat.stretchCompliance = alpha;
  mat.particleMass = 0.0066f;  // Table 1's: the tension below is this weight's
  const TriangleMesh mesh{{Vec3(-0.1f, 0, 0), Vec3(0.1f, 0, 0), Vec3(0, -0.05f, 0)}, {{0, 2, 1}}};
  float drop[3];
  int run = 0;
  for (auto [iterations, dt] :
       {std::pair{2, 1.0f / 120.0f}, std::pair{20, 1.0f / 120.0f}, std::pair{4, 1.0f / 480.0f}}) {
    Sheet s;
    addClothPiece(s.model, "tri", mesh, mat, {0, 1}, "test");
    ASSERT_TRUE(s.model.bend.ids.empty());
    for (int i = 0; i < 3; ++i) {
      s.p.add(1, static_cast<uint32_t>(i), mat.particleMass, 0.04f, mesh.vertices[i], Vec3::Zero());
      if (i < 2) s.p.invMass[i] = 0.0f;
    }
    simulate(s, static_cast<int>(4.0f / dt), dt, iterations, 0.98f);
    const Vec3 x = s.p.x[2];
    EXPECT_NEAR(x.x(), 0.0f, 1e-4f);  // Gauss-Seidel order tilts it a little
    const float len = (x - mesh.vertices[0]).norm(), l0 = std::sqrt(0.0125f);
    const float tension = mat.particleMass * 9.81f * len / (2.0f * -x.y());  // vertical balance at the free vertex
    EXPECT_NEAR(len - l0, alpha * tension, 0.02f * alpha * tension) << iterations << " iterations, dt " << dt;
    EXPECT_GT(len - l0, 0.005f);  // a visible stretch, so the check above means something
    drop[run++] = x.y();
  }
  EXPECT_NEAR(drop[0], drop[1], 1e-4f);
  EXPECT_NEAR(drop[0], drop[2], 1e-4f);
}

TEST(ClothSolver, BitIdenticalOnOneTwoAndThreeThreads) {
  // 90 x 90 particles: 5 slabs, so the slabs and their interfaces really run on several threads
  // (three threads split them unevenly)
  const int before = omp_get_max_threads();
  std::vector<Vec3> result[3];
  for (int threads : {1, 2, 3}) {
    omp_set_num_threads(threads);
    Sheet s = makeSheet(2, 1e-7f, 0.1f, 90);
    ASSERT_EQ(s.model.stretch.schedule.numSlabs, 5);
    simulate(s, 20, 1.0f / 60.0f, 10, 0.99f);
    result[threads - 1] = s.p.x;
  }
  omp_set_num_threads(before);
  for (int k : {1, 2}) {
    ASSERT_EQ(result[0].size(), result[k].size());
    EXPECT_EQ(std::memcmp(result[0].data(), result[k].data(), result[0].size() * sizeof(Vec3)), 0) << k + 1 << " threads";
  }
  EXPECT_NE(result[0][4000], result[0][0]);  // the sheet did move
}

// every pair closer than h, by brute force (the grid is not under test here)
NeighborLists bruteNeighbors(const std::vector<Vec3>& x, float h) {
  NeighborLists nl;
  nl.start.push_back(0);
  for (size_t i = 0; i < x.size(); ++i) {
    for (size_t j = 0; j < x.size(); ++j)
      if (j != i && (x[i] - x[j]).norm() < h) nl.index.push_back(static_cast<uint32_t>(j));
    nl.start.push_back(static_cast<uint32_t>(nl.index.size()));
  }
  return nl;
}

bool ringNeighbors(const Model& m, int i, int j) {
  return std::binary_search(m.vertexNeighbors.begin() + m.vertexNeighborStart[i],
                            m.vertexNeighbors.begin() + m.vertexNeighborStart[i + 1], j);
}

// closest pair of one piece that self-collision must keep apart
float closestCollidingPair(const Model& m, const Particles& p, int first, int count) {
  float closest = 1e30f;
  const float d = m.pieces[0].material.thickness;
  for (int i = first; i < first + count; ++i)
    for (int j = i + 1; j < first + count; ++j)
      if (!ringNeighbors(m, i, j) && (m.clothRestPosition[i] - m.clothRestPosition[j]).norm() > d)
        closest = std::min(closest, (p.xPred[i] - p.xPred[j]).norm());
  return closest;
}

// a 21 x 21 sheet (thickness 1 cm, particle 9 x 21 held) folded onto itself along row 10: row 10 + k
// lies 3 mm above row 10 - k; and a second piece 4 mm under a corner of the lower layer (other pieces
// are not self-collision's business). Returns the particles; the model gets both pieces.
constexpr int kFoldRes = 21;
Particles foldedSheet(Model& model) {
  const int res = kFoldRes;
  ClothMaterial mat;
  mat.thickness = 0.01f;
  addClothPiece(model, "sheet", makeRectangle(Vec3(0, 1, 0), Vec3::UnitX(), Vec3::UnitZ(), 0.5f, 0.5f, res, res), mat,
                {9 * res}, "test");
  addClothPiece(model, "other",
                makeRectangle(Vec3(-0.225f, 0.996f, -0.225f), Vec3::UnitX(), Vec3::UnitZ(), 0.05f, 0.05f, 3, 3), mat,
                {}, "test");
  const int n = model.numCloth, n1 = res * res;
  Particles p;
  for (int i = 0; i < n; ++i) {
    Vec3 x = model.clothRestPosition[i];
    const int row = i / res;
    if (i < n1 && row > 10) x = model.clothRestPosition[(20 - row) * res + i % res] + Vec3(0, 0.003f, 0);
    p.add(i < n1 ? 1 : 2, static_cast<uint32_t>(i), model.clothDryMass[i], 0.04f, x, Vec3::Zero());
    if (model.clothPinned[i]) p.invMass[i] = 0.0f;
  }
  return p;
}

TEST(ClothSelfCollision, FoldedSheetLayersEndAThicknessApart) {
  const int res = kFoldRes;
  Model model;
  Particles p = foldedSheet(model);
  const ClothMaterial& mat = model.pieces[0].material;
  const int n = model.numCloth, n1 = res * res;
  const std::vector<Vec3> start = p.xPred;
  EXPECT_NEAR(closestCollidingPair(model, p, 0, n1), 0.003f, 1e-6f);
  const NeighborLists nl = bruteNeighbors(p.xPred, 0.04f);
  ClothScratch scratch;

  // switched off: nothing moves
  model.pieces[0].material.selfCollision = false;
  clothSelfCollision(model, p, nl, scratch);
  EXPECT_EQ(p.xPred, start);
  model.pieces[0].material.selfCollision = true;

  const int contacts = clothSelfCollision(model, p, nl, scratch);
  EXPECT_EQ(contacts, 2 * 10 * res - 1);  // each folded pair seen from both sides, but not from the pinned one
  for (int pass = 0; pass < 2; ++pass) clothSelfCollision(model, p, nl, scratch);

  EXPECT_GT(closestCollidingPair(model, p, 0, n1), 0.99f * mat.thickness);
  EXPECT_LT(closestCollidingPair(model, p, 0, n1), 1.01f * mat.thickness);  // pushed apart, not thrown
  // equal masses share the push; the pinned particle stays and its partner takes all of it
  EXPECT_NEAR(p.xPred[8 * res + 5].y() - start[8 * res + 5].y(), -0.0035f, 1e-5f);
  EXPECT_NEAR(p.xPred[12 * res + 5].y() - start[12 * res + 5].y(), 0.0035f, 1e-5f);
  EXPECT_EQ(p.xPred[9 * res], start[9 * res]);
  EXPECT_NEAR(p.xPred[11 * res].y() - start[11 * res].y(), 0.007f, 1e-5f);
  // the fold row has only mesh neighbours near it, and the other piece is left where it was
  for (int i = 0; i < res; ++i) EXPECT_EQ(p.xPred[10 * res + i], start[10 * res + i]);
  for (int i = n1; i < n; ++i) EXPECT_EQ(p.xPred[i], start[i]);
}

TEST(ClothSelfCollision, LeavesMeshNeighboursAndPairsCloseAtRestAlone) {
  ClothMaterial mat;
  mat.thickness = 0.01f;
  // spacing 5 mm < thickness 10 mm, shrunk by 5 %: pairs two apart come to 9.5 mm but were only 10 mm
  // apart at rest, so they are the stretch constraints' business, not a collision
  Model fine;
  addClothPiece(fine, "fine", makeRectangle(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 0.02f, 0.02f, 5, 5), mat, {},
                "test");
  Particles p;
  for (int i = 0; i < fine.numCloth; ++i)
    p.add(1, static_cast<uint32_t>(i), fine.clothDryMass[i], 0.04f, 0.95f * fine.clothRestPosition[i], Vec3::Zero());
  std::vector<Vec3> start = p.xPred;
  ClothScratch scratch;
  clothSelfCollision(fine, p, bruteNeighbors(p.xPred, 0.04f), scratch);
  EXPECT_EQ(p.xPred, start);

  // spacing 25 mm: an edge squeezed to 1 mm is left alone (mesh neighbours), while a corner brought
  // 4 mm over the opposite corner is pushed a thickness off it
  Model coarse;
  addClothPiece(coarse, "coarse", makeRectangle(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 0.1f, 0.1f, 5, 5), mat, {},
                "test");
  Particles q;
  for (int i = 0; i < coarse.numCloth; ++i)
    q.add(1, static_cast<uint32_t>(i), coarse.clothDryMass[i], 0.04f, coarse.clothRestPosition[i], Vec3::Zero());
  q.xPred[13] = q.xPred[12] + Vec3(0.001f, 0, 0);
  q.xPred[24] = q.xPred[0] + Vec3(0, 0, 0.004f);
  start = q.xPred;
  EXPECT_EQ(clothSelfCollision(coarse, q, bruteNeighbors(q.xPred, 0.04f), scratch), 2);  // 0 and 24, not 12 and 13
  EXPECT_EQ(q.xPred[12], start[12]);
  EXPECT_EQ(q.xPred[13], start[13]);
  EXPECT_NEAR((q.xPred[24] - q.xPred[0]).norm(), 0.01f, 1e-6f);
  EXPECT_NEAR(q.xPred[24].z(), 0.007f, 1e-6f);
}

TEST(ClothSelfCollision, TheSmallStepsPushTheNearPairsAsTheFullPassDoes) {
  // the pairs found within 1.25 thicknesses (still particles) at a substep's start
  // (findSelfCollisionPairs) and pushed in each small step (collideSelfCollisionPairs) give what the
  // pass over every neighbour gives
  const int res = kFoldRes;
  Model model;
  Particles p = foldedSheet(model);
  const float d = model.pieces[0].material.thickness;
  const int n1 = res * res;
  const NeighborLists nl = bruteNeighbors(p.xPred, 0.04f);
  p.xPred[13 * res + 7].y() += 0.008f;  // 11 mm over its mirror: a candidate, not pushed
  p.xPred[14 * res + 7].y() += 0.012f;  // 15 mm: not even a candidate while the two stand still
  ClothScratch scratch;
  findSelfCollisionPairs(model, p, nl, 0.0075f, scratch);
  // every pair of the sheet (not 1-ring, apart by more than d at rest, one end free) within 1.25 d, each side
  int expected = 0;
  for (int i = 0; i < n1; ++i)
    for (int j = 0; j < n1; ++j)
      if (i != j && p.invMass[i] > 0.0f && !ringNeighbors(model, i, j) && (p.xPred[i] - p.xPred[j]).norm() < 1.25f * d &&
          (model.clothRestPosition[i] - model.clothRestPosition[j]).norm() > d)
        ++expected;
  EXPECT_EQ(scratch.pairCount[model.numCloth], expected);
  EXPECT_EQ(expected, 2 * 10 * res - 3);  // each particle over its mirror, both sides, not from the held one, not the 15 mm pair
  // one of them moving at 1 m/s against the other (either way: the reach takes the relative speed, not
  // its direction): a candidate
  p.v[14 * res + 7] = Vec3(0, 1, 0);
  ClothScratch moving;
  findSelfCollisionPairs(model, p, nl, 0.0075f, moving);
  EXPECT_EQ(moving.pairCount[model.numCloth], expected + 2);
  p.v[14 * res + 7] = Vec3::Zero();
  Particles full = p;
  ClothScratch fullScratch;
  const int pushed = collideSelfCollisionPairs(model, p, scratch);
  EXPECT_EQ(pushed, clothSelfCollision(model, full, nl, fullScratch));
  EXPECT_EQ(pushed, 2 * 10 * res - 5);  // the lifted ones' pairs are no longer within d
  EXPECT_EQ(p.xPred, full.xPred);

  // in a substep of 4 small steps without gravity the fold opens to the thickness within the substep
  Model stepped;
  Particles q = foldedSheet(stepped);
  stepped.solver.gravity = Vec3::Zero();
  stepped.solver.clothSubsteps = 4;
  stepped.solver.clothIterations = 1;
  buildClothConstraints(stepped);
  const NeighborLists ql = bruteNeighbors(q.xPred, 0.04f);
  ClothScratch qs;
  stepCloth(stepped, q, ql, qs, 0.0075f);
  EXPECT_GT(closestCollidingPair(stepped, q, 0, n1), 0.95f * d);
}

}  // namespace
}  // namespace soak
