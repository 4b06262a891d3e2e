// a Body collider: the smooth union of moving parts (smoothMin), its distance, normal, surface
// velocity, vectorised bound, contact, and the built-in mannequin as one
#include "world/colliders.hpp"

#include "world/mannequin.hpp"
#include "world/smooth_min.hpp"

#include "support/colliders.hpp"

#include <soak/error.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace soak {
namespace {

using testing::expectVec;
using testing::makeCollider;

Collider sphereAt(const Vec3& centre, float radius, float time1 = -1.0f, const Vec3& centre1 = Vec3::Zero()) {
  Collider c = makeCollider(ColliderShape::Sphere);
  c.radius = radius;
  c.keys[0].translation = centre;
  if (time1 > 0.0f) c.keys.push_back(Keyframe{time1, centre1, Quat::Identity()});
  return c;
}

// two spheres of radius 0.2, 0.3 m apart: their surfaces cross on a circle in the plane x = 0.15
Collider twoSpheres(float k) {
  return makeBodyCollider("b", {sphereAt(Vec3(0, 0, 0), 0.2f), sphereAt(Vec3(0.3f, 0, 0), 0.2f)}, k, "test");
}

TEST(SmoothMin, IsTheMinAwayFromTiesAndNeverFurtherThanAQuarterOfKBelowIt) {
  const float k = 0.04f;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-0.1f, 0.1f);
  for (int n = 0; n < 1000; ++n) {
    const float a = u(rng), b = u(rng);
    float w;
    const float s = smoothMin(a, b, k, &w);
    EXPECT_LE(s, std::min(a, b));
    EXPECT_GE(s, std::min(a, b) - 0.25f * k - 1e-7f);
    if (std::fabs(a - b) >= k) EXPECT_EQ(s, std::min(a, b));
    // the weight is the derivative in b (central differences)
    const float e = 1e-3f;
    float unused;
    const float dsdb = (smoothMin(a, b + e, k, &unused) - smoothMin(a, b - e, k, &unused)) / (2 * e);
    if (std::fabs(std::fabs(a - b) - k) > 2 * e) EXPECT_NEAR(w, dsdb, 2e-3f) << a << " " << b;
  }
  // folded over many values it stays within k of their min (the body's skin within k of its parts)
  for (int n = 0; n < 200; ++n) {
    float r = u(rng), m = r, w;
    for (int j = 0; j < 30; ++j) {
      const float d = m + 0.3f * k * u(rng) / 0.1f;  // values close together: the worst case
      r = smoothMin(r, d, k, &w);
      m = std::min(m, d);
    }
    EXPECT_GE(r, m - k);
  }
  // the bound is nearly reached: 30 equal values fold to 0.887 k below them
  float r = 0.0f, w;
  for (int j = 1; j < 30; ++j) r = smoothMin(r, 0.0f, k, &w);
  EXPECT_NEAR(r, -0.8867f * k, 1e-4f * k);
}

TEST(BodyCollider, FarFromTheJoinItIsItsNearestPart) {
  const Collider body = twoSpheres(0.04f);
  const ColliderPose pose = colliderPose(body, 0.0);
  ASSERT_EQ(pose.parts.size(), 2u);
  Vec3 n;
  EXPECT_FLOAT_EQ(colliderDistance(body, pose, Vec3(-0.5f, 0, 0), &n), 0.3f);
  expectVec(n, Vec3(-1, 0, 0), 1e-6f);
  EXPECT_FLOAT_EQ(colliderDistance(body, pose, Vec3(0.3f, 0.5f, 0), &n), 0.3f);
  expectVec(n, Vec3(0, 1, 0), 1e-6f);
  EXPECT_FLOAT_EQ(colliderDistance(body, pose, Vec3(0.3f, 0, 0), &n), -0.2f);  // inside: the part's depth
}

