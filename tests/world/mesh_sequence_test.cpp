// animated mesh colliders (world/mesh_sequence.hpp): the distance to the interpolated surface is the
// exact one, the surface moves with its vertices, frames play at their rate and rest at the ends,
// files are found by their pattern, and a bad sequence is refused naming the file
#include "world/mesh_sequence.hpp"

#include "world/colliders.hpp"
#include "world/mesh_sdf.hpp"

#include "support/colliders.hpp"

#include <soak/error.hpp>

#include <gtest/gtest.h>

#include <fmt/format.h>

#include <filesystem>
#include <random>

namespace soak {
namespace {

using testing::cubeMesh;
using testing::expectVec;
using testing::icosphere;
using testing::writeObj;

TriangleMesh moved(TriangleMesh m, const Vec3& by) {
  for (Vec3& x : m.vertices) x += by;
  return m;
}

// the signed distance to an axis-aligned box of half size h centred at c
float boxDistance(const Vec3& p, const Vec3& c, float h) {
  const Vec3 q = (p - c).cwiseAbs() - Vec3::Constant(h);
  return q.cwiseMax(0.0f).norm() + std::min(q.maxCoeff(), 0.0f);
}

// a MeshSequence collider of `frames` at `fps` from t = start
Collider sequenceCollider(const std::vector<TriangleMesh>& frames, double fps, double start = 0.0) {
  Collider c = testing::makeCollider(ColliderShape::MeshSequence);
  c.sequence = std::make_shared<const MeshSequence>(makeMeshSequence(frames, {}, fps, start));
  return c;
}

// a cube of half size 0.1 sliding 0.2 m along x from frame 0 to frame 1 (fps 10: at 2 m/s), then
// resting: between frames the distance is the box's at the interpolated centre and the surface moves
// at 2 m/s; before the first and after the last frame it rests
TEST(MeshSequence, FramesPlayAtTheirRateInterpolatedAndRestAtTheEnds) {
  const Collider c = sequenceCollider({cubeMesh(0.1f), moved(cubeMesh(0.1f), Vec3(0.2f, 0, 0))}, 10.0, 0.5);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-0.4f, 0.5f);
  for (double t : {0.0, 0.5, 0.525, 0.55, 0.599, 0.61, 2.0}) {
    const double s = std::clamp((t - 0.5) * 10.0, 0.0, 1.0);
    const Vec3 centre(0.2f * float(s), 0, 0);
    const ColliderPose pose = colliderPose(c, t);
    const bool playing = t >= 0.5 && t < 0.6;
    EXPECT_EQ(pose.moving(), playing) << "t " << t;
    for (int k = 0; k < 50; ++k) {
      const Vec3 p(u(rng), u(rng), u(rng));
      Vec3 n;
      EXPECT_NEAR(colliderDistance(c, pose, p, &n), boxDistance(p, centre, 0.1f), 2e-6f) << "t " << t;
      EXPECT_NEAR(n.norm(), 1.0f, 1e-5f);
      expectVec(colliderVelocity(c, pose, p), playing ? Vec3(2.0f, 0, 0) : Vec3::Zero(), 1e-4f);
    }
  }
}

// an icosphere's exact distance: the tree's nearest triangle and the pseudo-normal sign agree with
// the brute force over every triangle (mesh_sdf.hpp exactMeshDistance) at points in and out
TEST(MeshSequence, DistanceEqualsTheBruteForceOverEveryTriangle) {
  const TriangleMesh sphere = icosphere(0.3f, 2);
  const Collider c = sequenceCollider({sphere}, 24.0);
  const ColliderPose pose = colliderPose(c, 0.0);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.5f, 0.5f);
  int inside = 0;
  for (int k = 0; k < 300; ++k) {
    const Vec3 p(u(rng), u(rng), u(rng));
    const float d = colliderDistance(c, pose, p, nullptr);
    EXPECT_NEAR(d, exactMeshDistance(sphere, p.cast<double>()), 1e-6f) << p.transpose();
    inside += d < 0.0f;
  }
  EXPECT_GT(inside, 20);  // both signs were tried
}

