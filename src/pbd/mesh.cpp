// cloth meshes: OBJ loading, generated rectangles, and turning a mesh into model data (rest state,
// adjacency, stretch and bend constraints of Shao 2017 section 3.2, and their graph colourings).
#include <tiny_obj_loader.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <soak/error.hpp>

#include "pbd/cloth.hpp"

namespace soak {

namespace {

std::string trimmed(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
  return s;
}

// one directed edge of a triangle: vertices (a, b), its triangle, and the triangle's third vertex
struct EdgeRef {
  int lo, hi;  // sorted vertex pair, the key
  int a, b;    // direction in the triangle's winding
  int opposite;
  int triangle;
};

std::vector<EdgeRef> collectEdges(const std::vector<std::array<int, 3>>& triangles) {
  std::vector<EdgeRef> edges;
  edges.reserve(triangles.size() * 3);
  for (int t = 0; t < static_cast<int>(triangles.size()); ++t) {
    const auto& tri = triangles[t];
    for (int k = 0; k < 3; ++k) {
      const int a = tri[k], b = tri[(k + 1) % 3], c = tri[(k + 2) % 3];
      edges.push_back({std::min(a, b), std::max(a, b), a, b, c, t});
    }
  }
  // sorting by (pair, triangle) makes every later choice independent of hash or insertion order
  std::sort(edges.begin(), edges.end(), [](const EdgeRef& x, const EdgeRef& y) {
    if (x.lo != y.lo) return x.lo < y.lo;
    if (x.hi != y.hi) return x.hi < y.hi;
    return x.triangle < y.triangle;
  });
  return edges;
}

// checks a mesh before anything is appended, so a refused piece leaves the model untouched
void validateMesh(const std::string& name, const TriangleMesh& mesh, const std::vector<int>& pinned,
                  const std::string& source) {
  const std::string where = "cloth '" + name + "'";
  const int nv = static_cast<int>(mesh.vertices.size());
  if (mesh.triangles.empty()) throw errorAt(source, where, "the mesh has no triangles; expected a triangle mesh");
  for (int v = 0; v < nv; ++v)
    if (!mesh.vertices[v].allFinite())
      throw errorAt(source, where + ", vertex " + std::to_string(v), "position is not finite");
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const std::string place = where + ", triangle " + std::to_string(t);
    for (int k = 0; k < 3; ++k)
      if (tri[k] < 0 || tri[k] >= nv)
        throw errorAt(source, place,
                      "vertex index " + std::to_string(tri[k]) + " is out of range [0, " + std::to_string(nv) + ")");
    // zero area relative to the longest edge (in double); also catches repeated indices
    const Vec3d a = mesh.vertices[tri[0]].cast<double>(), b = mesh.vertices[tri[1]].cast<double>(),
                c = mesh.vertices[tri[2]].cast<double>();
    const double twiceArea = (b - a).cross(c - a).norm();
    const double longest = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    if (!(twiceArea > 1e-6 * longest) || longest == 0.0)
      throw errorAt(source, place,
                    "degenerate triangle (" + std::to_string(tri[0]) + ", " + std::to_string(tri[1]) + ", " +
                        std::to_string(tri[2]) +
                        ") has zero area (height below 1e-6 of its longest edge); expected three " +
                        "distinct, non-collinear vertices");
  }
  const std::vector<EdgeRef> edges = collectEdges(mesh.triangles);
  for (size_t s = 0; s < edges.size();) {
    size_t e = s;
    while (e < edges.size() && edges[e].lo == edges[s].lo && edges[e].hi == edges[s].hi) ++e;
    if (e - s > 2) {
      std::string tris;
      for (size_t k = s; k < e; ++k) tris += (k > s ? ", " : "") + std::to_string(edges[k].triangle);
      throw errorAt(source, where + ", edge (" + std::to_string(edges[s].lo) + ", " + std::to_string(edges[s].hi) + ")",
                    "the edge between vertices " + std::to_string(edges[s].lo) + " and " + std::to_string(edges[s].hi) +
                        " (0-based) is shared by " + std::to_string(e - s) + " triangles (" + tris +
                        "); each edge may be shared by at most two triangles (Shao 2017, section 3.2)");
    }
    s = e;
  }
  for (size_t k = 0; k < pinned.size(); ++k)
    if (pinned[k] < 0 || pinned[k] >= nv)
      throw errorAt(source, where + ", pinned vertex " + std::to_string(k),
                    "vertex index " + std::to_string(pinned[k]) + " is out of range [0, " + std::to_string(nv) + ")");
}

// greedy first-fit colouring in constraint order: the smallest colour that none of the
// constraint's particles uses yet. Deterministic because the constraint order is.
template <size_t N>
std::vector<int> greedyColors(const std::vector<std::array<int, N>>& ids, int numParticles, int& numColors) {
  std::vector<std::vector<int>> used(numParticles);  // colours already touching each particle
  std::vector<int> color(ids.size());
  std::vector<int> forbidden;
  numColors = 0;
  for (size_t k = 0; k < ids.size(); ++k) {
    forbidden.clear();
    for (int v : ids[k]) forbidden.insert(forbidden.end(), used[v].begin(), used[v].end());
    std::sort(forbidden.begin(), forbidden.end());
    int c = 0;
    for (int f : forbidden) {
      if (f == c)
        ++c;
      else if (f > c)
        break;
    }
    color[k] = c;
    numColors = std::max(numColors, c + 1);
    for (int v : ids[k]) used[v].push_back(c);
  }
  return color;
}

template <class T>
void permute(std::vector<T>& a, const std::vector<int>& order) {
  std::vector<T> out(a.size());
  for (size_t k = 0; k < order.size(); ++k) out[k] = a[order[k]];
  a.swap(out);
}

// the slab of each cloth particle: numSlabs runs of equal count along the rest shape's longest axis
std::vector<int> restSlabs(const std::vector<Vec3>& rest, int numSlabs) {
  const int n = static_cast<int>(rest.size());
  std::vector<int> slab(rest.size(), 0);
  if (n == 0) return slab;
  Vec3 lo = rest[0], hi = rest[0];
  for (const Vec3& x : rest) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  int axis = 0;
  (hi - lo).maxCoeff(&axis);
  std::vector<int> order(rest.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return rest[a][axis] < rest[b][axis]; });
  for (int k = 0; k < n; ++k) slab[order[k]] = static_cast<int>(static_cast<int64_t>(k) * numSlabs / n);
  return slab;
}

