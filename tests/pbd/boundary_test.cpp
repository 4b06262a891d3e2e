// rigid colliders as boundaries of the water's density (pbd/boundary.cpp): the solid fraction of the
// kernel is the half-space integral of poly6 at the part's distance, parts combine as a union, the
// gradient is that of the fraction, and the world boxes that let a point skip a part are tight and safe
#include "pbd/boundary.hpp"

#include "core/kernels.hpp"
#include "world/colliders.hpp"
#include "world/container.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

using namespace soak;

namespace {

// colliders of each shape, at rest (the pose is given beside them)
Collider sphereOf(float radius) {
  Collider c;
  c.shape = ColliderShape::Sphere;
  c.radius = radius;
  return c;
}
Collider capsuleOf(float radius, float halfHeight) {
  Collider c;
  c.shape = ColliderShape::Capsule;
  c.radius = radius;
  c.halfHeight = halfHeight;
  return c;
}
Collider boxOf(const Vec3& halfExtents) {
  Collider c;
  c.shape = ColliderShape::Box;
  c.halfExtents = halfExtents;
  return c;
}
Collider containerOf(const Vec3& halfExtents, float wallThickness) {
  Collider c = boxOf(halfExtents);
  c.shape = ColliderShape::Container;
  c.wallThickness = wallThickness;
  return c;
}

// the poly6 kernel's mass beyond a plane at signed distance d, integrated numerically (Simpson, 2000
// intervals) from its definition: W(r) = 315 / (64 pi h^9) (h^2 - r^2)^3, so the mass in the slab at
// height z is pi/4 * 315 / (64 pi h^9) (h^2 - z^2)^4 dz
double halfSpaceFraction(double d, double h) {
  if (d >= h) return 0.0;
  if (d <= -h) return 1.0;
  const int n = 2000;
  const double dz = (h - d) / n;
  const auto f = [&](double z) { return std::pow(h * h - z * z, 4); };
  double s = f(d) + f(h);
  for (int k = 1; k < n; ++k) s += (k % 2 ? 4.0 : 2.0) * f(d + k * dz);
  return 315.0 / (256.0 * std::pow(h, 9)) * s * dz / 3.0;
}

// one collider at a pose, as the step passes it
std::vector<BoundaryPart> partsOf(const Collider& c, const ColliderPose& pose) {
  Model model;
  model.colliders = {c};
  std::vector<BoundaryPart> parts;
  boundaryParts(model, {pose}, parts);
  return parts;
}

}  // namespace

TEST(Fluid, BoundaryPartBoxesSkipOnlyPartsBeyondTheSupport) {
  // boundaryFraction skips a part when the point is more than h outside the part's world box; the
  // fraction and its gradient must be those of every part measured, for rotated boxes, spheres,
  // capsules and a tilted container's walls, at points around and inside them
  Model model;
  const Quat tilt(Eigen::AngleAxisf(0.6f, Vec3(1, 2, 3).normalized()));
  const Collider box = boxOf(Vec3(0.3f, 0.05f, 0.2f)), sphere = sphereOf(0.15f), capsule = capsuleOf(0.05f, 0.2f);
  const Collider container = containerOf(Vec3(0.25f, 0.15f, 0.2f), 0.04f);
  model.colliders = {box, sphere, capsule, container};
  std::vector<ColliderPose> poses(4);
  const Vec3 at[4] = {Vec3(0, 0, 0), Vec3(0.4f, 0.1f, 0), Vec3(-0.4f, 0, 0.2f), Vec3(0, -0.5f, 0.1f)};
  for (int c = 0; c < 4; ++c) poses[c].translation = at[c], poses[c].rotation = tilt;
  std::vector<BoundaryPart> parts, unbounded;
  boundaryParts(model, poses, parts);
  ASSERT_EQ(parts.size(), 3u + 5u);
  unbounded = parts;
  for (BoundaryPart& part : unbounded)
    part.lo = Vec3::Constant(-std::numeric_limits<float>::infinity()), part.hi = -part.lo;
  const float h = 0.04f;
  int near = 0, skipped = 0;
  uint32_t seed = 12345u;
  const auto uniform = [&] { return (seed = seed * 1664525u + 1013904223u) / 4294967296.0f; };
  for (int k = 0; k < 20000; ++k) {
    const Vec3 x(1.4f * uniform() - 0.7f, 1.2f * uniform() - 0.8f, 1.0f * uniform() - 0.4f);
    Vec3 g, gRef;
    const float phi = boundaryFraction(parts, x, WallKernel(h), &g),
                phiRef = boundaryFraction(unbounded, x, WallKernel(h), &gRef);
    EXPECT_EQ(phi, phiRef) << x.transpose();
    EXPECT_EQ(g, gRef) << x.transpose();
    near += phiRef > 0.0f;
    for (const BoundaryPart& part : parts)
      skipped += (x.array() < part.lo.array() - h).any() || (x.array() > part.hi.array() + h).any();
  }
  EXPECT_GT(near, 1000);         // points by the parts
  EXPECT_GT(skipped, 20000 * 4); // and most parts skipped for most points
}

