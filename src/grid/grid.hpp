// neighbour search: a hashed uniform grid filled by counting sort (cellStart / cellEntries), rebuilt
// every step without allocation after warm-up, and per-particle neighbour lists built from it (from a
// dense grid of the particles' bounding box with the same cells when that is small enough: the cells
// of a row are then one range). Two particles are neighbours when |x_i - x_j| < h_ij = (h_i + h_j) / 2 (per-particle radii).
// The cell size need not be the largest radius: the few particles above it are searched wider.
#pragma once
#include <soak/math.hpp>

#include <cmath>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

namespace soak {

struct NeighborGrid {
  float cellSize = 0.0f;                // m, at least the largest support radius
  uint32_t tableMask = 0;               // hash table size - 1 (a power of two)
  std::vector<uint32_t> cellStart;      // size table + 1; bucket b holds cellEntries[cellStart[b] ..)
  std::vector<uint32_t> cellEntries;    // particle indices sorted by bucket, ascending within one
  std::vector<uint32_t> particleBucket; // bucket of each particle

  Eigen::Vector3i cellOf(const Vec3& p) const {
    return {static_cast<int>(std::floor(p.x() / cellSize)), static_cast<int>(std::floor(p.y() / cellSize)),
            static_cast<int>(std::floor(p.z() / cellSize))};
  }
  uint32_t bucketOf(const Eigen::Vector3i& c) const {
    const uint32_t h = (static_cast<uint32_t>(c.x()) * 92837111u) ^ (static_cast<uint32_t>(c.y()) * 689287499u) ^
                       (static_cast<uint32_t>(c.z()) * 283923481u);
    return h & tableMask;
  }

  // the non-empty buckets of the 27 cells around cell c (a superset of the particles within cellSize
  // of any point of c) as ranges [begin, end) of cellEntries, in a fixed order, each bucket once even
  // when two cells share it; returns the number of ranges (at most 27)
  int candidateRanges(const Eigen::Vector3i& c, uint32_t (*ranges)[2]) const {
    uint32_t seen[27];
    int nSeen = 0, nRanges = 0;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const uint32_t b = bucketOf(c + Eigen::Vector3i(dx, dy, dz));
          bool dup = false;
          for (int s = 0; s < nSeen; ++s) dup |= (seen[s] == b);
          if (dup) continue;
          seen[nSeen++] = b;
          if (cellStart[b] == cellStart[b + 1]) continue;
          ranges[nRanges][0] = cellStart[b];
          ranges[nRanges][1] = cellStart[b + 1];
          ++nRanges;
        }
    return nRanges;
  }

  // calls f(j) for the particles j in the 27 cells around p (a superset of those within cellSize of
  // p), each once, in a fixed order (buckets shared by two cells are visited once), until f returns
  // true; returns whether it did
  template <class F>
  bool forEachCandidate(const Vec3& p, F&& f) const {
    uint32_t ranges[27][2];
    const int nr = candidateRanges(cellOf(p), ranges);
    for (int r = 0; r < nr; ++r)
      for (uint32_t k = ranges[r][0]; k < ranges[r][1]; ++k)
        if (f(cellEntries[k])) return true;
    return false;
  }
};

// an allocator whose resize leaves new elements uninitialised (default-initialised): the lists are
// written in full after each resize, and value-initialising them was a serial fill of every entry
template <class T>
struct UninitAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = UninitAllocator<U>;
  };
  UninitAllocator() = default;
  template <class U>
  UninitAllocator(const UninitAllocator<U>&) noexcept {}
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

// neighbour lists, kept through the solver iterations of a step: neighbours of i are
// index[start[i] .. start[i + 1]), excluding i itself, in a fixed order. Those with an index below
// firstWater (the cloth particles) come first, in [start[i], mid[i]); the others follow in
// [mid[i], start[i + 1]), so a loop over one kind skips the other.
struct NeighborLists {
  std::vector<uint32_t> start;
  std::vector<uint32_t, UninitAllocator<uint32_t>> index;
  std::vector<uint32_t> mid;
  uint32_t firstWater = 0;              // the index split the lists were built with
  std::vector<float> px, py, pz, ph;   // scratch of the build: candidates' positions and radii in cellEntries order
  std::vector<std::vector<uint32_t>> chunkBuffers;  // scratch of the build: the lists of one round's chunks
  std::vector<size_t> chunkOffset;                  // scratch of the build: where each chunk's lists go
  // scratch of the build: a dense grid of the particles' bounding box (buildNeighborLists); dense
  // tells whether the last build used it or the hashed grid's buckets
  bool dense = false;
  Vec3 denseOrigin = Vec3::Zero();
  Eigen::Vector3i denseDims{0, 0, 0};
  std::vector<uint32_t> denseStart, denseEntries, denseCell;
  // the particles whose support radius exceeds the grid's cell size ("big", ascending); their pairs
  // come from a search of every cell within their reach (buildNeighborLists). Callers that look up
  // the grid's 27 cells themselves must add these (emission's drip density)
  std::vector<uint32_t> big;
  // scratch of the build: each big particle's list (cloth part first, bigCloth entries) and, turned
  // around, the big neighbours of every other particle i: bigOf[bigOfStart[i] .. bigOfStart[i + 1])
  std::vector<std::vector<uint32_t>> bigLists;
  std::vector<uint32_t> bigCloth, bigOfStart, bigOf;
  uint32_t count(size_t i) const { return start[i + 1] - start[i]; }
  // the cloth neighbours of i when the lists were built with firstWater = numCloth, else all
  uint32_t clothEnd(size_t i, uint32_t numCloth) const { return firstWater == numCloth ? mid[i] : start[i + 1]; }
  // the first water neighbour of i when the lists were built with firstWater = numCloth, else the first
  uint32_t waterBegin(size_t i, uint32_t numCloth) const { return firstWater == numCloth ? mid[i] : start[i]; }
};

// fills the grid for positions x with the given cell size (counting sort, deterministic)
void buildGrid(const std::vector<Vec3>& x, float cellSize, NeighborGrid& grid);

// neighbour lists for every particle from a grid built on the same positions; in each list the
// neighbours with index < firstWater (cloth) come before the others (water). Particles with a radius
// above the grid's cell size are found by their own wider search and come last in the others' lists
// (of their kind)
void buildNeighborLists(const std::vector<Vec3>& x, const std::vector<float>& radius, const NeighborGrid& grid,
                        NeighborLists& lists, uint32_t firstWater = 0);

}  // namespace soak