// stable reorder by (group, colour) and the blocks of the schedule (ConstraintSchedule in model.hpp)
template <size_t N>
std::vector<int> scheduleOrder(const std::vector<std::array<int, N>>& ids, const std::vector<int>& color, int numColors,
                               const std::vector<int>& slab, int numSlabs, ConstraintSchedule& schedule) {
  const int groups = 2 * numSlabs;
  std::vector<int> group(ids.size());
  for (size_t k = 0; k < ids.size(); ++k) {
    int lo = numSlabs, hi = -1;
    for (int v : ids[k]) lo = std::min(lo, slab[v]), hi = std::max(hi, slab[v]);
    group[k] = lo == hi ? lo : (hi == lo + 1 ? numSlabs + lo : groups - 1);
  }
  std::vector<int> order(ids.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int x, int y) { return std::pair(group[x], color[x]) < std::pair(group[y], color[y]); });
  schedule.numSlabs = numSlabs;
  schedule.numColors = numColors;
  schedule.blockStart.clear();
  std::vector<int> blockGroup;
  for (size_t k = 0; k < order.size(); ++k) {
    const int g = group[order[k]], c = color[order[k]];
    if (k > 0 && g == group[order[k - 1]] && c == color[order[k - 1]]) continue;
    schedule.blockStart.push_back(static_cast<int>(k));
    blockGroup.push_back(g);
  }
  schedule.blockStart.push_back(static_cast<int>(order.size()));
  // blocks come group by group: group g's are [groupBlock[g], groupBlock[g + 1])
  schedule.groupBlock.assign(static_cast<size_t>(groups) + 1, 0);
  for (int g : blockGroup) ++schedule.groupBlock[static_cast<size_t>(g) + 1];
  for (int g = 0; g < groups; ++g) schedule.groupBlock[static_cast<size_t>(g) + 1] += schedule.groupBlock[static_cast<size_t>(g)];
  return order;
}

// piece of each triangle, for the per-piece material of its constraints
std::vector<int> trianglePieces(const Model& model) {
  std::vector<int> piece(model.triangles.size(), 0);
  for (int k = 0; k < static_cast<int>(model.pieces.size()); ++k) {
    const ClothPiece& p = model.pieces[k];
    std::fill(piece.begin() + p.firstTriangle, piece.begin() + p.firstTriangle + p.triangleCount, k);
  }
  return piece;
}

