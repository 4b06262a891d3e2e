// helpers of the collider tests: a collider of one shape at the origin, a vector comparison, a cube mesh
#pragma once
#include <soak/model.hpp>

#include "world/mesh.hpp"

#include <gtest/gtest.h>

namespace soak::testing {

// a collider of `shape` with one keyframe at the origin and the struct's defaults
inline Collider makeCollider(ColliderShape shape) {
  Collider c;
  c.shape = shape;
  c.keys.push_back(Keyframe{});
  return c;
}

inline void expectVec(const Vec3& a, const Vec3& b, float tol) {
  EXPECT_NEAR(a.x(), b.x(), tol) << "got " << a.transpose() << " expected " << b.transpose();
  EXPECT_NEAR(a.y(), b.y(), tol) << "got " << a.transpose() << " expected " << b.transpose();
  EXPECT_NEAR(a.z(), b.z(), tol) << "got " << a.transpose() << " expected " << b.transpose();
}

// a closed cube of half size h centred at the origin, outward winding
inline TriangleMesh cubeMesh(float h) {
  TriangleMesh m;
  for (int k = 0; k < 8; ++k) m.vertices.push_back(Vec3(k & 1 ? h : -h, k & 2 ? h : -h, k & 4 ? h : -h));
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

}  // namespace soak::testing
