// exact signed distance to a closed triangle mesh, the pieces shared by the static mesh collider's
// grid (mesh_sdf.cpp) and the animated mesh sequence (mesh_sequence.cpp): the closest point on a
// triangle with the feature it lies on, the closed-surface check, and the angle-weighted
// pseudo-normals (Baerentzen & Aanaes 2005) whose sign is exact on a closed oriented mesh
#pragma once
#include <soak/math.hpp>

#include <array>
#include <string>
#include <vector>

namespace soak {

// closest-point features of a triangle: the face, edge k (vertices k, k+1) or vertex k
enum TriangleFeature { kFace = 0, kEdge0 = 1, kVertex0 = 4 };

// closest point on triangle (a, b, c) to p (Ericson, Real-Time Collision Detection 5.1.5), with the
// feature it lies on
Vec3d closestOnTriangle(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c, int* feature);

// twin[t][k]: the triangle across edge k (vertices k, k+1) of triangle t. Throws soak::Error naming
// `source` unless the mesh is closed and consistently oriented: every directed edge (a, b) has
// exactly one twin (b, a)
std::vector<std::array<int, 3>> twinTriangles(const std::vector<std::array<int, 3>>& tri, const std::string& source);

// the volume the triangles enclose (divergence theorem): negative when their normals point inwards
double signedVolume(const std::vector<Vec3d>& x, const std::vector<std::array<int, 3>>& tri);

// the pseudo-normals of every feature of a closed mesh at positions x
struct FeatureNormals {
  std::vector<Vec3d> face;                  // unit; zero for a degenerate (zero-area) triangle
  std::vector<std::array<Vec3d, 3>> edge;   // per triangle edge k (k, k+1): the sum of both faces
  std::vector<Vec3d> vertex;                // the angle-weighted sum of the faces around
};
// twins from twinTriangles (found by their vertices, so flipping every triangle does not disturb them)
void featureNormals(const std::vector<Vec3d>& x, const std::vector<std::array<int, 3>>& tri,
                    const std::vector<std::array<int, 3>>& twin, FeatureNormals& out);

// the nearest point of triangle t to p so far: its squared distance and the sign (+1 outside, -1
// inside) from the pseudo-normal of the feature it lies on
struct NearestOnMesh {
  double dist2 = 1.0e300;
  double sign = 1.0;
  int triangle = -1;
  Vec3d point{0, 0, 0};         // the nearest point
  Vec3d pseudoNormal{0, 0, 0};  // of the feature it lies on (not normalised)
};
// tests triangle t against the nearest so far and keeps the nearer
void nearerTriangle(const std::vector<Vec3d>& x, const std::vector<std::array<int, 3>>& tri,
                    const FeatureNormals& normals, int t, const Vec3d& p, NearestOnMesh& best);

}  // namespace soak
