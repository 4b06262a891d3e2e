// seam springs of sewn garments (garment/springs.hpp seamForce, implicit.hpp SeamParams): the pull and
// its Jacobian, where the seams go in the spring set, and the closing over closeTime
#include "garment/implicit.hpp"
#include "garment/springs.hpp"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <random>

#include "scene/cloth_piece.hpp"

namespace soak {
namespace {

TEST(GarmentSeams, PullAndJacobianMatchFiniteDifferences) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-0.05f, 0.05f);
  for (const float rest : {0.0f, 0.03f}) {
    for (int trial = 0; trial < 10; ++trial) {
      const Vec3 xi(u(rng), u(rng), u(rng)), xj = Vec3(0.1f, 0.0f, 0.0f) + Vec3(u(rng), u(rng), u(rng));
      Vec3d fi;
      Eigen::Matrix3d K;
      seamForce(1500.0f, rest, xi, xj, fi, &K);
      const double l = double((xj - xi).norm());
      EXPECT_NEAR(fi.norm(), 1500.0 * std::abs(l - rest), 1e-6 * fi.norm());
      EXPECT_GT(fi.dot((xj - xi).cast<double>()), 0.0);  // a gap longer than the rest length pulls i to j
      const float h = 1e-4f;
      for (int k = 0; k < 3; ++k) {
        Vec3 p = xi, m = xi;
        p[k] += h;
        m[k] -= h;
        Vec3d fp, fm;
        seamForce(1500.0f, rest, p, xj, fp, nullptr);
        seamForce(1500.0f, rest, m, xj, fm, nullptr);
        const Vec3d col = -(fp - fm) / (2.0 * h);  // -df_i/dx_i, column k
        for (int r = 0; r < 3; ++r) EXPECT_NEAR(K(r, k), col[r], 2e-3 * K.norm()) << "rest " << rest;
      }
    }
  }
  Vec3d fi;
  Eigen::Matrix3d K;
  seamForce(1500.0f, 0.0f, Vec3::Zero(), Vec3::Zero(), fi, &K);  // closed: no force, isotropic stiffness
  EXPECT_EQ(fi.norm(), 0.0);
  EXPECT_NEAR((K - 1500.0 * Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-9);
}

TEST(GarmentSeams, SeamsFollowTheMeshSpringsOnce) {
  // two triangles 0.2 m apart; seam (1, 3) twice, (0, 1) is an edge already
  const std::vector<Vec3> rest = {Vec3(0, 0, 0), Vec3(0.1f, 0, 0), Vec3(0, 0.1f, 0), Vec3(0.3f, 0, 0),
                                  Vec3(0.4f, 0, 0), Vec3(0.3f, 0.1f, 0)};
  const SpringSet s = buildSprings(rest, {{0, 1, 2}, {3, 4, 5}}, {}, {{3, 1}, {1, 3}, {0, 1}, {2, 5}});
  ASSERT_EQ(s.kindStart[3], 6);  // the two triangles' edges
  ASSERT_EQ(s.kindStart[4], 8);
  EXPECT_EQ(s.kind(6), SpringKind::Seam);
  EXPECT_EQ(s.ids[6], (std::array<int, 2>{1, 3}));
  EXPECT_NEAR(s.restLength[6], 0.2f, 1e-6f);   // the starting gap
  EXPECT_NEAR(s.restLength[7], 0.3f, 1e-6f);
  // closed seams hold energy 1/2 k l^2
  const SpringLaws laws;
  EXPECT_NEAR(elasticEnergy(s, laws, rest.data()), 0.5 * laws.seamStiffness * (0.04 + 0.09), 1e-3);
}

// two 0.2 m squares side by side in a vertical plane, 0.2 m apart, their facing sides sewn together
struct SewnRig {
  Model model;
  Particles p;
  GarmentParams params;
  GarmentPiece g;
  ImplicitScratch scratch;
  std::vector<int> left, right;  // the sewn columns
};

void makeSewnRig(SewnRig& r) {
  TriangleMesh a = makeRectangle(Vec3(-0.2f, 1, 0), Vec3::UnitX(), Vec3::UnitY(), 0.2f, 0.2f, 6, 6);
  const TriangleMesh b = makeRectangle(Vec3(0.2f, 1, 0), Vec3::UnitX(), Vec3::UnitY(), 0.2f, 0.2f, 6, 6);
  const int n = static_cast<int>(a.vertices.size());
  for (const Vec3& x : b.vertices) a.vertices.push_back(x);
  for (const auto& t : b.triangles) a.triangles.push_back({t[0] + n, t[1] + n, t[2] + n});
  for (int i = 0; i < 2 * n; ++i) {
    if (i < n && a.vertices[i].x() > -0.1001f) r.left.push_back(i);
    if (i >= n && a.vertices[i].x() < 0.1001f) r.right.push_back(i);
  }
  addClothPiece(r.model, "pair", a, ClothMaterial{}, {}, "<test>", ClothSolver::Implicit);
  r.model.pieces[0].seams.clear();
  for (size_t k = 0; k < r.left.size(); ++k) r.model.pieces[0].seams.push_back({r.left[k], r.right[k]});
  for (int i = 0; i < r.model.numCloth; ++i)
    r.p.add(1, uint32_t(i), r.model.clothDryMass[i], 0.04f, r.model.clothRestPosition[i], Vec3::Zero());
  r.params.seams.closeTime = 0.5f;
  r.g = buildGarmentPiece(r.model, 0, r.params);
}

double meanGap(const SewnRig& r) {
  double gap = 0.0;
  for (size_t k = 0; k < r.left.size(); ++k) gap += (r.p.x[r.right[k]] - r.p.x[r.left[k]]).norm();
  return gap / r.left.size();
}

double meanY(const SewnRig& r) {
  double y = 0.0;
  for (const Vec3& x : r.p.x) y += x.y();
  return y / r.p.x.size();
}

void stepSewn(SewnRig& r, int steps, double& t, float h) {
  for (int k = 0; k < steps; ++k, t += h) {
    implicitStep(r.model, r.g, r.params, h, t, {}, {}, {}, r.p, r.scratch);
    r.p.x = r.p.xPred;
  }
}

TEST(GarmentSeams, SeamsCloseOverTheCloseTimeBeforeGravityActs) {
  SewnRig r;
  makeSewnRig(r);
  const float h = 1.0f / 120.0f;
  double t = 0.0;
  EXPECT_NEAR(meanGap(r), 0.2, 1e-6);
  // the gap follows the rest length 0.2 (1 - t / 0.5) m a step or two behind (measured 5 mm at half way)
  stepSewn(r, 15, t, h);  // a quarter of the way
  EXPECT_NEAR(meanGap(r), 0.15, 0.008);
  EXPECT_NEAR(meanY(r), 1.0, 1e-4);  // no gravity while sewing
  stepSewn(r, 15, t, h);
  EXPECT_NEAR(meanGap(r), 0.1, 0.008);
  stepSewn(r, 84, t, h);  // 0.2 s after closing
  EXPECT_LT(meanGap(r), 0.002);
  EXPECT_LT(meanY(r), 1.0 - 0.5 * 9.81 * 0.2 * 0.2 * 0.9);  // falling freely since closeTime
}

TEST(GarmentSeams, GravityWhileClosingWhenAsked) {
  SewnRig r;
  makeSewnRig(r);
  r.params.seams.gravityWhileClosing = true;
  const float h = 1.0f / 120.0f;
  double t = 0.0;
  stepSewn(r, 24, t, h);  // 0.2 s
  EXPECT_NEAR(meanY(r), 1.0 - 0.5 * 9.81 * 0.2 * 0.2, 0.02);
}

}  // namespace
}  // namespace soak