// above a tilted plane the fraction is the half-space integral at the point's height (to 1e-5 of the
// numerical integral), 1/2 on the plane, 0 beyond h and 1 deeper than h; the gradient points into the
// solid with the derivative of the integral, and matches central differences
TEST(PbdBoundary, APlaneGivesTheHalfSpaceIntegralOfTheKernel) {
  Collider plane;
  plane.shape = ColliderShape::Plane;
  ColliderPose pose;
  pose.translation = Vec3(0.3f, -0.2f, 0.1f);
  pose.rotation = Quat(Eigen::AngleAxisf(0.4f, Vec3(1, 0, 1).normalized()));
  const std::vector<BoundaryPart> parts = partsOf(plane, pose);
  ASSERT_EQ(parts.size(), 1u);
  EXPECT_TRUE(std::isinf(parts[0].hi.x()));  // an infinite part is never skipped
  const Vec3 n = pose.rotation * Vec3::UnitY();
  const Vec3 base = pose.translation + pose.rotation * Vec3(0.2f, 0.0f, -0.3f);
  const float h = 0.04f;
  for (float d : {-0.05f, -0.03f, -0.01f, 0.0f, 0.005f, 0.02f, 0.039f, 0.041f}) {
    Vec3 g;
    const float phi = boundaryFraction(parts, base + d * n, WallKernel(h), &g);
    EXPECT_NEAR(phi, halfSpaceFraction(d, h), 1e-5) << d;
    const float e = 1e-4f;
    const float up = boundaryFraction(parts, base + (d + e) * n, WallKernel(h), nullptr);
    const float down = boundaryFraction(parts, base + (d - e) * n, WallKernel(h), nullptr);
    if (std::fabs(std::fabs(d) - h) > 2 * e) {
      EXPECT_NEAR(g.dot(n), (up - down) / (2 * e), 0.1f) << d;  // |grad| is up to 1.23 / h = 31 / m
      EXPECT_LT((g - g.dot(n) * n).norm(), 1e-4f / h) << "the gradient is along the normal, d " << d;
    }
  }
  EXPECT_NEAR(boundaryFraction(parts, base, WallKernel(h), nullptr), 0.5f, 1e-6f);
  EXPECT_EQ(boundaryFraction(parts, base + 0.05f * n, WallKernel(h), nullptr), 0.0f);
  EXPECT_EQ(boundaryFraction(parts, base - 0.05f * n, WallKernel(h), nullptr), 1.0f);
  EXPECT_EQ(boundaryFraction({}, base, WallKernel(h), nullptr), 0.0f);
}

