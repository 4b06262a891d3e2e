// colliders: exact signed distances and normals of each shape, keyframed poses and their velocities
#include "world/colliders.hpp"

#include "support/colliders.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace soak {
namespace {

using testing::expectVec;
using testing::makeCollider;

ColliderPose staticPose(const Vec3& t = Vec3::Zero(), const Quat& q = Quat::Identity()) {
  ColliderPose pose;
  pose.translation = t;
  pose.rotation = q;
  return pose;
}

Quat aroundAxis(float angle, const Vec3& axis) { return Quat(Eigen::AngleAxisf(angle, axis.normalized())); }

float dist(const Collider& c, const ColliderPose& pose, const Vec3& p, Vec3* n = nullptr) {
  Vec3 tmp;
  return colliderDistance(c, pose, p, n ? n : &tmp);
}

TEST(ColliderDistance, PlaneIsHeightAboveTheRotatedMovedPlane) {
  const Collider c = makeCollider(ColliderShape::Plane);
  Vec3 n;
  EXPECT_NEAR(dist(c, staticPose(), Vec3(1, 0.3f, 2), &n), 0.3f, 1e-6f);
  expectVec(n, Vec3(0, 1, 0), 1e-6f);
  EXPECT_NEAR(dist(c, staticPose(), Vec3(-4, -0.2f, 7), &n), -0.2f, 1e-6f);
  // rotating +90 deg about z maps local +y to world -x; the plane then faces -x through x = 1
  const ColliderPose pose = staticPose(Vec3(1, 0, 0), aroundAxis(kPi / 2, Vec3::UnitZ()));
  EXPECT_NEAR(dist(c, pose, Vec3(0.5f, 3, -2), &n), 0.5f, 1e-6f);
  expectVec(n, Vec3(-1, 0, 0), 1e-6f);
  EXPECT_NEAR(dist(c, pose, Vec3(1.25f, 0, 0), &n), -0.25f, 1e-6f);
}

TEST(ColliderDistance, SphereInsideOutsideAndCentre) {
  Collider c = makeCollider(ColliderShape::Sphere);
  c.radius = 0.5f;
  const ColliderPose pose = staticPose(Vec3(1, 0, 0));
  Vec3 n;
  EXPECT_NEAR(dist(c, pose, Vec3(1, 2, 0), &n), 1.5f, 1e-6f);
  expectVec(n, Vec3(0, 1, 0), 1e-6f);
  EXPECT_NEAR(dist(c, pose, Vec3(1.2f, 0, 0), &n), -0.3f, 1e-6f);
  expectVec(n, Vec3(1, 0, 0), 1e-6f);
  EXPECT_NEAR(dist(c, pose, Vec3(1.3f, 0.4f, 0), &n), 0.0f, 1e-6f);
  expectVec(n, Vec3(0.6f, 0.8f, 0), 1e-6f);
  // the centre is degenerate: still a unit normal, never NaN
  EXPECT_NEAR(dist(c, pose, Vec3(1, 0, 0), &n), -0.5f, 1e-6f);
  EXPECT_TRUE(n.allFinite());
  EXPECT_NEAR(n.norm(), 1.0f, 1e-6f);
}

TEST(ColliderDistance, CapsuleSideCapsAndAxis) {
  Collider c = makeCollider(ColliderShape::Capsule);
  c.halfHeight = 0.5f;
  c.radius = 0.2f;
  Vec3 n;
  // beside the segment: radial distance minus radius
  EXPECT_NEAR(dist(c, staticPose(), Vec3(0.5f, 0.3f, 0), &n), 0.3f, 1e-6f);
  expectVec(n, Vec3(1, 0, 0), 1e-6f);
  // above the top cap on the axis
  EXPECT_NEAR(dist(c, staticPose(), Vec3(0, 1.0f, 0), &n), 0.3f, 1e-6f);
  expectVec(n, Vec3(0, 1, 0), 1e-6f);
  // diagonal beyond the bottom end point (0, -0.5, 0)
  EXPECT_NEAR(dist(c, staticPose(), Vec3(0, -0.9f, -0.3f), &n), 0.3f, 1e-6f);
  expectVec(n, Vec3(0, -0.8f, -0.6f), 1e-6f);
  // inside, off axis
  EXPECT_NEAR(dist(c, staticPose(), Vec3(0, 0.2f, 0.05f), &n), -0.15f, 1e-6f);
  expectVec(n, Vec3(0, 0, 1), 1e-6f);
  // on the axis: deepest point, unit normal orthogonal to the axis
  EXPECT_NEAR(dist(c, staticPose(), Vec3(0, 0.1f, 0), &n), -0.2f, 1e-6f);
  EXPECT_TRUE(n.allFinite());
  EXPECT_NEAR(n.norm(), 1.0f, 1e-6f);
  EXPECT_NEAR(n.y(), 0.0f, 1e-6f);
  // lying along world x (rotated -90 deg about z) and moved to (0, 1, 0)
  const ColliderPose pose = staticPose(Vec3(0, 1, 0), aroundAxis(-kPi / 2, Vec3::UnitZ()));
  EXPECT_NEAR(dist(c, pose, Vec3(0.4f, 1.5f, 0), &n), 0.3f, 1e-5f);
  expectVec(n, Vec3(0, 1, 0), 1e-5f);
  EXPECT_NEAR(dist(c, pose, Vec3(1.0f, 1.0f, 0), &n), 0.3f, 1e-5f);
  expectVec(n, Vec3(1, 0, 0), 1e-5f);
}

TEST(ColliderDistance, BoxFacesEdgesCornersAndInside) {
  Collider c = makeCollider(ColliderShape::Box);
  c.halfExtents = Vec3(1.0f, 0.5f, 0.25f);
  Vec3 n;
  // inside: minus the distance to the nearest face, normal of that face
  EXPECT_NEAR(dist(c, staticPose(), Vec3(0.9f, 0, 0), &n), -0.1f, 1e-6f);
  expectVec(n, Vec3(1, 0, 0), 1e-6f);
  EXPECT_NEAR(dist(c, staticPose(), Vec3(0, -0.4f, 0), &n), -0.1f, 1e-6f);
  expectVec(n, Vec3(0, -1, 0), 1e-6f);
  EXPECT_NEAR(dist(c, staticPose(), Vec3(0.2f, 0.1f, -0.2f), &n), -0.05f, 1e-6f);
  expectVec(n, Vec3(0, 0, -1), 1e-6f);
  // outside a face
  EXPECT_NEAR(dist(c, staticPose(), Vec3(0, 0, 1), &n), 0.75f, 1e-6f);
  expectVec(n, Vec3(0, 0, 1), 1e-6f);
  // edge region: distance to the edge
  EXPECT_NEAR(dist(c, staticPose(), Vec3(2, 1.5f, 0), &n), std::sqrt(2.0f), 1e-6f);
  expectVec(n, Vec3(1, 1, 0) / std::sqrt(2.0f), 1e-6f);
  // corner region: distance to the corner
  EXPECT_NEAR(dist(c, staticPose(), Vec3(-2, -1.5f, -1.25f), &n), std::sqrt(3.0f), 1e-6f);
  expectVec(n, -Vec3(1, 1, 1) / std::sqrt(3.0f), 1e-6f);
  // the centre is a degenerate point: a fixed unit axis
  EXPECT_NEAR(dist(c, staticPose(), Vec3::Zero(), &n), -0.25f, 1e-6f);
  EXPECT_NEAR(n.norm(), 1.0f, 1e-6f);
  // rotated 90 deg about y: local x lies along world -z
  const ColliderPose pose = staticPose(Vec3(0, 0, 0), aroundAxis(kPi / 2, Vec3::UnitY()));
  EXPECT_NEAR(dist(c, pose, Vec3(0, 0, -1.5f), &n), 0.5f, 1e-5f);
  expectVec(n, Vec3(0, 0, -1), 1e-5f);
}

TEST(ColliderDistance, ContainerCavityWallsAndOpenTop) {
  Collider c = makeCollider(ColliderShape::Container);
  c.halfExtents = Vec3(0.5f, 0.3f, 0.5f);
  c.wallThickness = 0.04f;
  const ColliderPose pose = staticPose(Vec3(0, 1, 0));  // cavity centre at y = 1
  Vec3 n;
  // inside the cavity: free, at the distance of the nearest inner face (the bottom, 0.3 below)
  EXPECT_NEAR(dist(c, pose, Vec3(0, 1, 0), &n), 0.3f, 1e-6f);
  expectVec(n, Vec3(0, 1, 0), 1e-6f);
  EXPECT_NEAR(dist(c, pose, Vec3(0.45f, 1.1f, 0), &n), 0.05f, 1e-6f);
  expectVec(n, Vec3(-1, 0, 0), 1e-6f);
  // inside a side wall: negative, normal to the nearer face
  EXPECT_NEAR(dist(c, pose, Vec3(0.51f, 1, 0), &n), -0.01f, 1e-6f);
  expectVec(n, Vec3(-1, 0, 0), 1e-6f);
  EXPECT_NEAR(dist(c, pose, Vec3(0, 1, -0.53f), &n), -0.01f, 1e-6f);
  expectVec(n, Vec3(0, 0, -1), 1e-6f);
  // inside the bottom
  EXPECT_NEAR(dist(c, pose, Vec3(0.1f, 1 - 0.31f, 0.2f), &n), -0.01f, 1e-6f);
  expectVec(n, Vec3(0, 1, 0), 1e-6f);
  // just above a wall's rim: positive, normal up
  EXPECT_NEAR(dist(c, pose, Vec3(0.52f, 1.4f, 0), &n), 0.1f, 1e-6f);
  expectVec(n, Vec3(0, 1, 0), 1e-6f);
  // above the open top, far from the walls: distance to the nearest rim edge
  EXPECT_NEAR(dist(c, pose, Vec3(0, 2, 0), &n), std::sqrt(0.5f * 0.5f + 0.7f * 0.7f), 1e-5f);
  EXPECT_GT(n.y(), 0.5f);
  // below the container
  EXPECT_NEAR(dist(c, pose, Vec3(0, 0.5f, 0), &n), 0.16f, 1e-6f);
  expectVec(n, Vec3(0, -1, 0), 1e-6f);
  // outside beside a wall
  EXPECT_NEAR(dist(c, pose, Vec3(0.64f, 1, 0), &n), 0.1f, 1e-6f);
  expectVec(n, Vec3(1, 0, 0), 1e-6f);
}

// the normal is the gradient of the distance: central differences at random points away from the
// kinks (where the finite-difference gradient is not unit length)
// one collider of every analytic shape, sized to fit the points of the tests below (|x| < 0.8)
std::vector<Collider> everyShape() {
  Collider box = makeCollider(ColliderShape::Box);
  box.halfExtents = Vec3(0.4f, 0.25f, 0.3f);
  Collider sphere = makeCollider(ColliderShape::Sphere);
  sphere.radius = 0.35f;
  Collider capsule = makeCollider(ColliderShape::Capsule);
  capsule.radius = 0.15f;
  capsule.halfHeight = 0.3f;
  Collider container = makeCollider(ColliderShape::Container);
  container.halfExtents = Vec3(0.4f, 0.3f, 0.35f);
  container.wallThickness = 0.05f;
  return {makeCollider(ColliderShape::Plane), box, sphere, capsule, container};
}

TEST(ColliderDistance, NormalsMatchFiniteDifferences) {
  const std::vector<Collider> shapes = everyShape();
  const ColliderPose pose = staticPose(Vec3(0.1f, -0.2f, 0.3f), aroundAxis(0.7f, Vec3(1, 2, 3)));
  std::mt19937 rng(12345);
  std::uniform_real_distribution<float> u(-0.8f, 0.8f);
  const float h = 1e-3f;
  for (const Collider& c : shapes) {
    int checked = 0;
    for (int k = 0; k < 400; ++k) {
      const Vec3 p = pose.translation + Vec3(u(rng), u(rng), u(rng));
      Vec3 n;
      dist(c, pose, p, &n);
      ASSERT_TRUE(n.allFinite());
      ASSERT_NEAR(n.norm(), 1.0f, 1e-5f);
      Vec3 g;
      for (int a = 0; a < 3; ++a) {
        Vec3 e = Vec3::Zero();
        e[a] = h;
        g[a] = (dist(c, pose, p + e) - dist(c, pose, p - e)) / (2 * h);
      }
      if (std::abs(g.norm() - 1.0f) > 5e-3f) continue;  // straddles a kink of the sdf
      ++checked;
      EXPECT_NEAR((g - n).norm(), 0.0f, 5e-3f) << "shape " << static_cast<int>(c.shape) << " at " << p.transpose();
    }
    EXPECT_GT(checked, 300) << "shape " << static_cast<int>(c.shape);
  }
}

TEST(ColliderDistance, VectorisedBoundsAreBelowTheExactDistanceAndClose) {
  // colliderDistanceBounds (the skip test of the contacts and of the water's walls) against
  // colliderDistance: never above it (a particle it skips cannot be in contact), at most the slack
  // below it, for every shape in a rotated, moved frame; points on both sides of every surface, more
  // than a chunk of them, and an out[] already lower stays
  const std::vector<Collider> shapes = everyShape();
  const ColliderPose pose = staticPose(Vec3(0.1f, -0.2f, 0.3f), aroundAxis(0.7f, Vec3(1, 2, 3)));
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.8f, 0.8f);
  const int n = 1000;
  std::vector<float> x(3 * n);
  for (float& v : x) v = u(rng);
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) x[3 * i + a] += pose.translation[a];
  for (const Collider& c : shapes) {
    std::vector<float> out(n, std::numeric_limits<float>::max());
    out[5] = -7.0f;  // already lower: kept
    colliderDistanceBounds(c, pose, x.data(), n, out.data());
    EXPECT_EQ(out[5], -7.0f);
    int inside = 0;
    for (int i = 0; i < n; ++i) {
      if (i == 5) continue;
      const float exact = dist(c, pose, Vec3(x[3 * i], x[3 * i + 1], x[3 * i + 2]));
      inside += exact < 0.0f;
      EXPECT_LE(out[i], exact) << "shape " << static_cast<int>(c.shape) << " point " << i;
      EXPECT_GE(out[i], exact - kDistanceBoundSlack - 1e-5f) << "shape " << static_cast<int>(c.shape) << " point " << i;
    }
    EXPECT_GT(inside, 10) << "shape " << static_cast<int>(c.shape);
    EXPECT_LT(inside, n - 10) << "shape " << static_cast<int>(c.shape);
  }
}

