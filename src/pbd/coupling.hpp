// water-cloth coupling: the particle-triangle constraint of Eq. 21 (Shao 2017), Müller et al.
// 2007's self-collision constraint, tested on the step's motion so no water crosses a dry cloth
#pragma once
#include <soak/model.hpp>
#include <soak/state.hpp>

#include "grid/grid.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace soak {

struct CouplingContact {
  uint32_t a, b, c;  // the triangle's vertices
  Vec3 da, db, dc;   // m, their corrections
};

// the cloth particles in a dense grid over the sheet's bounding box, sorted by cell (x fastest), so
// that the cells of one row of a box are one range of the sorted arrays; positions copied in that
// order for the path tests
struct ClothBoxGrid {
  float cell = 0.0f;                         // m
  Vec3 origin = Vec3::Zero();                // m, corner of cell (0, 0, 0)
  Eigen::Vector3i dims{0, 0, 0};
  std::vector<uint32_t> cellStart;           // size cells + 1
  std::vector<uint32_t> entry;               // cloth particle of each sorted slot
  std::vector<uint32_t> cellOf;              // per cloth particle: its dense cell
  std::vector<float> px, py, pz, pr;         // m, positions and reach (findCouplingCandidates) in slot order
  // the cell of x clamped to the grid
  Eigen::Vector3i clampedCell(const Vec3& x) const {
    const Vec3 c = (x - origin) / cell;
    return {std::clamp(static_cast<int>(std::floor(c.x())), 0, dims.x() - 1),
            std::clamp(static_cast<int>(std::floor(c.y())), 0, dims.y() - 1),
            std::clamp(static_cast<int>(std::floor(c.z())), 0, dims.z() - 1)};
  }
  uint32_t index(int x, int y, int z) const {
    return static_cast<uint32_t>((z * dims.y() + y) * dims.x() + x);
  }
};

// what a coupling pass reads of a triangle, in one 32-byte record: its unit normal (0: degenerate)
// and first corner at the predicted positions, its piece's thickness d and its kappa^couple
struct TrianglePlane {
  Vec3 normal;
  float thickness;   // m
  Vec3 origin;       // m
  float stiffness;   // kappa^couple (Eq. 22)
  Vec3 centroid;     // m (set by the passes for the candidates; the second search does not read it)
  float reach;       // m, the farthest vertex from the centroid
};

struct CouplingScratch {
  std::vector<std::vector<CouplingContact>> chunkContacts;  // contacts of each chunk of water particles, in water order
  std::vector<std::vector<uint32_t>> seen;   // per thread: the water particle that last visited a triangle
  std::vector<std::vector<uint32_t>> seenCloth;  // per thread: the water particle that last tested a cloth particle
  std::vector<std::vector<uint32_t>> researchMark;  // per thread: the rigid pass's second search that last met a triangle
  std::vector<uint32_t> researchCount;       // per thread: second searches so far (the marks' stamp)
  ClothBoxGrid clothGrid;                    // the cloth particles alone at their predicted positions
  std::vector<float> triangleEdge2;          // m^2, each triangle's longest edge at the predicted positions, squared
  std::vector<float> vertexReach;            // m, per cloth particle: how near a path it is a candidate
  std::vector<int32_t> nearestCloth;         // per water particle: the cloth particle nearest its start (-1: none)
  std::vector<std::vector<uint32_t>> chunkCandidates;  // candidates of each chunk of water particles
  std::vector<size_t> chunkOffset;                     // where each chunk's candidates go
  std::vector<uint32_t> candidateStart;      // CSR over water particles (index - numCloth): their candidate
  std::vector<uint32_t> candidates;          // triangles, found once per substep for every coupling pass
  std::vector<float> candidateSide;          // +-1: the side of each candidate the particle came from
  std::vector<float> particleSide;           // per water particle: the side given to candidates it does not start over
  std::vector<Vec3> searchedEnd;             // per water particle: the end of the path its candidates were searched along
  float clothRadius = 0.0f;                  // m, the largest cloth support radius when the candidates were searched
  std::vector<Vec3> startNormal;             // unit normal of each triangle at the start of the substep (0: degenerate)
  std::vector<uint8_t> triangleActive;       // 1: the triangle is some water particle's candidate this substep
  std::vector<uint32_t> activeTriangles;     // those triangles, ascending: the passes compute their planes only
  std::vector<TrianglePlane> plane;          // each active triangle's plane and centroid at the predicted positions
  std::vector<Vec3> clothDelta;
  std::vector<uint32_t> clothCount;
  std::vector<float> triangleStiffness;   // kappa^couple per triangle (Eq. 22 drives it; 1 when dry)
};

// C = s (x_q - p) . n - d >= 0 (Eq. 21 as corrected in NOTES.md): p the closest point of triangle
// (a, b, c) to x_q, n its unit normal, s the side x_q came from, d the cloth thickness.
// Returns C and the barycentric weights of p in bary.
float couplingConstraint(const Vec3& xq, const Vec3& xa, const Vec3& xb, const Vec3& xc, float side, float thickness,
                         Vec3& normal, Vec3& bary);

// Eq. 5: the per-iteration factor of a stiffness kappa in [0, 1] solved over n iterations
inline float iterationFactor(float kappa, int iterations) {
  if (kappa >= 1.0f) return 1.0f;
  if (kappa <= 0.0f) return 0.0f;
  return 1.0f - std::pow(1.0f - kappa, 1.0f / static_cast<float>(iterations > 0 ? iterations : 1));
}

// the candidate triangles of every water particle: those around the cloth particles within reach of
// its path this substep (the segment from x to x*, so a particle fast enough to pass the sheet in one
// step still meets it), each once, in the order first met, and the side it came from. Once per
// substep, after the solvers have moved x* and before the passes of solveCoupling.
void findCouplingCandidates(const Model& model, const Particles& p, CouplingScratch& s);

// one pass of the coupling constraint for every water particle against its candidate triangles.
// p.x holds the positions at the start of the substep (the side each particle came from), p.xPred
// the predicted ones. With rigidCloth the cloth is held still (a final pass that guarantees water
// ends on its side). Returns the number of contacts of a movable-cloth pass (0 for the rigid one).
uint64_t solveCoupling(const Model& model, Particles& p, CouplingScratch& s, bool rigidCloth);

}  // namespace soak