// the union of the two spheres has a crease where they meet; the body fills it and its normal turns
// smoothly across it, where the union's jumps
TEST(BodyCollider, FillsTheCreaseWithAContinuousNormal) {
  const float k = 0.04f;
  const Collider body = twoSpheres(k);
  const Collider a = sphereAt(Vec3(0, 0, 0), 0.2f), b = sphereAt(Vec3(0.3f, 0, 0), 0.2f);
  const ColliderPose pose = colliderPose(body, 0.0), pa = colliderPose(a, 0.0), pb = colliderPose(b, 0.0);
  const Vec3 crease(0.15f, std::sqrt(0.04f - 0.0225f), 0);  // on both spheres
  EXPECT_NEAR(colliderDistance(body, pose, crease, nullptr), -0.25f * k, 1e-6f);  // s(0, 0) = -k / 4
  float bodyTurn = 0.0f, unionTurn = 0.0f;
  Vec3 lastBody = Vec3::Zero(), lastUnion = Vec3::Zero();
  for (int s = 0; s <= 100; ++s) {  // along x at a height just over the crease, 1 mm apart
    const Vec3 x(0.1f + 0.001f * float(s), crease.y() + 0.005f, 0);
    Vec3 nb, na, nu;
    colliderDistance(body, pose, x, &nb);
    const float da = colliderDistance(a, pa, x, &na), db = colliderDistance(b, pb, x, &nu);
    if (da < db) nu = na;
    if (s > 0) {
      bodyTurn = std::max(bodyTurn, std::acos(std::clamp(nb.dot(lastBody), -1.0f, 1.0f)));
      unionTurn = std::max(unionTurn, std::acos(std::clamp(nu.dot(lastUnion), -1.0f, 1.0f)));
    }
    lastBody = nb, lastUnion = nu;
  }
  EXPECT_GT(unionTurn, 0.5f);  // rad in one millimetre: the crease
  EXPECT_LT(bodyTurn, 0.05f);
}

TEST(BodyCollider, NormalIsTheGradientAndTheBoundIsTight) {
  const Collider body = twoSpheres(0.04f);
  const ColliderPose pose = colliderPose(body, 0.0);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.35f, 0.65f);
  std::vector<float> xs;
  std::vector<float> exact;
  for (int n = 0; n < 500; ++n) {
    const Vec3 x(u(rng), 0.6f * u(rng), 0.6f * u(rng));
    Vec3 nrm;
    const float d = colliderDistance(body, pose, x, &nrm);
    const float e = 1e-3f;
    Vec3 g;
    for (int a = 0; a < 3; ++a) {
      Vec3 dx = Vec3::Zero();
      dx[a] = e;
      g[a] = (colliderDistance(body, pose, x + dx, nullptr) - colliderDistance(body, pose, x - dx, nullptr)) / (2 * e);
    }
    EXPECT_LE(g.norm(), 1.0f + 1e-2f);  // a blend of unit normals: 1-Lipschitz, never beyond the skin
    if (g.norm() > 0.1f) expectVec(nrm, g.normalized(), 2e-2f);
    xs.insert(xs.end(), x.data(), x.data() + 3);
    exact.push_back(d);
  }
  std::vector<float> bound(exact.size(), 1e30f);
  colliderDistanceBounds(body, pose, xs.data(), int64_t(exact.size()), bound.data());
  for (size_t i = 0; i < exact.size(); ++i) {
    EXPECT_LE(bound[i], exact[i]);
    EXPECT_GT(bound[i], exact[i] - 2e-4f);
  }
}

// the skin's velocity is its parts' blended with the weights of the normal: a part's own near it, a
// mix where they join; a still part does not slow a point that only the moving one reaches
TEST(BodyCollider, SkinMovesWithItsPartsBlended) {
  const float k = 0.04f;
  Collider moving = sphereAt(Vec3(0.3f, 0, 0), 0.2f, 1.0f, Vec3(0.3f, 0.5f, 0));  // 0.5 m/s up
  const Collider body = makeBodyCollider("b", {sphereAt(Vec3(0, 0, 0), 0.2f), moving}, k, "test");
  const ColliderPose pose = colliderPose(body, 0.2);
  EXPECT_TRUE(pose.moving());
  expectVec(pose.parts[1].translation, Vec3(0.3f, 0.1f, 0), 1e-6f);
  const Vec3 farSide(0.55f, 0.1f, 0);  // on the moving sphere's far side
  expectVec(colliderVelocity(body, pose, farSide), Vec3(0, 0.5f, 0), 1e-6f);
  expectVec(colliderVelocity(body, pose, Vec3(-0.25f, 0, 0)), Vec3::Zero(), 1e-6f);
  // where both are within k (equally far from both centres, near the skin): the weight of the
  // second part in the fold
  const Vec3 centre1 = pose.parts[1].translation;
  const Vec3 x = 0.5f * centre1 + 0.125f * Vec3(-centre1.y(), centre1.x(), 0).normalized();
  Vec3 na, nb;
  const float da = colliderDistance(body.parts->at(0), pose.parts[0], x, &na);
  const float db = colliderDistance(body.parts->at(1), pose.parts[1], x, &nb);
  ASSERT_LT(std::fabs(da - db), k);
  float w;
  smoothMin(da, db, k, &w);
  EXPECT_GT(w, 0.1f);
  EXPECT_LT(w, 0.9f);
  expectVec(colliderVelocity(body, pose, x), Vec3(0, 0.5f * w, 0), 1e-6f);
  EXPECT_LE(colliderVelocity(body, pose, x).norm(), colliderSpeedBound(body, pose, x) + 1e-7f);
}