// rebuilds adjacency, constraints and colourings from model.triangles over all pieces
void rebuildTopology(Model& model) {
  const int n = model.numCloth;
  const std::vector<int> triPiece = trianglePieces(model);

  // triangles around each particle (CSR, ascending triangle index)
  model.vertexTriangleStart.assign(n + 1, 0);
  for (const auto& tri : model.triangles)
    for (int v : tri) ++model.vertexTriangleStart[v + 1];
  for (int v = 0; v < n; ++v) model.vertexTriangleStart[v + 1] += model.vertexTriangleStart[v];
  model.vertexTriangles.assign(model.vertexTriangleStart[n], 0);
  {
    std::vector<int> fill(model.vertexTriangleStart.begin(), model.vertexTriangleStart.end() - 1);
    for (int t = 0; t < static_cast<int>(model.triangles.size()); ++t)
      for (int v : model.triangles[t]) model.vertexTriangles[fill[v]++] = t;
  }

  const std::vector<EdgeRef> edges = collectEdges(model.triangles);
  StretchConstraints stretch;
  BendConstraints bend;
  std::vector<std::vector<int>> ring(n);
  for (size_t s = 0; s < edges.size();) {
    size_t e = s;
    while (e < edges.size() && edges[e].lo == edges[s].lo && edges[e].hi == edges[s].hi) ++e;
    const EdgeRef& first = edges[s];
    const ClothMaterial& mat = model.pieces[triPiece[first.triangle]].material;
    ring[first.lo].push_back(first.hi);
    ring[first.hi].push_back(first.lo);
    if (model.pieces[triPiece[first.triangle]].solver == ClothSolver::Implicit) {  // springs in src/garment instead
      s = e;
      continue;
    }

    // Eq. 8: one stretch constraint per unique edge, rest length from the rest shape
    stretch.ids.push_back({first.lo, first.hi});
    stretch.restLength.push_back((model.clothRestPosition[first.lo] - model.clothRestPosition[first.hi]).norm());
    stretch.compliance.push_back(mat.stretchCompliance);

    // Eq. 9: one bend constraint per interior edge, oriented by the first triangle's winding
    if (e - s == 2) {
      const std::array<int, 4> ids{first.a, first.b, first.opposite, edges[s + 1].opposite};
      Vec3 grad[4];
      const auto& x = model.clothRestPosition;
      bend.ids.push_back(ids);
      bend.restAngle.push_back(bendConstraint(x[ids[0]], x[ids[1]], x[ids[2]], x[ids[3]], 0.0f, grad));
      bend.compliance.push_back(mat.bendCompliance);
    }
    s = e;
  }

  // 1-ring neighbours (CSR, sorted per particle)
  model.vertexNeighborStart.assign(n + 1, 0);
  model.vertexNeighbors.clear();
  for (int v = 0; v < n; ++v) {
    std::sort(ring[v].begin(), ring[v].end());
    model.vertexNeighbors.insert(model.vertexNeighbors.end(), ring[v].begin(), ring[v].end());
    model.vertexNeighborStart[v + 1] = static_cast<int>(model.vertexNeighbors.size());
  }

  // slabs of about 1500 particles, at most 8 (the solver's parallel phases, src/pbd/cloth.cpp)
  const int numSlabs = std::clamp(n / 1500, 1, 8);
  const std::vector<int> slab = restSlabs(model.clothRestPosition, numSlabs);
  int numColors = 0;
  std::vector<int> color = greedyColors(stretch.ids, n, numColors);
  std::vector<int> order = scheduleOrder(stretch.ids, color, numColors, slab, numSlabs, stretch.schedule);
  permute(stretch.ids, order);
  permute(stretch.restLength, order);
  permute(stretch.compliance, order);

  color = greedyColors(bend.ids, n, numColors);
  order = scheduleOrder(bend.ids, color, numColors, slab, numSlabs, bend.schedule);
  permute(bend.ids, order);
  permute(bend.restAngle, order);
  permute(bend.compliance, order);

  model.stretch = std::move(stretch);
  model.bend = std::move(bend);
}

}  // namespace

