// mesh colliders: a closed triangle mesh (any OBJ) turned into a signed distance grid, sampled
// trilinearly with its gradient as the contact normal (ColliderShape::Mesh in colliders.cpp)
#pragma once
#include <soak/model.hpp>

#include "world/mesh.hpp"

#include <array>
#include <string>
#include <vector>

namespace soak {

// signed distances (m, negative inside) on the nodes of a regular grid; node (i, j, k) sits at
// origin + cellSize (i, j, k) and its value is value[i + nx (j + ny k)]
struct SdfGrid {
  Vec3 origin{0, 0, 0};          // m, node (0, 0, 0)
  float cellSize = 0.01f;        // m
  std::array<int, 3> dims{0, 0, 0};
  std::vector<float> value;      // m
};

// most nodes a grid may have (256^3); a finer request is refused
constexpr int64_t kMaxSdfNodes = int64_t(256) * 256 * 256;

// the exact signed distance to the nearest triangle on every node of a grid covering the mesh's
// bounding box plus `padding` (m) with spacing `cellSize` (m). The sign comes from the angle-weighted
// pseudo-normal of the nearest feature (face, edge or vertex; Baerentzen & Aanaes 2005), exact for a
// closed, consistently oriented mesh; an inward-oriented mesh is flipped first. Throws soak::Error
// naming `source` when the mesh is empty, has a bad index, a degenerate triangle, is not closed
// (an edge not shared by exactly two triangles of opposite winding), or the grid would be too large.
SdfGrid buildSdfGrid(const TriangleMesh& mesh, float cellSize, float padding, const std::string& source);

// trilinear interpolation of the grid at p (local frame); `gradient` (may be null) gets the unit
// gradient of the interpolant, the outward normal. Outside the grid the distance is the value at the
// nearest grid point plus the distance to it (an upper bound that grows correctly far away).
float sampleSdf(const SdfGrid& grid, const Vec3& p, Vec3* gradient);

// exact signed distance from p to a closed mesh by brute force over its triangles (for tests and
// checks; O(triangles)). Same sign rule as buildSdfGrid; the mesh must already be closed.
double exactMeshDistance(const TriangleMesh& mesh, const Vec3d& p);

// a ColliderShape::Mesh collider for a closed mesh given in its local frame (one key at rest)
Collider makeMeshCollider(const std::string& name, const TriangleMesh& mesh, float cellSize, float padding,
                          const std::string& source);

// reads an OBJ file and makes its mesh collider; errors name the file
Collider loadMeshCollider(const std::string& name, const std::string& path, float cellSize, float padding);

}  // namespace soak
