// a cloth piece appended to a Model: its particles' rest data, triangles, adjacency, and the PBD
// constraints of the whole cloth rebuilt (cloth_piece.hpp)
#include "scene/cloth_piece.hpp"

#include <soak/error.hpp>

#include <algorithm>
#include <array>
#include <string>

#include "pbd/cloth.hpp"

namespace soak {

namespace {

// triangles around each particle and 1-ring neighbours (both CSR, ascending) over all pieces
void buildClothAdjacency(Model& model) {
  const int n = model.numCloth;
  model.vertexTriangleStart.assign(n + 1, 0);
  for (const auto& tri : model.triangles)
    for (int v : tri) ++model.vertexTriangleStart[v + 1];
  for (int v = 0; v < n; ++v) model.vertexTriangleStart[v + 1] += model.vertexTriangleStart[v];
  model.vertexTriangles.assign(model.vertexTriangleStart[n], 0);
  std::vector<int> fill(model.vertexTriangleStart.begin(), model.vertexTriangleStart.end() - 1);
  for (int t = 0; t < static_cast<int>(model.triangles.size()); ++t)
    for (int v : model.triangles[t]) model.vertexTriangles[fill[v]++] = t;

  std::vector<std::vector<int>> ring(n);
  const std::vector<EdgeRef> edges = collectEdges(model.triangles);
  for (size_t s = 0; s < edges.size(); ++s) {
    if (s > 0 && edges[s].lo == edges[s - 1].lo && edges[s].hi == edges[s - 1].hi) continue;  // one edge once
    ring[edges[s].lo].push_back(edges[s].hi);
    ring[edges[s].hi].push_back(edges[s].lo);
  }
  model.vertexNeighborStart.assign(n + 1, 0);
  model.vertexNeighbors.clear();
  for (int v = 0; v < n; ++v) {
    std::sort(ring[v].begin(), ring[v].end());
    model.vertexNeighbors.insert(model.vertexNeighbors.end(), ring[v].begin(), ring[v].end());
    model.vertexNeighborStart[v + 1] = static_cast<int>(model.vertexNeighbors.size());
  }
}

// adds a triangle's area to its vertices as the mixed Voronoi areas of Meyer et al. 2003: each
// vertex's Voronoi region when no angle is obtuse, else half the area to the obtuse vertex and a
// quarter to the others; the three shares add up to the area, and on a regular grid every inner
// vertex gets one cell whichever way the cells are split
void addMixedAreas(const TriangleMesh& mesh, const std::array<int, 3>& t, std::vector<double>& area) {
  const Vec3d p[3] = {mesh.vertices[t[0]].cast<double>(), mesh.vertices[t[1]].cast<double>(),
                      mesh.vertices[t[2]].cast<double>()};
  const double whole = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
  for (int k = 0; k < 3; ++k) {
    const Vec3d a = p[(k + 1) % 3] - p[k], b = p[(k + 2) % 3] - p[k];
    if (a.dot(b) < 0.0) {  // obtuse at vertex k
      for (int j = 0; j < 3; ++j) area[t[j]] += whole * (j == k ? 0.5 : 0.25);
      return;
    }
  }
  for (int k = 0; k < 3; ++k) {
    // the edges from vertex k, each weighted by the cotangent of the angle facing it
    const Vec3d& o = p[k];
    const Vec3d& q = p[(k + 1) % 3];
    const Vec3d& r = p[(k + 2) % 3];
    const auto cot = [](const Vec3d& u, const Vec3d& v) { return u.dot(v) / u.cross(v).norm(); };
    area[t[k]] += ((r - o).squaredNorm() * cot(o - q, r - q) + (q - o).squaredNorm() * cot(o - r, q - r)) / 8.0;
  }
}

// each vertex's mixed Voronoi area on the rest mesh, m^2 (0 for a vertex in no triangle)
std::vector<float> restAreas(const TriangleMesh& mesh) {
  std::vector<double> area(mesh.vertices.size(), 0.0);
  for (const auto& t : mesh.triangles) addMixedAreas(mesh, t, area);
  return std::vector<float>(area.begin(), area.end());
}

// the dry mass of each vertex: material.particleMass when it is set, else the vertex's mixed Voronoi
// area times material.arealDensity (a vertex in no triangle is refused: its mass would be 0)
std::vector<float> dryMasses(const std::string& name, const std::vector<float>& area, const ClothMaterial& material,
                             const std::string& source) {
  if (material.particleMass > 0.0f) return std::vector<float>(area.size(), material.particleMass);
  std::vector<float> mass(area.size());
  for (size_t v = 0; v < mass.size(); ++v) {
    if (!(area[v] > 0.0f))
      throw Error(source + ": cloth '" + name + "': vertex " + std::to_string(v) +
                  " (0-based) belongs to no triangle of non-zero area; expected every vertex in one when the "
                  "mass comes from material.arealDensity (its mass would be 0; give particleMass instead)");
    mass[v] = static_cast<float>(static_cast<double>(material.arealDensity) * area[v]);
  }
  return mass;
}

}  // namespace

// Cloth pieces are added before any water particle exists. The scene loader then creates one particle
// per vertex in State, in order, so particle index == piece.firstParticle + vertex index.
void addClothPiece(Model& model, const std::string& name, const TriangleMesh& mesh, const ClothMaterial& material,
                   const std::vector<int>& pinnedVertices, const std::string& source, ClothSolver solver) {
  validateClothMesh(name, mesh, pinnedVertices, source);  // first: a refused piece leaves the model untouched
  const std::vector<float> area = restAreas(mesh);
  const std::vector<float> mass = dryMasses(name, area, material, source);

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
  model.clothDryMass.insert(model.clothDryMass.end(), mass.begin(), mass.end());
  model.clothRestArea.insert(model.clothRestArea.end(), area.begin(), area.end());
  model.clothPinned.insert(model.clothPinned.end(), mesh.vertices.size(), uint8_t{0});
  for (int v : pinnedVertices) model.clothPinned[piece.firstParticle + v] = 1;
  model.clothImplicit.insert(model.clothImplicit.end(), mesh.vertices.size(),
                             uint8_t{solver == ClothSolver::Implicit ? uint8_t{1} : uint8_t{0}});
  model.numCloth += piece.particleCount;
  model.pieces.push_back(piece);

  buildClothAdjacency(model);
  buildClothConstraints(model);
}

}  // namespace soak
