// triangle meshes as every solver and the scene loader see them: OBJ reading, generated rectangles,
// the edge list of a triangle soup, and the checks a cloth mesh must pass
#pragma once
#include <soak/math.hpp>

#include <array>
#include <string>
#include <vector>

namespace soak {

// a triangle mesh as read from OBJ or generated; positions in metres
struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
};

// reads an OBJ file (triangulating polygons); throws soak::Error naming the file on failure, and
// refuses a file larger than kMaxObjBytes before reading it
inline constexpr size_t kMaxObjBytes = size_t(1) << 30;
TriangleMesh loadObjMesh(const std::string& path);
// the same from OBJ text; `source` names it in errors
TriangleMesh parseObjMesh(const std::string& text, const std::string& source);
// checks the numbers of OBJ text strictly before tinyobjloader, which reads "nan" or "abc" as 0:
// every v, vn and vt line holds only finite numbers (v: 3, 4 with a weight or 6 with a colour), every f line at least
// 3 vertices of non-zero integer indices (i, i/j, i//k, i/j/k). Throws soak::Error
// "<source>: at line N: expected ..., got ..."
void checkObjText(const std::string& text, const std::string& source);

// a rectangle of size (width x height) m with (resX x resY) vertices, centred at `center`, lying in
// the plane spanned by unit axes `axisU` (width) and `axisV` (height); alternating diagonals
TriangleMesh makeRectangle(const Vec3& center, const Vec3& axisU, const Vec3& axisV, float width, float height,
                           int resX, int resY);

// one directed edge of a triangle: vertices (a, b), its triangle, and the triangle's third vertex
struct EdgeRef {
  int lo, hi;  // sorted vertex pair, the key
  int a, b;    // direction in the triangle's winding
  int opposite;
  int triangle;
};

// every directed edge of the triangles, sorted by (vertex pair, triangle): the copies of one edge are
// adjacent, and every later choice is independent of hash or insertion order
std::vector<EdgeRef> collectEdges(const std::vector<std::array<int, 3>>& triangles);

// throws soak::Error (naming `source` and cloth `name`) when the mesh has no triangles, a vertex is not
// finite, an index is out of range, a triangle is degenerate, an edge is shared by more than two
// triangles or a pinned vertex does not exist
void validateClothMesh(const std::string& name, const TriangleMesh& mesh, const std::vector<int>& pinned,
                       const std::string& source);

}  // namespace soak
