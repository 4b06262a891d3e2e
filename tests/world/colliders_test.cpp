// colliders: exact signed distances and normals of each shape, keyframed poses and their velocities,
// contact projection with friction, restitution
#include "world/colliders.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace soak {
namespace {

Collider makeCollider(ColliderShape shape) {
  Collider c;
  c.shape = shape;
  c.keys.push_back(Keyframe{});
  return c;
}

ColliderPose staticPose(const Vec3& t = Vec3::Zero(), const Quat& q = Quat::Identity()) {
  ColliderPose pose;
  pose.translation = t;
  pose.rotation = q;
  return pose;
}

Quat aroundAxis(float angle, const Vec3& axis) { return Quat(Eigen::AngleAxisf(angle, axis.normalized())); }

void expectVec(const Vec3& a, const Vec3& b, float tol) {
  EXPECT_NEAR(a.x(), b.x(), tol) << "got " << a.transpose() << " expected " << b.transpose();
  EXPECT_NEAR(a.y(), b.y(), tol) << "got " << a.transpose() << " expected " << b.transpose();
  EXPECT_NEAR(a.z(), b.z(), tol) << "got " << a.transpose() << " expected " << b.transpose();
}

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

Model planeModel(float friction) {
  Model m;
  m.water.spacing = 0.02f;
  Collider c = makeCollider(ColliderShape::Plane);
  c.friction = friction;
  m.colliders.push_back(c);
  ClothPiece piece;
  piece.material.thickness = 0.01f;
  piece.material.friction = 0.0f;
  m.pieces.push_back(piece);
  return m;
}

std::vector<ColliderPose> posesAt(const Model& m, double t) {
  std::vector<ColliderPose> poses;
  for (const Collider& c : m.colliders) poses.push_back(colliderPose(c, t));
  return poses;
}

TEST(ColliderContact, MarginsOfWaterAndCloth) {
  Model m = planeModel(0.0f);
  EXPECT_FLOAT_EQ(contactMargin(m, kWaterPhase), 0.01f);
  EXPECT_FLOAT_EQ(contactMargin(m, 1), 0.005f);
  m.pieces[0].material.thickness = 0.0f;
  EXPECT_FLOAT_EQ(contactMargin(m, 1), 1e-4f);
}

TEST(ColliderContact, ParticleBelowPlaneEndsAtMargin) {
  const Model m = planeModel(0.0f);
  Particles p;
  p.add(kWaterPhase, 0, 0.008f, 0.04f, Vec3(0, 0.05f, 0), Vec3::Zero());
  p.add(kWaterPhase, 1, 0.008f, 0.04f, Vec3(1, 0.05f, 0), Vec3::Zero());
  p.add(1, 2, 0.006f, 0.0f, Vec3(2, 0.05f, 0), Vec3::Zero());
  p.xPred[0] = Vec3(0, -0.03f, 0);
  p.xPred[1] = Vec3(1, 0.04f, 0);  // clear of the plane
  p.xPred[2] = Vec3(2, -0.1f, 0);  // cloth: margin is half its thickness
  std::vector<Vec3> normals;
  projectColliders(m, posesAt(m, 0.0), p, 0.01f, normals);
  ASSERT_EQ(normals.size(), 3u);
  EXPECT_NEAR(p.xPred[0].y(), contactMargin(m, kWaterPhase), 1e-6f);
  expectVec(normals[0], Vec3(0, 1, 0), 0.0f);
  expectVec(p.xPred[1], Vec3(1, 0.04f, 0), 0.0f);
  expectVec(normals[1], Vec3::Zero(), 0.0f);
  EXPECT_NEAR(p.xPred[2].y(), 0.005f, 1e-6f);
}

TEST(ColliderContact, FrictionRemovesTheFractionOfSlip) {
  for (float mu : {0.0f, 0.5f, 1.0f}) {
    const Model m = planeModel(mu);
    Particles p;
    p.add(kWaterPhase, 0, 0.008f, 0.04f, Vec3(0, 0.05f, 0), Vec3::Zero());
    p.xPred[0] = Vec3(0.1f, -0.03f, 0.02f);
    std::vector<Vec3> normals;
    projectColliders(m, posesAt(m, 0.0), p, 0.01f, normals);
    EXPECT_NEAR(p.xPred[0].x(), (1 - mu) * 0.1f, 1e-6f) << "mu " << mu;
    EXPECT_NEAR(p.xPred[0].z(), (1 - mu) * 0.02f, 1e-6f) << "mu " << mu;
    EXPECT_NEAR(p.xPred[0].y(), 0.01f, 1e-6f);
  }
}

TEST(ColliderContact, ClothFrictionAveragesColliderAndMaterial) {
  const Model m = planeModel(1.0f);  // material friction 0
  Particles p;
  p.add(1, 0, 0.006f, 0.0f, Vec3(0, 0.05f, 0), Vec3::Zero());
  p.xPred[0] = Vec3(0.1f, -0.03f, 0);
  std::vector<Vec3> normals;
  projectColliders(m, posesAt(m, 0.0), p, 0.01f, normals);
  EXPECT_NEAR(p.xPred[0].x(), 0.05f, 1e-6f);
}

TEST(ColliderContact, PinnedParticlesAreUntouched) {
  const Model m = planeModel(1.0f);
  Particles p;
  p.add(1, 0, 0.0f, 0.0f, Vec3(0, 0.05f, 0), Vec3::Zero());  // mass 0 -> invMass 0
  ASSERT_EQ(p.invMass[0], 0.0f);
  p.xPred[0] = Vec3(0.1f, -0.3f, 0);
  std::vector<Vec3> normals;
  projectColliders(m, posesAt(m, 0.0), p, 0.01f, normals);
  expectVec(p.xPred[0], Vec3(0.1f, -0.3f, 0), 0.0f);
  expectVec(normals[0], Vec3::Zero(), 0.0f);
}

TEST(ColliderContact, SpherePushesOutRadially) {
  Model m = planeModel(0.0f);
  m.colliders[0] = makeCollider(ColliderShape::Sphere);
  m.colliders[0].radius = 0.3f;
  m.colliders[0].friction = 0.0f;
  m.colliders[0].keys[0].translation = Vec3(0, 1, 0);
  Particles p;
  p.add(kWaterPhase, 0, 0.008f, 0.04f, Vec3(0, 1.5f, 0), Vec3::Zero());
  p.xPred[0] = Vec3(0.1f, 1.2f, 0);
  std::vector<Vec3> normals;
  projectColliders(m, posesAt(m, 0.0), p, 0.01f, normals);
  const Vec3 dir = Vec3(0.1f, 0.2f, 0).normalized();
  expectVec(p.xPred[0], Vec3(0, 1, 0) + (0.3f + 0.01f) * dir, 1e-6f);
  expectVec(normals[0], dir, 1e-6f);
}

// a container wall crossed past its middle within one substep is nearer its far face: the particle
// goes back out through the face it came in by, from inside the container and from outside alike
TEST(ColliderContact, ThinWallCrossedPastItsMiddleSendsTheParticleBack) {
  Model m = planeModel(0.0f);
  m.colliders[0] = makeCollider(ColliderShape::Container);
  m.colliders[0].halfExtents = Vec3(0.5f, 0.25f, 0.5f);
  m.colliders[0].wallThickness = 0.04f;  // the +x wall spans x = 0.50 .. 0.54, its middle 0.52
  m.colliders[0].friction = 0.0f;
  const float margin = contactMargin(m, kWaterPhase);
  Particles p;
  p.add(kWaterPhase, 0, 0.008f, 0.04f, Vec3(0.49f, 0.0f, 0.1f), Vec3::Zero());  // inside, 0.01 from the wall
  p.add(kWaterPhase, 1, 0.008f, 0.04f, Vec3(0.56f, 0.0f, 0.1f), Vec3::Zero());  // outside
  p.add(kWaterPhase, 2, 0.008f, 0.04f, Vec3(0.49f, 0.0f, -0.1f), Vec3::Zero());  // inside, not past the middle
  p.xPred[0] = Vec3(0.525f, 0.0f, 0.1f);
  p.xPred[1] = Vec3(0.515f, 0.0f, 0.1f);
  p.xPred[2] = Vec3(0.515f, 0.0f, -0.1f);
  std::vector<Vec3> normals;
  projectColliders(m, posesAt(m, 0.0), p, 0.015f, normals);
  expectVec(p.xPred[0], Vec3(0.5f - margin, 0.0f, 0.1f), 1e-6f);
  expectVec(normals[0], Vec3(-1, 0, 0), 0.0f);
  expectVec(p.xPred[1], Vec3(0.54f + margin, 0.0f, 0.1f), 1e-6f);
  expectVec(normals[1], Vec3(1, 0, 0), 0.0f);
  expectVec(p.xPred[2], Vec3(0.5f - margin, 0.0f, -0.1f), 1e-6f);
  // a particle driven at the wall at 2 m/s, a 0.03 m substep: it stays in the container
  Particles q;
  q.add(kWaterPhase, 0, 0.008f, 0.04f, Vec3(0.40f, 0.0f, 0.0f), Vec3(2.0f, 0.0f, 0.0f));
  const float dt = 0.015f;
  for (int step = 0; step < 10; ++step) {
    q.v[0] = Vec3(2.0f, 0.0f, 0.0f);
    q.xPred[0] = q.x[0] + dt * q.v[0];
    projectColliders(m, posesAt(m, step * dt), q, dt, normals);
    q.x[0] = q.xPred[0];
    ASSERT_LE(q.x[0].x(), 0.5f - margin + 1e-6f) << "step " << step;
  }
}

// a particle resting on a plane that slides along x is carried with it when friction is 1,
// stays behind when friction is 0 (integrated like the step: predict, project, v = dx / dt)
TEST(ColliderContact, MovingColliderDragsParticleWithFriction) {
  for (float mu : {0.0f, 1.0f}) {
    Model m = planeModel(mu);
    m.colliders[0].keys.clear();
    m.colliders[0].keys.push_back(Keyframe{0.0f, Vec3(0, 0, 0), Quat::Identity()});
    m.colliders[0].keys.push_back(Keyframe{1.0f, Vec3(0.5f, 0, 0), Quat::Identity()});
    Particles p;
    p.add(kWaterPhase, 0, 0.008f, 0.04f, Vec3(0, 0.01f, 0), Vec3::Zero());
    const float dt = 0.01f;
    std::vector<Vec3> normals;
    for (int step = 0; step < 50; ++step) {
      const double t = step * dt;
      p.v[0] += dt * Vec3(0, -9.81f, 0);
      p.xPred[0] = p.x[0] + dt * p.v[0];
      projectColliders(m, posesAt(m, t), p, dt, normals);
      p.v[0] = (p.xPred[0] - p.x[0]) / dt;
      p.x[0] = p.xPred[0];
    }
    EXPECT_NEAR(p.x[0].y(), 0.01f, 1e-5f);
    EXPECT_NEAR(p.x[0].x(), mu * 0.25f, 1e-4f) << "mu " << mu;
    EXPECT_NEAR(p.v[0].x(), mu * 0.5f, 1e-3f) << "mu " << mu;
  }
}

TEST(ColliderRestitution, ZeroKillsAndOneReversesInwardNormalVelocity) {
  for (float e : {0.0f, 1.0f}) {
    Model m = planeModel(0.0f);
    m.colliders[0].restitution = e;
    Particles p;
    p.add(kWaterPhase, 0, 0.008f, 0.04f, Vec3(0, 0.01f, 0), Vec3(1, -2, 0));
    p.add(kWaterPhase, 1, 0.008f, 0.04f, Vec3(1, 0.01f, 0), Vec3(1, 2, 0));   // leaving: kept
    p.add(kWaterPhase, 2, 0.008f, 0.04f, Vec3(2, 0.01f, 0), Vec3(1, -2, 0));  // no contact: kept
    const std::vector<Vec3> normals = {Vec3(0, 1, 0), Vec3(0, 1, 0), Vec3::Zero()};
    applyColliderRestitution(m, posesAt(m, 0.0), normals, p);
    expectVec(p.v[0], Vec3(1, 2 * e, 0), 1e-6f);
    expectVec(p.v[1], Vec3(1, 2, 0), 0.0f);
    expectVec(p.v[2], Vec3(1, -2, 0), 0.0f);
  }
}

TEST(ColliderRestitution, RelativeToAMovingColliderAndItsOwnCoefficient) {
  Model m = planeModel(0.0f);
  m.colliders[0].keys.clear();
  m.colliders[0].keys.push_back(Keyframe{0.0f, Vec3(0, 0, 0), Quat::Identity()});
  m.colliders[0].keys.push_back(Keyframe{1.0f, Vec3(0, 1, 0), Quat::Identity()});  // rises at 1 m/s
  m.colliders[0].restitution = 0.0f;
  Collider far = makeCollider(ColliderShape::Sphere);  // not the contact: its restitution is unused
  far.restitution = 1.0f;
  far.keys[0].translation = Vec3(5, 5, 5);
  m.colliders.push_back(far);
  Particles p;
  p.add(kWaterPhase, 0, 0.008f, 0.04f, Vec3(0, 0.51f, 0), Vec3::Zero());
  const std::vector<Vec3> normals = {Vec3(0, 1, 0)};
  applyColliderRestitution(m, posesAt(m, 0.5), normals, p);
  expectVec(p.v[0], Vec3(0, 1, 0), 1e-6f);  // now moves with the floor
}

}  // namespace
}  // namespace soak