TEST(BodyCollider, PushOutReachesTheMarginWhereThePartsBlend) {
  const Collider body = twoSpheres(0.04f);
  const ColliderPose pose = colliderPose(body, 0.0);
  const float margin = 0.005f;
  for (const Vec3& start : {Vec3(0.15f, 0.15f, 0), Vec3(0.15f, 0.1f, 0.05f), Vec3(-0.1f, 0.1f, 0)}) {
    Vec3 x = start, n;
    ASSERT_TRUE(pushOutOf(body, pose, margin, x, &n));
    EXPECT_NEAR(colliderDistance(body, pose, x, nullptr), margin, 1e-5f) << start.transpose();
    EXPECT_FALSE(pushOutOf(body, pose, margin, x, &n));  // now clear
  }
}

// the PBD contact puts a particle that ends inside the crease on the skin, at its margin
TEST(BodyCollider, ParticleContactPutsItOnTheSkin) {
  Model m;
  m.water.spacing = 0.02f;
  m.colliders.push_back(twoSpheres(0.04f));
  Particles p;
  p.add(kWaterPhase, 0, 0.008f, 0.04f, Vec3(0.15f, 0.25f, 0), Vec3::Zero());
  p.xPred[0] = Vec3(0.15f, 0.12f, 0.01f);  // in the filled crease, under both spheres' surfaces
  std::vector<Vec3> normals;
  const std::vector<ColliderPose> poses = {colliderPose(m.colliders[0], 0.0)};
  projectColliders(m, poses, p, 0.01f, normals);
  // on the tangent plane of the face it entered by: at the margin, a hair beyond it on the curved skin
  const float d = colliderDistance(m.colliders[0], poses[0], p.xPred[0], nullptr);
  EXPECT_GE(d, contactMargin(m, kWaterPhase) - 1e-6f);
  EXPECT_LT(d, contactMargin(m, kWaterPhase) + 1e-4f);
  EXPECT_GT(normals[0].y(), 0.9f);
}

TEST(BodyCollider, BadPartsAndRadiiAreRefused) {
  const Collider s = sphereAt(Vec3::Zero(), 0.1f);
  EXPECT_THROW(makeBodyCollider("b", {}, 0.01f, "t"), Error);
  EXPECT_THROW(makeBodyCollider("b", {s}, 0.0f, "t"), Error);
  Collider plane = makeCollider(ColliderShape::Plane);
  plane.name = "b.floor";
  try {
    makeBodyCollider("b", {s, plane}, 0.01f, "scene.json");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("b.floor"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("expected a sphere, capsule or box"), std::string::npos) << e.what();
  }
}

// the smooth mannequin: its skin holds its parts (never inside their union), is within the blend
// radius of it, and its parts move as buildMannequin's colliders do
TEST(BodyCollider, MannequinSkinWrapsItsParts) {
  MannequinParams mp;
  std::vector<PoseKey> keys = {{0.0f, {}}, {1.0f, {}}};
  keys[1].pose.elbowFlexion = {1.2f, 0.0f};
  const std::vector<Collider> parts = buildMannequin(mp, keys, 0.5f, "m", "test");
  const std::vector<Collider> smooth = mannequinColliders(mp, keys, 0.5f, "m", "test");
  ASSERT_EQ(smooth.size(), 1u);
  const Collider& body = smooth[0];
  const float k = mp.blend * mp.height;
  EXPECT_FLOAT_EQ(body.blendRadius, k);
  const ColliderPose pose = colliderPose(body, 0.5);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> ux(-0.4f, 0.4f), uy(0.0f, 1.8f), uz(-0.25f, 0.25f);
  int blended = 0;
  for (int n = 0; n < 3000; ++n) {
    const Vec3 x(ux(rng), uy(rng), uz(rng));
    float nearest = 1e30f;
    for (size_t q = 0; q < parts.size(); ++q) {
      const ColliderPose pq = colliderPose(parts[q], 0.5);
      expectVec(pq.translation, pose.parts[q].translation, 1e-6f);
      nearest = std::min(nearest, colliderDistance(parts[q], pq, x, nullptr));
    }
    const float d = colliderDistance(body, pose, x, nullptr);
    EXPECT_LE(d, nearest + 1e-6f);
    EXPECT_GE(d, nearest - k);
    blended += d < nearest - 1e-4f ? 1 : 0;
  }
  EXPECT_GT(blended, 100);  // the blend is not confined to a few points
  // blend 0: the separate parts; out of [0, 0.1]: refused, naming the key
  mp.blend = 0.0f;
  EXPECT_EQ(mannequinColliders(mp, keys, 0.5f, "m", "test").size(), parts.size());
  mp.blend = 0.2f;
  try {
    mannequinColliders(mp, keys, 0.5f, "m", "scene.json");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("mannequin.blend"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace soak
