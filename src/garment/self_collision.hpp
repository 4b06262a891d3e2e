// self-collision of an implicit garment (docs/garment.md, "Self-collision"): after the solve and the
// body contact, every free vertex is kept at least the cloth's thickness away from every triangle of
// its piece that does not hold it (or a vertex seamed to it), on the side it was at the start of the
// step, so a vertex that passed through a triangle during the step is put back (proximity with the
// start-of-step side, after Bridson, Fedkiw and Anderson 2002); one that crossed the plane outside
// the triangle (round its edge) keeps its new side, and a push closes at most one thickness. Edge-edge proximity is not tested:
// two edges can still pass through each other between the vertices. The push is shared by the vertex and
// the triangle's three vertices by inverse mass and barycentric weight (momentum is kept), and their
// velocity towards each other along the triangle's normal is removed (inelastic). The pairs within
// reach (closer than 2 d to the plane, projecting less than d outside the triangle) are found once
// per step, by chunks of vertices in parallel joined in order; the passes are Gauss-Seidel over those
// pairs in vertex order, serial: the result does not depend on the thread count.
#pragma once
#include <soak/math.hpp>
#include <soak/model.hpp>
#include <soak/state.hpp>

#include <array>
#include <cstdint>
#include <vector>

namespace soak {

struct SelfCollisionScratch {
  std::vector<uint32_t> bucketStart;  // triangles of hash bucket b: entry[bucketStart[b] .. bucketStart[b + 1])
  std::vector<int> entry;
  std::vector<std::array<int, 3>> cellLo, cellHi;  // each triangle's cell range
  std::vector<Vec3> boxLo, boxHi;                  // each triangle's padded box
  std::vector<std::array<int, 2>> pairs;            // the step's proximity pairs (vertex, triangle)
  std::vector<std::vector<std::array<int, 2>>> chunkPairs;  // per chunk of vertices, joined into pairs
  std::vector<uint8_t> moved;                      // per vertex of the piece: pushed this step
};

// the push of one vertex against one triangle. x0, x1: the four points (vertex, then the triangle's
// a, b, c) at the start and the end of the step; w: their inverse masses (0: does not move); d: the
// least distance. Returns false when the vertex is clear (farther than d on its start side, or its
// end position projects outside the triangle); else the end positions and velocities v are corrected.
bool pushVertexOffTriangle(const std::array<Vec3, 4>& x0, std::array<Vec3, 4>& x1, std::array<Vec3, 4>& v,
                           const std::array<float, 4>& w, float d);

// three Gauss-Seidel passes over the piece's particles [first, first + count): every vertex against the local
// triangles `tris` within its reach. Seam groups `group` (vertices seamed together share a group): a triangle holding
// the vertex's group is not tested. Inverse masses `invMass` (0: pinned or disturbed). Positions p.x (start) and p.xPred (end),
// velocities p.v. Marks the vertices it moved in s.moved. Returns the pushes made.
int selfCollide(const std::vector<std::array<int, 3>>& tris, const std::vector<int>& group, int first, int count, const std::vector<float>& invMass,
                float thickness, Particles& p, SelfCollisionScratch& s);

}  // namespace soak