// an open container is five boxes; in the corner of its cavity, d1 above the floor and d2 from a side
// wall, water sees both: phi = 1 - (1 - Phi(d1)) (1 - Phi(d2)), with the product rule's gradient
TEST(PbdBoundary, AContainerCornerIsTheUnionOfItsWalls) {
  const Collider box = containerOf(Vec3(0.3f, 0.2f, 0.25f), 0.05f);
  ColliderPose pose;
  pose.translation = Vec3(1.0f, 0.5f, -0.5f);
  pose.rotation = Quat(Eigen::AngleAxisf(0.7f, Vec3::UnitY()));
  const std::vector<BoundaryPart> parts = partsOf(box, pose);
  ASSERT_EQ(parts.size(), size_t(kContainerWalls));
  Vec3 centers[kContainerWalls], halves[kContainerWalls];
  containerWalls(box, centers, halves);
  for (int k = 0; k < kContainerWalls; ++k) {
    EXPECT_EQ(parts[k].shape.shape, ColliderShape::Box);
    EXPECT_EQ(parts[k].shape.halfExtents, halves[k]);
    EXPECT_LT((parts[k].pose.translation - (pose.translation + pose.rotation * centers[k])).norm(), 1e-6f);
  }
  const float h = 0.04f, d1 = 0.012f, d2 = 0.008f;
  // the cavity's floor is y = -0.2, its +x wall x = 0.3 (local frame); far from the z walls
  const auto world = [&](const Vec3& local) { return Vec3(pose.rotation * local + pose.translation); };
  const Vec3 local(0.3f - d2, -0.2f + d1, 0.0f);
  Vec3 g;
  const float phi = boundaryFraction(parts, world(local), WallKernel(h), &g);
  const double a = halfSpaceFraction(d1, h), b = halfSpaceFraction(d2, h);
  EXPECT_NEAR(phi, 1.0 - (1.0 - a) * (1.0 - b), 2e-5);
  EXPECT_GT(phi, std::max(a, b));
  const float e = 1e-4f;
  for (int axis = 0; axis < 3; ++axis) {
    Vec3 step = Vec3::Zero();
    step[axis] = e;
    const float fd = (boundaryFraction(parts, world(local + step), WallKernel(h), nullptr) -
                      boundaryFraction(parts, world(local - step), WallKernel(h), nullptr)) / (2 * e);
    EXPECT_NEAR((pose.rotation.inverse() * g)[axis], fd, 0.1f) << axis;
  }
  // in the middle of the cavity, more than h from every wall, nothing; inside a wall, everything
  EXPECT_EQ(boundaryFraction(parts, world(Vec3(0, 0, 0)), WallKernel(h), nullptr), 0.0f);
  EXPECT_EQ(boundaryFraction(parts, world(Vec3(0, -0.225f, 0)), WallKernel(0.02f), nullptr), 1.0f);  // mid-floor
}

// the world boxes of spheres, capsules and rotated boxes hold the part and are no larger than its exact
// world bounds by more than the 1e-5 relative rounding allowance
TEST(PbdBoundary, PartBoxesAreTheWorldBoundsOfEachShape) {
  const Quat tilt(Eigen::AngleAxisf(0.5f, Vec3(0, 0, 1)));
  ColliderPose pose;
  pose.translation = Vec3(0.2f, 1.0f, -0.4f);
  pose.rotation = tilt;
  const Collider sphere = sphereOf(0.15f), capsule = capsuleOf(0.05f, 0.2f), box = boxOf(Vec3(0.3f, 0.1f, 0.2f));
  const Eigen::Matrix3f r = tilt.toRotationMatrix();
  const Vec3 expected[3] = {Vec3::Constant(0.15f), r.col(1).cwiseAbs() * 0.2f + Vec3::Constant(0.05f),
                            r.cwiseAbs() * box.halfExtents};
  const Collider* shapes[3] = {&sphere, &capsule, &box};
  for (int k = 0; k < 3; ++k) {
    const std::vector<BoundaryPart> parts = partsOf(*shapes[k], pose);
    ASSERT_EQ(parts.size(), 1u);
    const Vec3 half = 0.5f * (parts[0].hi - parts[0].lo);
    EXPECT_LT((0.5f * (parts[0].hi + parts[0].lo) - pose.translation).norm(), 1e-6f) << k;
    for (int a = 0; a < 3; ++a) {
      EXPECT_GE(half[a], expected[k][a]) << k << " " << a;
      EXPECT_LE(half[a], expected[k][a] * (1.0f + 2e-5f) + 2e-6f) << k << " " << a;
    }
  }
}