// a sphere growing from 0.2 to 0.3 m in one frame at 10 fps: its surface moves out at 1 m/s, so a
// point outside it sees the surface come towards it at 1 m/s along the normal
TEST(MeshSequence, AGrowingSphereMovesItsSurfaceAlongTheNormal) {
  const TriangleMesh small = icosphere(0.2f, 3), large = icosphere(0.3f, 3);
  const Collider c = sequenceCollider({small, large}, 10.0);
  const ColliderPose pose = colliderPose(c, 0.05);
  for (const Vec3& dir : {Vec3(1, 0, 0), Vec3(0, -1, 0), Vec3(1, 1, 1).normalized(), Vec3(0.3f, -0.8f, 0.2f).normalized()}) {
    const Vec3 p = 0.5f * dir;
    Vec3 n;
    const float d = colliderDistance(c, pose, p, &n);
    EXPECT_NEAR(d, 0.25f, 2e-3f) << dir.transpose();  // the chords of level 3 sag by under 2 mm
    EXPECT_GT(n.dot(dir), 0.999f);
    const Vec3 v = colliderVelocity(c, pose, p);
    EXPECT_NEAR(v.dot(n), 1.0f, 1e-2f) << dir.transpose();
    // a point inside a face moves as the blend of its corners' radial velocities: tangentially by
    // at most the angle between them (an edge of level 3 spans 0.13 rad)
    EXPECT_LT((v - v.dot(n) * n).norm(), 0.13f) << dir.transpose();
    EXPECT_LT(colliderDistance(c, pose, 0.2f * dir, nullptr), -0.04f);  // inside
  }
}

// the collider's keys move the sequence rigidly on top: a pose turned 90 degrees about y and lifted
// 1 m carries the sliding cube's distance with it, and its velocity adds the rigid one
TEST(MeshSequence, KeysMoveTheSequenceRigidlyOnTop) {
  Collider c = sequenceCollider({cubeMesh(0.1f), moved(cubeMesh(0.1f), Vec3(0.2f, 0, 0))}, 10.0);
  c.keys = {Keyframe{0.0f, Vec3(0, 1, 0), Quat(Eigen::AngleAxisf(0.5f * float(M_PI), Vec3(0, 1, 0)))},
            Keyframe{1.0f, Vec3(0, 2, 0), Quat(Eigen::AngleAxisf(0.5f * float(M_PI), Vec3(0, 1, 0)))}};
  const ColliderPose pose = colliderPose(c, 0.05);
  // the local +x slide is world -z after the turn; the centre at local (0.1, 0, 0), world (0, 1.05, -0.1)
  const Vec3 centre(0, 1.05f, -0.1f);
  for (const Vec3& p : {Vec3(0.3f, 1.05f, -0.1f), Vec3(0, 1.05f, -0.5f), Vec3(0.05f, 1.1f, -0.12f)}) {
    EXPECT_NEAR(colliderDistance(c, pose, p, nullptr), boxDistance(p, centre, 0.1f), 1e-5f) << p.transpose();
    expectVec(colliderVelocity(c, pose, p), Vec3(0, 1, -2), 1e-4f);
  }
  EXPECT_GE(colliderSpeedBound(c, pose, centre), colliderVelocity(c, pose, centre).norm());
  // the cheap bound never exceeds the distance, and the box holds the cube
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-0.5f, 0.5f);
  std::vector<float> x, bound(200, 1e30f);
  for (int k = 0; k < 200; ++k)
    for (int a = 0; a < 3; ++a) x.push_back(centre[a] + u(rng));
  colliderDistanceBounds(c, pose, x.data(), 200, bound.data());
  for (int k = 0; k < 200; ++k) {
    const Vec3 p(x[3 * k], x[3 * k + 1], x[3 * k + 2]);
    EXPECT_LE(bound[k], colliderDistance(c, pose, p, nullptr) + 1e-6f) << p.transpose();
  }
  Vec3 lo, hi;
  ASSERT_TRUE(colliderBox(c, pose, &lo, &hi));
  expectVec(lo, centre - Vec3::Constant(0.1f), 1e-5f);
  expectVec(hi, centre + Vec3::Constant(0.1f), 1e-5f);
}

