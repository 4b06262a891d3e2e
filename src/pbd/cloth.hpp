// PBD cloth: stretch (Eq. 8) and dihedral bending (Eq. 9) constraints with XPBD compliance, solved
// colour by colour in parallel (deterministic), and particle-particle self-collision.
#pragma once
#include <soak/model.hpp>
#include <soak/state.hpp>

#include "grid/grid.hpp"

#include <string>
#include <vector>

namespace soak {

// a triangle mesh as read from OBJ or generated; positions in metres
struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
};

// reads an OBJ file (triangulating polygons); throws soak::Error naming the file on failure
TriangleMesh loadObjMesh(const std::string& path);

// a rectangle of size (width x height) m with (resX x resY) vertices, centred at `center`, lying in
// the plane spanned by unit axes `axisU` (width) and `axisV` (height); alternating diagonals
TriangleMesh makeRectangle(const Vec3& center, const Vec3& axisU, const Vec3& axisV, float width, float height,
                           int resX, int resY);

// appends a cloth piece to the model: particles' rest data, triangles, and rebuilds stretch/bend
// constraints, colourings and adjacency. Throws soak::Error (naming `source`) when an edge is shared
// by more than two triangles, a triangle is degenerate or an index is out of range. An Implicit
// piece gets adjacency but no PBD stretch / bend constraints (src/garment builds its springs).
void addClothPiece(Model& model, const std::string& name, const TriangleMesh& mesh, const ClothMaterial& material,
                   const std::vector<int>& pinnedVertices, const std::string& source,
                   ClothSolver solver = ClothSolver::Pbd);

// the particle index of vertex 0 of the piece is model.pieces[k].firstParticle

// scratch for the cloth solver (XPBD multipliers)
struct ClothScratch {
  std::vector<float> stretchLambda, bendLambda;
  std::vector<float> correction;      // m, the moves of the stretch constraints' particles, 6 per constraint (SoA)
  std::vector<float> correctionBend;  // m, the same for the bend constraints, 12 per constraint
  std::vector<Vec3> delta;
  std::vector<int> deltaCount;
};

// C(x1, x2) = |x1 - x2| - l0 (Eq. 8); returns C and writes gradients wrt x1 and x2
float stretchConstraint(const Vec3& x1, const Vec3& x2, float restLength, Vec3& grad1, Vec3& grad2);

// signed dihedral angle of triangles (a, b, c) and (b, a, d) sharing edge (a, b), minus phi0 (Eq. 9);
// writes the gradients wrt a, b, c, d
float bendConstraint(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, float restAngle, Vec3 grad[4]);

// solves the cloth constraints for `iterations` iterations on p.xPred (XPBD, multipliers reset
// here once per substep)
void solveCloth(const Model& model, Particles& p, ClothScratch& scratch, float dt, int iterations);

// pushes apart cloth particles of the same piece closer than its thickness that are not mesh
// neighbours (Jacobi, gather style: each particle sums its own corrections)
void clothSelfCollision(const Model& model, Particles& p, const NeighborLists& neighbors, ClothScratch& scratch);

}  // namespace soak
