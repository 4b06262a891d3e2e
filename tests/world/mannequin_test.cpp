// mannequin: height and ground contact, left/right symmetry, head above the shoulders, joints that
// stay joined, keyed motion (the garments sewn around it: garment_mesh_test.cpp)
#include "world/mannequin.hpp"

#include "world/garment_mesh.hpp"  // bodyDistance

#include "scene/cloth_piece.hpp"
#include "world/colliders.hpp"

#include <soak/error.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

namespace soak {
namespace {

const Collider& part(const std::vector<Collider>& body, const std::string& name) {
  for (const Collider& c : body)
    if (c.name == "mannequin." + name) return c;
  throw std::runtime_error("no part " + name);
}

// world end points of a capsule (or the centre twice for a sphere) at time t
std::array<Vec3, 2> ends(const Collider& c, double t) {
  const ColliderPose p = colliderPose(c, t);
  const Vec3 axis = c.shape == ColliderShape::Capsule ? Vec3(p.rotation * Vec3(0, c.halfHeight, 0)) : Vec3::Zero();
  return {p.translation - axis, p.translation + axis};
}

// highest / lowest point of the union of spheres and capsules
float extremeY(const std::vector<Collider>& body, double t, bool top) {
  float y = top ? -1e30f : 1e30f;
  for (const Collider& c : body)
    for (const Vec3& e : ends(c, t)) y = top ? std::max(y, e.y() + c.radius) : std::min(y, e.y() - c.radius);
  return y;
}

MannequinPose aPose(float abduction) {
  MannequinPose p;
  p.shoulderAbduction = {abduction, abduction};
  return p;
}

TEST(MannequinBody, HeightMatchesAndStandsOnItsSoles) {
  for (float height : {1.75f, 1.52f}) {
    MannequinParams mp;
    mp.height = height;
    mp.position = Vec3(1.0f, 0.2f, -2.0f);
    mp.yaw = 0.7f;
    const std::vector<Collider> body = buildMannequin(mp, {}, 0.4f);
    ASSERT_EQ(body.size(), 18u);
    EXPECT_NEAR(extremeY(body, 0.0, true), 0.2f + height, 1e-4f);
    EXPECT_NEAR(extremeY(body, 0.0, false), 0.2f, 1e-4f);
    for (const Collider& c : body) {
      EXPECT_FLOAT_EQ(c.friction, 0.4f);
      EXPECT_EQ(c.keys.size(), 1u);
      EXPECT_GT(c.radius, 0.0f);
    }
    // shoulders as wide as asked: the outer surfaces of the upper arms hanging at the sides
    const MannequinJoints j = mannequinJoints(mp, mp.pose);
    EXPECT_NEAR((j.shoulder[kLeft] - j.shoulder[kRight]).norm() + 2.0f * mp.upperArmRadius * height,
                mp.shoulderWidth * height, 1e-4f);
  }
}

TEST(MannequinBody, LeftAndRightAreMirrorImages) {
  MannequinParams mp;
  mp.pose = aPose(0.4f);
  mp.pose.elbowFlexion = {0.3f, 0.3f};
  mp.pose.hipFlexion = {0.2f, 0.2f};
  mp.pose.kneeFlexion = {0.5f, 0.5f};
  const std::vector<Collider> body = buildMannequin(mp, {}, 0.5f);
  for (const Collider& c : body) {
    const std::string& n = c.name;
    if (n.size() < 2 || n.substr(n.size() - 2) != "_l") continue;
    const Collider& r = part(body, n.substr(10, n.size() - 12) + "_r");
    const Vec3 a = colliderPose(c, 0.0).translation, b = colliderPose(r, 0.0).translation;
    EXPECT_NEAR(a.x(), -b.x(), 1e-5f) << n;
    EXPECT_NEAR(a.y(), b.y(), 1e-5f) << n;
    EXPECT_NEAR(a.z(), b.z(), 1e-5f) << n;
    EXPECT_GT(a.x(), 0.0f) << n << " (the left side is +x)";
  }
  // the body's distance field is mirror symmetric
  for (float y = 0.05f; y < 1.75f; y += 0.1f)
    for (float x = 0.02f; x < 0.6f; x += 0.07f) {
      const Vec3 p(x, y, 0.03f), q(-x, y, 0.03f);
      EXPECT_NEAR(bodyDistance(body, 0.0, p, nullptr), bodyDistance(body, 0.0, q, nullptr), 1e-5f);
    }
}

TEST(MannequinBody, HeadAboveTheShouldersAndPartsJoined) {
  MannequinParams mp;
  mp.pose = aPose(0.6f);
  mp.pose.shoulderFlexion = {0.3f, -0.2f};
  mp.pose.elbowFlexion = {1.2f, 0.4f};
  mp.pose.hipFlexion = {0.8f, -0.1f};
  mp.pose.kneeFlexion = {1.0f, 0.2f};
  const std::vector<Collider> body = buildMannequin(mp, {}, 0.5f);
  const MannequinJoints j = mannequinJoints(mp, mp.pose);
  const Collider& head = part(body, "head");
  const float headBottom = colliderPose(head, 0.0).translation.y() - head.radius;
  EXPECT_GT(headBottom, j.shoulder[kLeft].y());
  EXPECT_GT(headBottom, part(body, "yoke").keys[0].translation.y() + part(body, "yoke").radius);
  EXPECT_NEAR(colliderPose(head, 0.0).translation.x(), 0.0f, 1e-6f);
  // each limb segment runs from its joint to the next: the chain is unbroken in any pose
  const std::pair<const char*, std::array<Vec3, 2>> segments[] = {
      {"upper_arm_l", {j.shoulder[kLeft], j.elbow[kLeft]}}, {"forearm_l", {j.elbow[kLeft], j.wrist[kLeft]}},
      {"upper_arm_r", {j.shoulder[kRight], j.elbow[kRight]}}, {"thigh_l", {j.hip[kLeft], j.knee[kLeft]}},
      {"foot_l", {j.ankle[kLeft] - 0.03f * mp.height * Vec3::UnitX().cross(j.knee[kLeft] - j.ankle[kLeft]).normalized(),
                  j.ankle[kLeft] + 0.10f * mp.height * Vec3::UnitX().cross(j.knee[kLeft] - j.ankle[kLeft]).normalized()}}};
  for (const auto& [name, joint] : segments) {
    const auto e = ends(part(body, name), 0.0);
    const float direct = (e[0] - joint[0]).norm() + (e[1] - joint[1]).norm();
    const float swapped = (e[1] - joint[0]).norm() + (e[0] - joint[1]).norm();
    EXPECT_LT(std::min(direct, swapped), 1e-4f) << name;
  }
  // the shank starts at the knee and stops short of the ankle by (shank - foot radius), on the leg
  for (int sd = 0; sd < 2; ++sd) {
    const auto e = ends(part(body, sd == kLeft ? "shank_l" : "shank_r"), 0.0);
    const Vec3 knee = j.knee[sd], ankle = j.ankle[sd];
    EXPECT_LT(std::min((e[0] - knee).norm(), (e[1] - knee).norm()), 1e-4f);
    const float shortBy = (mp.shankRadius - mp.footRadius) * mp.height;
    EXPECT_LT(std::min((e[0] - ankle).norm(), (e[1] - ankle).norm()) - shortBy, 1e-4f);
  }
  // elbow flexion bends the forearm forwards (+z), knee flexion the shank backwards
  EXPECT_GT(j.wrist[kLeft].z(), j.elbow[kLeft].z() + 0.1f);
  EXPECT_LT(j.ankle[kLeft].z(), j.knee[kLeft].z() - 0.05f);
  // the raised thigh moves the knee forwards
  EXPECT_GT(j.knee[kLeft].z(), 0.2f);
}

TEST(MannequinMotion, PoseKeysAnimateTheColliders) {
  MannequinParams mp;
  PoseKey k0, k1, k2;
  k0.time = 0.0f;
  k0.pose = aPose(0.2f);
  k1.time = 1.0f;
  k1.pose = aPose(1.4f);
  k1.pose.rootOffset = Vec3(0.0f, 0.0f, 0.5f);
  k2.time = 1.5f;
  k2.pose = k1.pose;
  k2.pose.kneeFlexion = {0.0f, 1.0f};
  const std::vector<PoseKey> keys = {k0, k1, k2};
  const std::vector<Collider> body = buildMannequin(mp, keys, 0.5f);
  for (const Collider& c : body) EXPECT_EQ(c.keys.size(), 46u) << c.name;  // 1.5 s at 30 per second, + end
  // at and between samples the hand follows the interpolated pose
  for (double t : {0.0, 0.5, 0.51, 0.987, 1.2, 2.0}) {
    const MannequinPose pose = poseAt(mp, keys, t);
    const MannequinJoints j = mannequinJoints(mp, pose);
    const auto e = ends(part(body, "forearm_l"), t);
    EXPECT_LT(std::min((e[0] - j.wrist[kLeft]).norm(), (e[1] - j.wrist[kLeft]).norm()), 3e-3f) << t;
    EXPECT_NEAR(colliderPose(part(body, "pelvis"), t).translation.z(), pose.rootOffset.z(), 1e-5f) << t;
  }
  // the raised arm moves up and out; the hand's collider velocity says so
  const ColliderPose hand = colliderPose(part(body, "hand_l"), 0.5);
  EXPECT_GT(hand.linearVelocity.y(), 0.3f);
  EXPECT_GT(hand.linearVelocity.x(), 0.1f);
  EXPECT_NEAR(hand.linearVelocity.z(), 0.5f, 1e-3f);  // the root walks 0.5 m/s
  // after 1 s only the right knee bends: the right foot rises, the left one stays
  const float leftFoot0 = colliderPose(part(body, "foot_l"), 1.0).translation.y();
  EXPECT_NEAR(colliderPose(part(body, "foot_l"), 1.5).translation.y(), leftFoot0, 1e-5f);
  EXPECT_GT(colliderPose(part(body, "foot_r"), 1.5).translation.y(), leftFoot0 + 0.1f);
  // ends held
  EXPECT_EQ(colliderPose(part(body, "head"), 3.0).linearVelocity, Vec3::Zero());
}

TEST(MannequinBody, RefusesBadParameters) {
  MannequinParams mp;
  mp.height = -1.0f;
  EXPECT_THROW(buildMannequin(mp, {}, 0.5f), Error);
  mp = MannequinParams{};
  mp.thighRadius = 0.0f;
  EXPECT_THROW(buildMannequin(mp, {}, 0.5f), Error);
  PoseKey a, b;
  a.time = 1.0f;
  b.time = 0.5f;
  try {
    buildMannequin(MannequinParams{}, {a, b}, 0.5f, "mannequin", "scene.json");
    FAIL() << "keys out of order were accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("scene.json"), std::string::npos);
  }
}

}  // namespace
}  // namespace soak
