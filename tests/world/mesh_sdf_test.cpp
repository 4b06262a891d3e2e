// mesh colliders: the grid of a closed cube / sphere matches the analytic distance within a cell,
// node values are the exact distance to the mesh, signs inside / outside, open meshes refused
#include "world/colliders.hpp"
#include "world/mesh_sdf.hpp"

#include "support/colliders.hpp"

#include <soak/error.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>

namespace soak {
namespace {

using testing::cubeMesh;
using testing::icosphere;
using testing::writeObj;

float boxDistance(const Vec3& p, float h) {
  const Vec3 q = p.cwiseAbs() - Vec3::Constant(h);
  return q.cwiseMax(0.0f).norm() + std::min(q.maxCoeff(), 0.0f);
}

TEST(MeshSdfGrid, CubeObjMatchesTheAnalyticBoxDistanceWithinACell) {
  const std::string path = writeObj(cubeMesh(0.3f), "soak_mesh_sdf_cube.obj");
  const float h = 0.02f;
  const Collider c = loadMeshCollider("cube", path, h, 0.1f);
  ASSERT_EQ(c.shape, ColliderShape::Mesh);
  ASSERT_TRUE(c.sdf);
  const ColliderPose pose = colliderPose(c, 0.0);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-0.4f, 0.4f);
  int inside = 0;
  for (int k = 0; k < 2000; ++k) {
    const Vec3 p(u(rng), u(rng), u(rng));
    Vec3 n;
    const float d = colliderDistance(c, pose, p, &n);
    const float exact = boxDistance(p, 0.3f);
    EXPECT_NEAR(d, exact, h) << p.transpose();
    if (std::fabs(exact) > h) EXPECT_EQ(d < 0.0f, exact < 0.0f) << p.transpose();
    EXPECT_NEAR(n.norm(), 1.0f, 1e-4f);
    inside += exact < 0.0f;
  }
  EXPECT_GT(inside, 500);
  // on a face's axis the normal is the face normal
  Vec3 n;
  colliderDistance(c, pose, Vec3(0.35f, 0.01f, -0.02f), &n);
  EXPECT_GT(n.x(), 0.99f);
  colliderDistance(c, pose, Vec3(0.02f, -0.25f, 0.01f), &n);
  EXPECT_LT(n.y(), -0.99f);
}

TEST(MeshSdfGrid, NodeValuesAreTheExactDistanceToTheMesh) {
  const TriangleMesh sphere = icosphere(0.25f, 2);
  const SdfGrid g = buildSdfGrid(sphere, 0.025f, 0.08f, "sphere");
  for (int k = 0; k < g.dims[2]; k += 3)
    for (int j = 0; j < g.dims[1]; j += 2)
      for (int i = 0; i < g.dims[0]; ++i) {
        const Vec3d p = g.origin.cast<double>() + g.cellSize * Vec3d(i, j, k);
        const double exact = exactMeshDistance(sphere, p);
        ASSERT_NEAR(g.value[i + g.dims[0] * (j + g.dims[1] * k)], exact, 1e-5) << p.transpose();
      }
}

TEST(MeshSdfGrid, SphereMatchesTheAnalyticDistanceAndNormal) {
  const float r = 0.25f, h = 0.02f;
  const TriangleMesh sphere = icosphere(r, 3);  // chords sag by under 2 mm at this level
  Collider c = makeMeshCollider("ball", sphere, h, 0.1f, "ball");
  // moved by a key: the distance follows the pose
  c.keys[0].translation = Vec3(1.0f, 2.0f, -0.5f);
  const ColliderPose pose = colliderPose(c, 0.0);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-0.33f, 0.33f);
  for (int k = 0; k < 2000; ++k) {
    const Vec3 local(u(rng), u(rng), u(rng));
    const Vec3 p = local + c.keys[0].translation;
    Vec3 n;
    const float d = colliderDistance(c, pose, p, &n);
    const float exact = local.norm() - r;
    EXPECT_NEAR(d, exact, h) << local.transpose();
    if (std::fabs(exact) > h) EXPECT_EQ(d < 0.0f, exact < 0.0f);
    if (std::fabs(exact) > 2.0f * h && local.norm() > 3.0f * h) EXPECT_GT(n.dot(local.normalized()), 0.95f);
  }
  EXPECT_LT(colliderDistance(c, pose, c.keys[0].translation, nullptr), -r + h);
}

TEST(MeshSdfGrid, InwardWoundMeshGivesTheSameSigns) {
  TriangleMesh in = cubeMesh(0.3f);
  for (auto& t : in.triangles) std::swap(t[1], t[2]);
  const SdfGrid a = buildSdfGrid(cubeMesh(0.3f), 0.05f, 0.1f, "cube"), b = buildSdfGrid(in, 0.05f, 0.1f, "cube");
  ASSERT_EQ(a.value.size(), b.value.size());
  for (size_t k = 0; k < a.value.size(); ++k) EXPECT_FLOAT_EQ(a.value[k], b.value[k]);
  EXPECT_LT(sampleSdf(a, Vec3::Zero(), nullptr), -0.29f);
}

TEST(MeshSdfGrid, OpenMeshIsRefusedNamingTheFile) {
  TriangleMesh open = cubeMesh(0.3f);
  open.triangles.pop_back();
  const std::string path = writeObj(open, "soak_mesh_sdf_open.obj");
  try {
    loadMeshCollider("open", path, 0.05f, 0.1f);
    FAIL() << "an open mesh was accepted";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find("closed"), std::string::npos) << msg;
  }
  // two triangles running the same way along an edge: not orientable as given
  TriangleMesh flipped = cubeMesh(0.3f);
  std::swap(flipped.triangles[0][1], flipped.triangles[0][2]);
  EXPECT_THROW(buildSdfGrid(flipped, 0.05f, 0.1f, "flipped.obj"), Error);
}

TEST(MeshSdfGrid, RefusesBadResolution) {
  EXPECT_THROW(buildSdfGrid(cubeMesh(0.3f), 0.0f, 0.1f, "cube.obj"), Error);
  EXPECT_THROW(buildSdfGrid(cubeMesh(0.3f), 1e-4f, 0.1f, "cube.obj"), Error);  // 8000^3 nodes
}

}  // namespace
}  // namespace soak
