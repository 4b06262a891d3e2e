// a cloth piece appended to a Model: its particles' rest data, triangles, adjacency, and the PBD
// constraints of the whole cloth rebuilt (cloth_piece.hpp)
#include "scene/cloth_piece.hpp"

#include <algorithm>

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

}  // namespace

// Cloth pieces are added before any water particle exists. The scene loader then creates one particle
// per vertex in State, in order, so particle index == piece.firstParticle + vertex index.
void addClothPiece(Model& model, const std::string& name, const TriangleMesh& mesh, const ClothMaterial& material,
                   const std::vector<int>& pinnedVertices, const std::string& source, ClothSolver solver) {
  validateClothMesh(name, mesh, pinnedVertices, source);  // first: a refused piece leaves the model untouched

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

  buildClothAdjacency(model);
  buildClothConstraints(model);
}

}  // namespace soak