// pushOutOf hands back the surface velocity from its own search: the same as colliderVelocity at the
// pushed point, with the frames sliding the cube and the keys turning it (the rigid field moves with x)
TEST(MeshSequence, APushGivesTheSurfaceVelocityAtThePushedPoint) {
  Collider c = sequenceCollider({cubeMesh(0.1f), moved(cubeMesh(0.1f), Vec3(0.2f, 0, 0))}, 10.0);
  c.keys = {Keyframe{0.0f, Vec3(0, 1, 0), Quat::Identity()},
            Keyframe{1.0f, Vec3(0, 1, 0), Quat(Eigen::AngleAxisf(0.5f * float(M_PI), Vec3(0, 1, 0)))}};
  const ColliderPose pose = colliderPose(c, 0.05);
  ASSERT_GT(pose.angularVelocity.norm(), 1.0f);
  for (const Vec3& start : {Vec3(0.1f, 1.11f, 0.02f), Vec3(0.05f, 1.05f, 0.0f), Vec3(0.22f, 1.0f, 0.03f)}) {
    Vec3 x = start, n, v;
    ASSERT_TRUE(pushOutOf(c, pose, 0.02f, x, &n, &v)) << start.transpose();
    EXPECT_NEAR(colliderDistance(c, pose, x, nullptr), 0.02f, 1e-5f);
    expectVec(v, colliderVelocity(c, pose, x), 1e-5f);
  }
}

// a mesh wound inwards is turned outwards (by frame 0's volume); a triangle that collapses in a
// later frame is skipped (its neighbours hold its points) and the distance stays exact
TEST(MeshSequence, InwardWindingIsTurnedAndACollapsedTriangleIsSkipped) {
  TriangleMesh inward = cubeMesh(0.1f);
  for (auto& t : inward.triangles) std::swap(t[1], t[2]);
  TriangleMesh squashed = icosphere(0.3f, 1);
  const Collider c = sequenceCollider({inward, moved(inward, Vec3(0.1f, 0, 0))}, 24.0);  // later frames as wound
  EXPECT_NEAR(colliderDistance(c, colliderPose(c, 0.0), Vec3(0, 0.3f, 0), nullptr), 0.2f, 1e-6f);
  EXPECT_NEAR(colliderDistance(c, colliderPose(c, 0.0), Vec3::Zero(), nullptr), -0.1f, 1e-6f);
  // frame 1 moves one vertex of the sphere onto its neighbour, collapsing the two triangles between them
  TriangleMesh collapsed = squashed;
  const auto& t0 = squashed.triangles[0];
  collapsed.vertices[t0[0]] = collapsed.vertices[t0[1]];
  const Collider s = sequenceCollider({squashed, collapsed}, 1.0);
  const ColliderPose end = colliderPose(s, 5.0);
  for (const Vec3& p : {Vec3(0.5f, 0.1f, 0), Vec3(0, 0, 0), Vec3(-0.1f, 0.6f, 0.2f), Vec3(1.5f * collapsed.vertices[t0[1]])}) {
    const float d = colliderDistance(s, end, p, nullptr);
    double best = 1e30;
    // the brute-force nearest point of the triangles that still have an area
    for (const auto& t : collapsed.triangles) {
      const Vec3 a = collapsed.vertices[t[0]], b = collapsed.vertices[t[1]], cc = collapsed.vertices[t[2]];
      if ((b - a).cross(cc - a).norm() == 0.0f) continue;
      int feature = 0;
      best = std::min(best, (p.cast<double>() - closestOnTriangle(p.cast<double>(), a.cast<double>(), b.cast<double>(),
                                                                  cc.cast<double>(), &feature))
                                .norm());
    }
    EXPECT_NEAR(std::abs(d), best, 1e-6f) << p.transpose();
    EXPECT_EQ(d < 0.0f, p.norm() < 0.2f) << p.transpose();
  }
}

