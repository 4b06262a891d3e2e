// building a Model's cloth: one call per piece appends its particles' rest data, triangles and
// adjacency, and rebuilds the PBD constraints of the whole cloth (pbd/cloth.hpp)
#pragma once
#include <soak/model.hpp>

#include "world/mesh.hpp"

#include <string>
#include <vector>

namespace soak {

// appends a cloth piece to the model. Throws soak::Error (naming `source`) when the mesh fails
// validateClothMesh. An Implicit piece gets adjacency but no PBD stretch / bend constraints
// (src/garment builds its springs). Cloth pieces are added before any water particle exists; the
// particle of the piece's vertex v is model.pieces[k].firstParticle + v.
void addClothPiece(Model& model, const std::string& name, const TriangleMesh& mesh, const ClothMaterial& material,
                   const std::vector<int>& pinnedVertices, const std::string& source,
                   ClothSolver solver = ClothSolver::Pbd);

}  // namespace soak
