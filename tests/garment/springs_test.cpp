// KES spring laws (Chen 2012 Eq. 11-14) and the spring sets built from a triangle mesh
#include "garment/springs.hpp"

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "world/mesh.hpp"

namespace soak {
namespace {

TEST(GarmentSprings, KesStretchDerivativeMatchesFiniteDifferences) {
  const KesLaw law{800.0f, 3.0f};
  const float limit = 0.9f;
  // below the limit (|eps| < 0.3) and on the tangent continuation beyond it
  for (float eps : {-0.5f, -0.28f, -0.1f, -0.01f, 0.0f, 0.004f, 0.05f, 0.15f, 0.25f, 0.29f, 0.31f, 0.6f}) {
    float d = 0.0f;
    kesStretchStress(eps, law, limit, &d);
    const float h = 1e-4f;
    float dp, dm;
    const double fd = (double(kesStretchStress(eps + h, law, limit, &dp)) - kesStretchStress(eps - h, law, limit, &dm)) /
                      (2.0 * h);
    EXPECT_NEAR(d, fd, 2e-3 * std::abs(fd) + 1e-3) << "eps " << eps;
    // Eq. 13 in closed form where Eq. 11 holds
    const double a = std::abs(eps);
    if (a * law.a2 < limit) {
      const double eq13 = law.a1 * (1.0 + 2.0 * law.a2 * a) / std::pow(1.0 - law.a2 * a, 4.0);
      EXPECT_NEAR(d, eq13, 1e-5 * eq13) << "eps " << eps;
      const double eq11 = law.a1 * eps / std::pow(1.0 - law.a2 * a, 3.0);
      EXPECT_NEAR(kesStretchStress(eps, law, limit, nullptr), eq11, 1e-5 * std::abs(eq11));
    }
  }
  // a2 = 0 is Hooke's law
  EXPECT_FLOAT_EQ(kesStretchStress(0.2f, KesLaw{500.0f, 0.0f}, limit, nullptr), 100.0f);
}

TEST(GarmentSprings, EnergyDensitiesIntegrateTheStress) {
  const KesLaw stretch{800.0f, 3.0f}, bend{20.0f, 50.0f};
  for (double eps : {-0.45, -0.2, -0.05, 0.02, 0.1, 0.29, 0.5}) {
    const double h = 1e-5;
    const double fd = (kesStretchEnergy(eps + h, stretch, 0.9f) - kesStretchEnergy(eps - h, stretch, 0.9f)) / (2 * h);
    const double sigma = kesStretchStress(static_cast<float>(eps), stretch, 0.9f, nullptr);
    EXPECT_NEAR(fd, sigma, 1e-4 * std::abs(sigma) + 1e-3) << "eps " << eps;
    const double fdb = (kesBendEnergy(eps + h, bend) - kesBendEnergy(eps - h, bend)) / (2 * h);
    EXPECT_NEAR(fdb, kesBendStress(static_cast<float>(eps), bend, nullptr), 1e-5) << "eps " << eps;
  }
  EXPECT_FLOAT_EQ(kesBendStress(-0.1f, bend, nullptr), 20.0f * -0.1f + 50.0f * -0.1f * 0.1f);  // Eq. 14
}

// a single spring along x from 0 to a stretched length: f on i points to j, K matches -df_i/dx_i
TEST(GarmentSprings, SpringForceAndJacobianMatchFiniteDifferences) {
  SpringSet one = buildSprings({Vec3(0, 0, 0), Vec3(0.1f, 0, 0), Vec3(0, 0.1f, 0)}, {{0, 1, 2}});
  ASSERT_EQ(one.kindStart[1], 3);
  SpringLaws laws;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.02f, 0.02f);
  const int s = 0;  // (0, 1), l0 = 0.1
  for (int trial = 0; trial < 20; ++trial) {
    const Vec3 xi = Vec3(u(rng), u(rng), u(rng)) * 0.2f;
    const Vec3 xj = Vec3(0.115f, 0.0f, 0.0f) + Vec3(u(rng), u(rng), u(rng)) * 0.2f;  // stretched
    Vec3d fi;
    Eigen::Matrix3d K;
    const float eps = springForce(one, laws, s, xi, xj, fi, &K);
    EXPECT_GT(eps, 0.0f);
    EXPECT_GT(fi.dot((xj - xi).cast<double>()), 0.0);  // tension pulls i towards j
    const float h = 1e-5f;
    for (int k = 0; k < 3; ++k) {
      Vec3 p = xi, m = xi;
      p[k] += h;
      m[k] -= h;
      Vec3d fp, fm;
      springForce(one, laws, s, p, xj, fp, nullptr);
      springForce(one, laws, s, m, xj, fm, nullptr);
      const Vec3d col = -(fp - fm) / (2.0 * h);  // -df_i/dx_i, column k
      for (int r = 0; r < 3; ++r) EXPECT_NEAR(K(r, k), col[r], 2e-3 * K.norm()) << "trial " << trial;
    }
    EXPECT_NEAR((K - K.transpose()).norm(), 0.0, 1e-9 * K.norm());
  }
  // compressed: the transverse term is dropped, K stays positive semi-definite
  Vec3d fi;
  Eigen::Matrix3d K;
  springForce(one, laws, s, Vec3::Zero(), Vec3(0.08f, 0.01f, 0.0f), fi, &K);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(K);
  EXPECT_GE(es.eigenvalues().minCoeff(), -1e-9);
}

std::set<std::pair<int, int>> pairsOf(const SpringSet& s, SpringKind k) {
  std::set<std::pair<int, int>> out;
  for (int i = 0; i < s.size(); ++i)
    if (s.kind(i) == k) out.insert({s.ids[i][0], s.ids[i][1]});
  return out;
}

// 3 x 3 vertices, checkerboard diagonals all meeting at the centre (hand-counted in docs/garment.md)
TEST(GarmentSprings, GridSpringsMatchHandCount) {
  const TriangleMesh mesh = makeRectangle(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 0.2f, 0.2f, 3, 3);
  const SpringSet s = buildSprings(mesh.vertices, mesh.triangles);
  EXPECT_EQ(pairsOf(s, SpringKind::Stretch).size(), 16u);
  const std::set<std::pair<int, int>> shear{{1, 3}, {1, 5}, {3, 7}, {5, 7}};
  const std::set<std::pair<int, int>> bend{{0, 2}, {3, 5}, {6, 8}, {0, 6}, {1, 7}, {2, 8}, {0, 8}, {2, 6}};
  EXPECT_EQ(pairsOf(s, SpringKind::Shear), shear);
  EXPECT_EQ(pairsOf(s, SpringKind::Bend), bend);
  EXPECT_EQ(s.size(), 28);
  // stretch springs share out the sheet's area: sum L0 l0 = 0.04 m^2
  double area = 0.0;
  for (int i = 0; i < s.kindStart[1]; ++i) area += double(s.width[i]) * s.restLength[i];
  EXPECT_NEAR(area, 0.04, 1e-6);
  for (int i = 0; i < s.size(); ++i) EXPECT_NEAR(s.restLength[i], (mesh.vertices[s.ids[i][1]] - mesh.vertices[s.ids[i][0]]).norm(), 1e-7);
  // the vertex CSR lists each spring at both ends
  for (int v = 0; v < 9; ++v)
    for (int k = s.vertexStart[v]; k < s.vertexStart[v + 1]; ++k) {
      const auto& id = s.ids[s.vertexSpring[k]];
      EXPECT_TRUE(id[0] == v || id[1] == v);
    }
  EXPECT_EQ(s.vertexStart[9], 2 * s.size());
}

TEST(GarmentSprings, RestShapeHasNoForceAndNoEnergy) {
  const TriangleMesh mesh = makeRectangle(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), 0.5f, 0.4f, 6, 5);
  const SpringSet s = buildSprings(mesh.vertices, mesh.triangles);
  SpringLaws laws;
  EXPECT_NEAR(elasticEnergy(s, laws, mesh.vertices.data()), 0.0, 1e-12);
  for (int i = 0; i < s.size(); ++i) {
    Vec3d f;
    springForce(s, laws, i, mesh.vertices[s.ids[i][0]], mesh.vertices[s.ids[i][1]], f, nullptr);
    EXPECT_LT(f.norm(), 1e-3);
  }
}

}  // namespace
}  // namespace soak