// frames of another topology, a non-finite position, an open first frame, fps <= 0: refused naming
// the frame's file
TEST(MeshSequence, ABadSequenceIsRefusedNamingTheFile) {
  const TriangleMesh cube = cubeMesh(0.1f);
  const auto refuses = [](const std::vector<TriangleMesh>& frames, double fps, const std::string& expected) {
    try {
      makeMeshSequence(frames, {"a_0001.obj", "a_0002.obj"}, fps, 0.0);
      ADD_FAILURE() << "accepted; expected " << expected;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  TriangleMesh more = cube;
  more.vertices.push_back(Vec3(1, 1, 1));
  refuses({cube, more}, 24.0, "a_0002.obj: at mesh sequence, frame 1: expected 8 vertices as in the first frame, got 9");
  TriangleMesh rewired = cube;
  std::swap(rewired.triangles[3][0], rewired.triangles[3][1]);
  refuses({cube, rewired}, 24.0, "a_0002.obj: at mesh sequence, frame 1, triangle 3: expected vertices");
  TriangleMesh nan = cube;
  nan.vertices[2].x() = std::nanf("");
  refuses({cube, nan}, 24.0, "a_0002.obj: at mesh sequence, frame 1, vertex 3: position is not finite");
  TriangleMesh open = cube;
  open.triangles.pop_back();
  refuses({open}, 24.0, "a_0001.obj: at mesh collider, edge");
  refuses({cube}, 0.0, "expected fps > 0");
}

// files named by the pattern: the lowest frame found, consecutive up to the first missing one; a
// range must be complete; the padding of the run of '#' is kept apart from other numbers
TEST(MeshSequence, FilesAreFoundByTheirPattern) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "soak_mesh_sequence_files";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const TriangleMesh cube = cubeMesh(0.1f);
  for (int f : {3, 4, 5, 7}) writeObj(moved(cube, Vec3(0.01f * f, 0, 0)), "soak_mesh_sequence_files/walk_" + fmt::format("{:04d}", f) + ".obj");
  writeObj(cube, "soak_mesh_sequence_files/walk_1.obj");  // not "####"-padded: not a frame
  const std::string pattern = (dir / "walk_####.obj").string();
  int first = -1;
  const std::vector<std::string> files = meshSequenceFiles(pattern, -1, -1, &first);
  EXPECT_EQ(first, 3);
  ASSERT_EQ(files.size(), 3u);
  EXPECT_EQ(files[2], (dir / "walk_0005.obj").string());
  EXPECT_EQ(meshSequenceFiles(pattern, 7, -1, nullptr).size(), 1u);
  const auto refuses = [&](const std::string& pat, int a, int b, const std::string& expected) {
    try {
      meshSequenceFiles(pat, a, b, nullptr);
      ADD_FAILURE() << "accepted; expected " << expected;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  refuses(pattern, 3, 7, "walk_0006.obj: at mesh sequence: expected frame 6 of the sequence, the file does not exist");
  refuses((dir / "walk.obj").string(), -1, -1, "expected one run of '#'");
  refuses((dir / "run_##.obj").string(), -1, -1, "found none (the first would be");
  // loaded with a scale: the frames' positions in metres, and the motion between them
  const MeshSequence s = loadMeshSequence(files, 25.0, 0.0, 2.0f);
  EXPECT_EQ(s.frameCount, 3);
  expectVec(s.positions[s.vertexCount + 7], 2.0f * (cube.vertices[7] + Vec3(0.04f, 0, 0)), 1e-6f);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace soak
