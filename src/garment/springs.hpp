// mass-spring cloth of Chen, Magnenat-Thalmann, Allen 2012 (section 3.2): stretch, shear and bending
// springs built from a triangle mesh, with the nonlinear KES laws of Eq. 11 (stretch, shear) and
// Eq. 14 (bending), the spring force of Eq. 9/12 and its Jacobian (Eq. 13).
//
// Which pairs are springs (docs/garment.md, "springs"):
//   stretch: every mesh edge (i, j);
//   shear:   for every interior edge (a, b) shared by triangles (a, b, c) and (b, a, d), the pair
//            (c, d) across it: the other diagonal of the quad the two triangles form;
//   bend:    "skip one vertex": for every edge (a, b), the pair (a, c) where c is the neighbour of b
//            that continues a -> b most straightly (cosine of the turn >= SpringBuildOptions::
//            bendStraightness); on a grid these are Provot's (i, i + 2) springs.
//   seam:    the vertex pairs of a sewn garment's seams (ClothPiece::seams), last: linear springs
//            whose rest length closes from the starting gap to 0 (seamForce).
// A pair is kept once: an edge is only a stretch spring, and a pair that is both a skip-one pair and
// a pair across an edge (on a grid, (i, i + 2) across a cell side) is a bend spring.
// Vertex indices are local to the mesh (a cloth piece: particle = firstParticle + vertex).
#pragma once
#include <soak/math.hpp>
#include <soak/model.hpp>

#include <soak/garment_params.hpp>

#include <array>
#include <cstdint>
#include <vector>

namespace soak {

enum class SpringKind : uint8_t { Stretch = 0, Shear = 1, Bend = 2, Seam = 3 };

// struct of arrays; springs of kind k are [kindStart[k], kindStart[k + 1])
struct SpringSet {
  int numVertices = 0;
  std::vector<std::array<int, 2>> ids;  // local vertex indices, ids[s][0] < ids[s][1]
  std::vector<float> restLength;        // m, l0 (Eq. 7-8); a seam's: the gap at the start
  std::vector<float> width;             // m, L0 = S_r / l0 (Eq. 9): the spring's share of the cloth area over l0
  std::array<int, 5> kindStart{0, 0, 0, 0, 0};
  // CSR: springs touching vertex v are vertexSpring[vertexStart[v] .. vertexStart[v + 1]), ascending
  std::vector<int> vertexStart;
  std::vector<int> vertexSpring;

  int size() const { return static_cast<int>(ids.size()); }
  SpringKind kind(int s) const {
    return s < kindStart[1]   ? SpringKind::Stretch
           : s < kindStart[2] ? SpringKind::Shear
           : s < kindStart[3] ? SpringKind::Bend
                              : SpringKind::Seam;
  }
  int other(int s, int v) const { return ids[s][0] == v ? ids[s][1] : ids[s][0]; }
};

// builds the springs of a triangle mesh (rest positions, local triangles) and its seams (local vertex
// pairs, distinct; a pair that is already a spring stays that spring)
SpringSet buildSprings(const std::vector<Vec3>& rest, const std::vector<std::array<int, 3>>& triangles,
                       const SpringBuildOptions& options = {}, const std::vector<std::array<int, 2>>& seams = {});

// the springs of cloth piece k of the model, from its rest shape (local indices)
SpringSet buildPieceSprings(const Model& model, int piece, const SpringBuildOptions& options = {});

// Eq. 11's pole, 1/a2, the strain its stress tends to infinity at (infinity for a2 = 0)
float kesPoleStrain(const KesLaw& law);
// the strain past which Eq. 11 is continued by its tangent, strainLimit / a2 (infinity for a2 = 0)
float kesContinuationStrain(const KesLaw& law, float strainLimit);
// Eq. 11 with the tangent continuation past kesContinuationStrain; dsigma = dsigma/deps (Eq. 13)
float kesStretchStress(float eps, const KesLaw& law, float strainLimit, float* dsigma);
// Eq. 14; dsigma = a1 + 2 a2 |eps|
float kesBendStress(float eps, const KesLaw& law, float* dsigma);
// strain energy density W(eps) with dW/deps = sigma: Eq. 11 gives a1 eps^2 / (2 (1 - a2|eps|)^2),
// Eq. 14 gives a1 eps^2 / 2 + a2 |eps|^3 / 3
double kesStretchEnergy(double eps, const KesLaw& law, float strainLimit);
double kesBendEnergy(double eps, const KesLaw& law);

// the law of spring s: stress sigma(eps) and its derivative
float springStress(const SpringSet& springs, const SpringLaws& laws, int s, float eps, float* dsigma);

// Eq. 12 (a seam: seamForce with rest length 0): force on vertex i = ids[s][0] from spring s, f_i = L0 sigma(eps) (x_j - x_i) / l with
// eps = (l - l0) / l0 (Eq. 7-8); the force on j is -f_i. K (may be null) receives the 3x3 stiffness
// -df_i/dx_i = df_i/dx_j = L0 (sigma'/l0 u u^T + max(sigma, 0)/l (I - u u^T)), u = (x_j - x_i)/l:
// the transverse term is dropped under compression so K stays positive semi-definite (Choi & Ko 2002).
// Returns the strain.
float springForce(const SpringSet& springs, const SpringLaws& laws, int s, const Vec3& xi, const Vec3& xj, Vec3d& fi,
                  Eigen::Matrix3d* K);

// a seam's pull: a linear spring of stiffness k (N/m) and rest length r (m), f_i = k (l - r) u with
// u = (x_j - x_i) / l; K (may be null) = k u u^T + k max(l - r, 0) / l (I - u u^T), k I at l = 0
void seamForce(float k, float r, const Vec3& xi, const Vec3& xj, Vec3d& fi, Eigen::Matrix3d* K);

// elastic energy of all springs (seams closed: rest length 0) at positions x (local vertices), J: sum L0 l0 W(eps)
double elasticEnergy(const SpringSet& springs, const SpringLaws& laws, const Vec3* x);

}  // namespace soak