Collider movingCollider() {
  Collider c = makeCollider(ColliderShape::Box);
  c.keys.clear();
  c.keys.push_back(Keyframe{0.0f, Vec3(0, 0, 0), Quat::Identity()});
  c.keys.push_back(Keyframe{1.0f, Vec3(2, 0, 0), aroundAxis(kPi / 2, Vec3::UnitY())});
  c.keys.push_back(Keyframe{3.0f, Vec3(2, 4, 0), aroundAxis(kPi / 2, Vec3::UnitY())});
  return c;
}

float angleBetween(const Quat& a, const Quat& b) { return a.angularDistance(b); }

TEST(ColliderPoseTest, KeysMidpointsAndHeldEnds) {
  const Collider c = movingCollider();
  ColliderPose p = colliderPose(c, -1.0);
  expectVec(p.translation, Vec3(0, 0, 0), 1e-6f);
  expectVec(p.linearVelocity, Vec3::Zero(), 0.0f);
  expectVec(p.angularVelocity, Vec3::Zero(), 0.0f);

  p = colliderPose(c, 0.0);
  expectVec(p.translation, Vec3(0, 0, 0), 1e-6f);
  EXPECT_NEAR(angleBetween(p.rotation, Quat::Identity()), 0.0f, 1e-5f);

  p = colliderPose(c, 0.5);
  expectVec(p.translation, Vec3(1, 0, 0), 1e-6f);
  EXPECT_NEAR(angleBetween(p.rotation, aroundAxis(kPi / 4, Vec3::UnitY())), 0.0f, 1e-4f);
  expectVec(p.linearVelocity, Vec3(2, 0, 0), 1e-5f);
  expectVec(p.angularVelocity, Vec3(0, kPi / 2, 0), 1e-5f);

  p = colliderPose(c, 0.25);  // slerp, not lerp: a quarter of the angle
  EXPECT_NEAR(angleBetween(p.rotation, aroundAxis(kPi / 8, Vec3::UnitY())), 0.0f, 1e-4f);

  p = colliderPose(c, 1.0);
  expectVec(p.translation, Vec3(2, 0, 0), 1e-6f);
  EXPECT_NEAR(angleBetween(p.rotation, aroundAxis(kPi / 2, Vec3::UnitY())), 0.0f, 1e-4f);

  p = colliderPose(c, 2.0);
  expectVec(p.translation, Vec3(2, 2, 0), 1e-6f);
  expectVec(p.linearVelocity, Vec3(0, 2, 0), 1e-5f);
  expectVec(p.angularVelocity, Vec3::Zero(), 1e-5f);

  p = colliderPose(c, 10.0);
  expectVec(p.translation, Vec3(2, 4, 0), 1e-6f);
  EXPECT_NEAR(angleBetween(p.rotation, aroundAxis(kPi / 2, Vec3::UnitY())), 0.0f, 1e-4f);
  expectVec(p.linearVelocity, Vec3::Zero(), 0.0f);
  expectVec(p.angularVelocity, Vec3::Zero(), 0.0f);
}

