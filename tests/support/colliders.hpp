// helpers of the collider tests: a collider of one shape at the origin, a vector comparison, a cube mesh
#pragma once
#include <soak/model.hpp>

#include "world/mesh.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

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

// icosphere of radius r: an icosahedron subdivided `levels` times, vertices on the sphere, outward
inline TriangleMesh icosphere(float r, int levels) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  TriangleMesh m;
  m.vertices = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  m.triangles = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      m.vertices.push_back(0.5f * (m.vertices[a] + m.vertices[b]));
      return mid[key] = static_cast<int>(m.vertices.size()) - 1;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& tr : m.triangles) {
      const int a = midpoint(tr[0], tr[1]), b = midpoint(tr[1], tr[2]), c = midpoint(tr[2], tr[0]);
      next.push_back({tr[0], a, c});
      next.push_back({tr[1], b, a});
      next.push_back({tr[2], c, b});
      next.push_back({a, b, c});
    }
    m.triangles = next;
  }
  for (Vec3& v : m.vertices) v = r * v.normalized();
  return m;
}

// writes the mesh as OBJ to `name` under the temporary directory (its folder must exist); its path
inline std::string writeObj(const TriangleMesh& m, const std::string& name) {
  const std::string path = (std::filesystem::temp_directory_path() / name).string();
  std::ofstream f(path);
  f.precision(9);
  for (const Vec3& v : m.vertices) f << "v " << v.x() << " " << v.y() << " " << v.z() << "\n";
  for (const auto& t : m.triangles) f << "f " << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << "\n";
  return path;
}

}  // namespace soak::testing