TriangleMesh loadObjMesh(const std::string& path) {
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  tinyobj::ObjReader reader;
  if (!reader.ParseFromFile(path, config)) {
    const std::string msg = trimmed(reader.Error());
    throw errorAt(path, "", "cannot read OBJ mesh" + (msg.empty() ? std::string() : ": " + msg));
  }
  const tinyobj::attrib_t& attrib = reader.GetAttrib();
  TriangleMesh mesh;
  const size_t nv = attrib.vertices.size() / 3;
  mesh.vertices.reserve(nv);
  for (size_t v = 0; v < nv; ++v)
    mesh.vertices.emplace_back(static_cast<float>(attrib.vertices[3 * v]),
                               static_cast<float>(attrib.vertices[3 * v + 1]),
                               static_cast<float>(attrib.vertices[3 * v + 2]));
  // vertices are kept as listed (nothing merged), so OBJ vertex k + 1 is particle k of the piece
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    size_t offset = 0;
    for (size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f) {
      const size_t count = shape.mesh.num_face_vertices[f];
      if (count == 3) {
        std::array<int, 3> tri;
        for (int k = 0; k < 3; ++k) {
          tri[k] = shape.mesh.indices[offset + k].vertex_index;
          if (tri[k] < 0 || tri[k] >= static_cast<int>(nv))
            throw errorAt(
                path, "shape '" + shape.name + "', face " + std::to_string(f),
                "vertex index " + std::to_string(tri[k] + 1) + " is out of range [1, " + std::to_string(nv) + "]");
        }
        mesh.triangles.push_back(tri);
      }
      offset += count;
    }
  }
  if (mesh.triangles.empty()) throw errorAt(path, "", "the OBJ file has no triangles; expected a triangle mesh");
  return mesh;
}

TriangleMesh makeRectangle(const Vec3& center, const Vec3& axisU, const Vec3& axisV, float width, float height,
                           int resX, int resY) {
  if (resX < 2 || resY < 2)
    throw Error("makeRectangle: resolution " + std::to_string(resX) + " x " + std::to_string(resY) +
                " must be at least 2 x 2");
  TriangleMesh mesh;
  mesh.vertices.reserve(static_cast<size_t>(resX) * resY);
  for (int j = 0; j < resY; ++j)
    for (int i = 0; i < resX; ++i) {
      const float u = static_cast<float>(i) / static_cast<float>(resX - 1) - 0.5f;
      const float v = static_cast<float>(j) / static_cast<float>(resY - 1) - 0.5f;
      mesh.vertices.push_back(center + (u * width) * axisU + (v * height) * axisV);
    }
  // winding gives every triangle the normal axisU x axisV; diagonals alternate like a checkerboard
  // so the sheet has no preferred shear direction
  mesh.triangles.reserve(static_cast<size_t>(resX - 1) * (resY - 1) * 2);
  for (int j = 0; j + 1 < resY; ++j)
    for (int i = 0; i + 1 < resX; ++i) {
      const int v00 = j * resX + i, v10 = v00 + 1, v01 = v00 + resX, v11 = v01 + 1;
      if ((i + j) % 2 == 0) {
        mesh.triangles.push_back({v00, v10, v11});
        mesh.triangles.push_back({v00, v11, v01});
      } else {
        mesh.triangles.push_back({v00, v10, v01});
        mesh.triangles.push_back({v10, v11, v01});
      }
    }
  return mesh;
}

// Cloth pieces are added before any water particle exists. The scene loader then creates one particle
// per vertex in State, in order, so particle index == piece.firstParticle + vertex index.
void addClothPiece(Model& model, const std::string& name, const TriangleMesh& mesh, const ClothMaterial& material,
                   const std::vector<int>& pinnedVertices, const std::string& source, ClothSolver solver) {
  validateMesh(name, mesh, pinnedVertices, source);

  ClothPiece piece;
  piece.name = name;
  piece.firstParticle = model.numCloth;
  piece.particleCount = static_cast<int>(mesh.vertices.size());
  piece.firstTriangle = static_cast<int>(model.triangles.size());
  piece.triangleCount = static_cast<int>(mesh.triangles.size());
  piece.material = material;
  piece.solver = solver;

  for (const auto& tri : mesh.triangles)
    model.triangles.push_back(
        {tri[0] + piece.firstParticle, tri[1] + piece.firstParticle, tri[2] + piece.firstParticle});
  model.clothRestPosition.insert(model.clothRestPosition.end(), mesh.vertices.begin(), mesh.vertices.end());
  model.clothDryMass.insert(model.clothDryMass.end(), mesh.vertices.size(), material.particleMass);
  model.clothPinned.insert(model.clothPinned.end(), mesh.vertices.size(), uint8_t{0});
  for (int v : pinnedVertices) model.clothPinned[piece.firstParticle + v] = 1;
  model.clothImplicit.insert(model.clothImplicit.end(), mesh.vertices.size(),
                             uint8_t{solver == ClothSolver::Implicit ? uint8_t{1} : uint8_t{0}});
  model.numCloth += piece.particleCount;
  model.pieces.push_back(piece);

  rebuildTopology(model);
}

}  // namespace soak
