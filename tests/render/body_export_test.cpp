// the mannequin as an OBJ sequence (soak/body_export.hpp): one closed topology through a motion, every
// frame on that frame's smooth skin, and played back as a mesh sequence it is the same collider as
// the body it came from (up to the mesh's chords)
#include <soak/body_export.hpp>

#include <soak/error.hpp>

#include "world/colliders.hpp"
#include "world/mannequin.hpp"
#include "world/mesh_sequence.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace soak {
namespace {

constexpr float kDeg = float(M_PI) / 180.0f;

// a mannequin raising its arms from 45 to 80 degrees and bending its elbows over 1 s
Collider raisingArms() {
  PoseKey a, b;
  a.pose.shoulderAbduction = {45 * kDeg, 45 * kDeg};
  b.time = 1.0f;
  b.pose.shoulderAbduction = {80 * kDeg, 80 * kDeg};
  b.pose.elbowFlexion = {40 * kDeg, 40 * kDeg};
  const std::vector<Collider> body = mannequinColliders(MannequinParams{}, {a, b}, 0.5f, "body", "test");
  return body.at(0);
}

TEST(BodyExport, FramesShareOneClosedTopologyOnEachFramesSkin) {
  const Collider body = raisingArms();
  const std::vector<double> times = {0.0, 0.5, 1.0};
  const std::vector<TriangleMesh> frames = skinnedBodyFrames(body, times, 0.02f);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_GT(frames[0].vertices.size(), 3000u);
  // one topology, closed and oriented: a mesh sequence takes it
  const MeshSequence seq = makeMeshSequence(frames, {}, 2.0, 0.0);
  EXPECT_EQ(seq.frameCount, 3);
  for (size_t f = 0; f < frames.size(); ++f) {
    const ColliderPose pose = colliderPose(body, times[f]);
    float worst = 0.0f;
    for (const Vec3& x : frames[f].vertices) worst = std::max(worst, std::abs(colliderDistance(body, pose, x, nullptr)));
    EXPECT_LT(worst, 2e-4f) << "frame " << f;  // on the skin after the projection steps
  }
  // the hands moved: the skinning followed the arms
  const auto highest = [](const TriangleMesh& m) {
    float y = -1e9f;
    for (const Vec3& x : m.vertices) y = std::max(y, std::abs(x.x()) > 0.3f ? x.y() : y);
    return y;
  };
  EXPECT_GT(highest(frames[2]), highest(frames[0]) + 0.1f);
}

// played back, the sequence is the body: points of the body's skin (found by stepping along its
// normal) lie on the sequence's surface to the chords of a 2 cm mesh, at frames and between them; and the surface moves as the skin does. (The body's distance off the
// skin is a smooth minimum, not the Euclidean distance the sequence measures: only the skin compares)
TEST(BodyExport, TheSequencePlaysTheBodyItCameFrom) {
  const Collider body = raisingArms();
  std::vector<double> times;
  for (int f = 0; f <= 10; ++f) times.push_back(0.1 * f);
  Collider seq;
  seq.shape = ColliderShape::MeshSequence;
  seq.keys = {Keyframe{}};
  seq.sequence = std::make_shared<const MeshSequence>(makeMeshSequence(skinnedBodyFrames(body, times, 0.02f), {}, 10.0, 0.0));
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-0.9f, 0.9f);
  for (double t : {0.0, 0.25, 0.7}) {
    const ColliderPose pb = colliderPose(body, t), ps = colliderPose(seq, t);
    int onSkin = 0;
    float worst = 0.0f, worstSpeed = 0.0f;
    for (int k = 0; k < 4000 && onSkin < 300; ++k) {
      Vec3 p(u(rng), 0.9f + u(rng), 0.3f * u(rng)), n;
      if (std::abs(colliderDistance(body, pb, p, nullptr)) > 0.05f) continue;
      for (int step = 0; step < 8; ++step) p -= colliderDistance(body, pb, p, &n) * n;
      if (std::abs(colliderDistance(body, pb, p, nullptr)) > 1e-5f) continue;
      ++onSkin;
      worst = std::max(worst, std::abs(colliderDistance(seq, ps, p, nullptr)));
      worstSpeed = std::max(worstSpeed, (colliderVelocity(seq, ps, p) - colliderVelocity(body, pb, p)).norm());
    }
    EXPECT_GT(onSkin, 200);
    // a triangle of the 2 cm grid spans up to its diagonal, 2.8 cm: on the forearm's 2.1 cm radius its
    // sagitta is 4.7 mm (measured worst 2.2-3.4 mm)
    EXPECT_LT(worst, 4.5e-3f) << "t " << t;
    EXPECT_LT(worstSpeed, 0.08f) << "t " << t;  // measured 0.02-0.05 m/s with the arms at 0.2 m/s
  }
  // the left hand's skin moves with the hand (up and in as the arm rises and bends)
  const ColliderPose pb = colliderPose(body, 0.45), ps = colliderPose(seq, 0.45);
  // hand_l is part 7 (head, neck, chest, waist, pelvis, upper_arm_l, forearm_l, hand_l, ...)
  const Vec3 hand = pb.parts[7].translation;
  Vec3 n;
  const float d = colliderDistance(body, pb, hand + Vec3(0, 0.2f, 0), &n);
  const Vec3 onSkin = hand + Vec3(0, 0.2f, 0) - d * n;
  const Vec3 vb = colliderVelocity(body, pb, onSkin), vs = colliderVelocity(seq, ps, onSkin);
  EXPECT_GT(vb.norm(), 0.15f);
  EXPECT_LT((vs - vb).norm(), 0.15f * vb.norm()) << vs.transpose() << " against " << vb.transpose();
}

TEST(BodyExport, OnlyABodyIsSkinned) {
  Collider sphere;
  sphere.shape = ColliderShape::Sphere;
  sphere.name = "ball";
  sphere.keys = {Keyframe{}};
  EXPECT_THROW(skinnedBodyFrames(sphere, {0.0}, 0.02f), Error);
}

}  // namespace
}  // namespace soak
