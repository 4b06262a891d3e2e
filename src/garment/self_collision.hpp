// self-collision of an implicit garment (docs/garment.md, "Self-collision"): after the solve and the
// body contact, every free vertex is kept at least the cloth's thickness away from every triangle of
// its piece that does not hold it (or a vertex seamed to it), and every mesh edge as far from every
// edge it does not share a vertex (or seam group) with, on the side it was at the start of the step,
// so a vertex or edge that passed through during the step is put back (proximity with the
// start-of-step side, after Bridson, Fedkiw and Anderson 2002); one that went round the triangle's
// or the edge's end keeps its new side, and a push closes at most one thickness. The push is shared
// by the four points by inverse mass and barycentric weight (momentum is kept), and their velocity
// towards each other along the normal is removed (inelastic). The pairs within reach, or that passed
// through each other during the step however fast (each primitive's box covers its sweep), are found
// once per step, by chunks in parallel joined in order; the passes are Gauss-Seidel over those pairs,
// vertex-triangle then edge-edge, serial: the result does not depend on the thread count. A pair still
// through each other after them joins a rigid impact zone, moved in translation by its mean motion
// (the fail-safe, impactZones in self_collision_resolve.hpp).
#pragma once
#include <soak/math.hpp>
#include <soak/model.hpp>
#include <soak/state.hpp>

#include <array>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace soak {

// the constant data of one piece's self-collision (piece-local vertex ids)
struct SelfCollisionMesh {
  std::vector<std::array<int, 3>> triangles;
  std::vector<std::array<int, 2>> edges;  // every triangle side once, (a < b), ascending
  std::vector<int> group;                 // per vertex: the lowest vertex it is seamed to (itself if none)
  // per group g: the groups sharing a triangle with it, ring[ringStart[g] .. ringStart[g + 1]), ascending
  std::vector<int> ringStart, ring;
  // whether groups a and b share a triangle (a vertex of one lies in the other's one-ring)
  bool neighbours(int a, int b) const;
};

// the self-collision data of a piece of `count` vertices with triangles `tris` and seams (pairs of
// vertices sewn together, joined into groups by union-find)
SelfCollisionMesh buildSelfCollisionMesh(int count, std::vector<std::array<int, 3>> tris,
                                         const std::vector<std::array<int, 2>>& seams);

// a hashed grid of the padded boxes of a piece's triangles or edges, each over its points at the start
// and the end of the step (its sweep)
struct BoxGrid {
  float cell = 1.0f;                  // m
  float pad = 0.0f;                   // m
  struct Entry {
    int id;
    Vec3 lo, hi;  // its padded box, kept beside the id for the bucket's scan
  };
  // primitives of hash bucket b: entry[bucketStart[b] .. bucketStart[b + 1]), ascending
  std::vector<uint32_t> bucketStart;
  std::vector<Entry> entry;
  std::vector<std::array<int, 3>> cellLo, cellHi;  // each primitive's cell range
  std::vector<Vec3> boxLo, boxHi;                  // each primitive's padded box
  template <size_t K>
  void build(std::span<const std::array<int, K>> prims, const Vec3* x0, const Vec3* x1, float cellSize, float padding);
  template <typename F>
  void forCells(size_t t, F&& f) const;  // f(bucket) for every cell of primitive t
};

struct SelfCollisionScratch {
  BoxGrid triangles, edges;
  std::vector<std::array<int, 2>> pairs;      // the step's proximity pairs (vertex, triangle)
  std::vector<std::array<int, 2>> edgePairs;  // and (edge, edge), A < B
  std::vector<std::vector<std::array<int, 2>>> chunkPairs;  // per chunk of vertices or edges, joined into pairs
  std::vector<uint8_t> moved;                      // per vertex of the piece: pushed this step
  std::vector<uint32_t> lastMove, testedAt;        // the passes' push counts: per vertex, per pair
  std::vector<int> zone;                           // the fail-safe's impact zones (union-find), -1 none
  std::vector<std::pair<Vec3, Vec3>> zoneMotion;   // per point in a zone: its displacement and velocity before
  std::vector<Vec3> zoneSum, zoneSumV;             // per zone root: mass-weighted sums
  std::vector<float> zoneMass;
};

// the push of one vertex against one triangle. x0, x1: the four points (vertex, then the triangle's
// a, b, c) at the start and the end of the step; w: their inverse masses (0: does not move); d: the
// least distance. Returns false when the vertex is clear (farther than d on its start side, or its
// end position projects outside the triangle); else the end positions and velocities v are corrected.
bool pushVertexOffTriangle(const std::array<Vec3, 4>& x0, std::array<Vec3, 4>& x1, std::array<Vec3, 4>& v,
                           const std::array<float, 4>& w, float d);

// the push of edge A (points 0, 1) against edge B (points 2, 3), as pushVertexOffTriangle: their
// lines' closest points, inside both edges at the end, are kept d apart along the edges' common
// normal, on the side B started on (or its new side where the edges slid past each other's ends).
// Returns false when they are clear, their closest points lie past an end (a vertex's case), the
// edges are within about 6 degrees of parallel, or they turned by more than 60 degrees in the step
bool pushEdgeOffEdge(const std::array<Vec3, 4>& x0, std::array<Vec3, 4>& x1, std::array<Vec3, 4>& v,
                     const std::array<float, 4>& w, float d);

// three Gauss-Seidel passes over the piece's particles [first, first + count): every vertex against the triangles
// within its reach, then every edge against the edges within its reach. A triangle holding the vertex's seam group
// is not tested, nor an edge pair that shares a group or whose groups share a triangle (two sides of one fold:
// a crossing between them is a vertex's through a triangle). Inverse masses `invMass` (0: pinned or disturbed).
// Positions p.x (start) and p.xPred (end), velocities p.v. Then the fail-safe. Marks the vertices it moved in
// s.moved. Returns the pushes made of each kind and the points the fail-safe put back.
struct SelfCollisionPushes {
  int vertexTriangle = 0, edgeEdge = 0;
  int reverted = 0;  // points the fail-safe moved into impact zones (a pair still through each other)
};
SelfCollisionPushes selfCollide(const SelfCollisionMesh& mesh, int first, int count, const std::vector<float>& invMass,
                                float thickness, Particles& p, SelfCollisionScratch& s);

}  // namespace soak