// the rigid velocity field is the time derivative of a body-fixed point's world position
TEST(ColliderPoseTest, VelocityFieldMatchesFiniteDifferenceOfBodyPoint) {
  Collider c = makeCollider(ColliderShape::Box);
  c.keys.clear();
  c.keys.push_back(Keyframe{0.0f, Vec3(0.3f, 0, 0), aroundAxis(0.2f, Vec3(1, 1, 0))});
  c.keys.push_back(Keyframe{2.0f, Vec3(-1, 0.5f, 1), aroundAxis(1.4f, Vec3(0, 1, 2))});
  const Vec3 body(0.4f, -0.3f, 0.7f);
  const double t = 0.8, h = 1e-3;
  const ColliderPose a = colliderPose(c, t - h), b = colliderPose(c, t + h), mid = colliderPose(c, t);
  const Vec3 xa = a.rotation * body + a.translation, xb = b.rotation * body + b.translation;
  const Vec3 xm = mid.rotation * body + mid.translation;
  expectVec(mid.velocityAt(xm), (xb - xa) / static_cast<float>(2 * h), 2e-3f);
}

TEST(ColliderPoseTest, SingleKeyIsStatic) {
  Collider c = makeCollider(ColliderShape::Sphere);
  c.keys[0].translation = Vec3(1, 2, 3);
  const ColliderPose p = colliderPose(c, 5.0);
  expectVec(p.translation, Vec3(1, 2, 3), 0.0f);
  expectVec(p.velocityAt(Vec3(4, 4, 4)), Vec3::Zero(), 0.0f);
}

}  // namespace
}  // namespace soak
