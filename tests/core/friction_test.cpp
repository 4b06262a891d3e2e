#include "core/friction.hpp"

#include <gtest/gtest.h>

namespace soak {
namespace {

TEST(Friction, CoulombHoldsBelowTheConeAndSlidesAbove) {
  const Vec3 n(0, 1, 0);
  // normal velocity change 1 m/s, mu 0.5: up to 0.5 m/s of slip is stopped
  const Vec3 held = coulombFriction(Vec3(0.4f, 0.0f, 0.2f), n, 0.5f, 1.0f);
  EXPECT_LT(held.norm(), 1e-7f);
  const Vec3 slid = coulombFriction(Vec3(2.0f, 0.0f, 0.0f), n, 0.5f, 1.0f);
  EXPECT_NEAR(slid.x(), 1.5f, 1e-6f);
  EXPECT_NEAR(slid.y(), 0.0f, 1e-7f);
  const Vec3 keepsNormal = coulombFriction(Vec3(2.0f, 0.3f, 0.0f), n, 0.5f, 1.0f);
  EXPECT_NEAR(keepsNormal.y(), 0.3f, 1e-6f);
  EXPECT_NEAR(keepsNormal.x(), 1.5f, 1e-6f);
  EXPECT_FLOAT_EQ(mixFriction(0.36f, 0.25f), 0.3f);
  EXPECT_EQ(mixFriction(0.6f, 0.0f), 0.0f);
}

// at the edge of the cone (slip speed equal to mu times the normal velocity change) the contact holds; a
// sliding contact keeps the direction of its slip; a negative normal change or mu = 0 removes nothing
TEST(Friction, CoulombAtTheConeEdgeKeepsDirectionAndIgnoresPulls) {
  const Vec3 n = Vec3(1, 2, 2) / 3.0f;
  const Vec3 t1 = Vec3(2, -1, 0).normalized();
  const Vec3 edge = coulombFriction(0.5f * t1 + 0.2f * n, n, 0.25f, 2.0f);  // speed 0.5 = budget 0.5
  EXPECT_LT((edge - 0.2f * n).norm(), 1e-6f);
  const Vec3 slid = coulombFriction(1.5f * t1 - 0.1f * n, n, 0.25f, 2.0f);
  EXPECT_LT((slid - (1.0f * t1 - 0.1f * n)).norm(), 1e-6f);  // 1.5 - 0.5 along the same direction
  const Vec3 v = 0.8f * t1 + 0.3f * n;
  EXPECT_LT((coulombFriction(v, n, 0.5f, -3.0f) - v).norm(), 1e-7f);
  EXPECT_LT((coulombFriction(v, n, 0.0f, 3.0f) - v).norm(), 1e-7f);
  // mixing is symmetric, sqrt(a b), and a negative coefficient counts as 0
  EXPECT_FLOAT_EQ(mixFriction(0.25f, 0.64f), 0.4f);
  EXPECT_EQ(mixFriction(0.64f, 0.25f), mixFriction(0.25f, 0.64f));
  EXPECT_EQ(mixFriction(-0.5f, 0.5f), 0.0f);
}

// static and kinetic coefficients: a slip within mu_s times the push stops; a larger one loses mu_k
// times the push, not mu_s times
TEST(Friction, StaticHoldsUpToMuStaticAndKineticRemovesMuKinetic) {
  const Vec3 n(0, 0, 1);
  const FrictionCoefficients mu{0.6f, 0.4f};
  EXPECT_LT(coulombFriction(Vec3(0.59f, 0.0f, 0.1f), n, mu, 1.0f).head<2>().norm(), 1e-7f);
  const Vec3 slid = coulombFriction(Vec3(0.0f, 0.61f, 0.1f), n, mu, 1.0f);
  EXPECT_NEAR(slid.y(), 0.21f, 1e-6f);
  EXPECT_NEAR(slid.z(), 0.1f, 1e-7f);
  const FrictionCoefficients mixed = mixFriction(FrictionCoefficients{0.36f, 0.25f}, FrictionCoefficients{1.0f, 0.04f});
  EXPECT_FLOAT_EQ(mixed.staticCoef, 0.6f);
  EXPECT_FLOAT_EQ(mixed.kinetic, 0.1f);
}

}  // namespace
}  // namespace soak
