#include "grid/grid.hpp"

#include "core/parallel.hpp"

#include <algorithm>

namespace soak {

void buildGrid(const std::vector<Vec3>& x, float cellSize, NeighborGrid& grid) {
  const size_t n = x.size();
  grid.cellSize = cellSize;
  uint32_t table = 1024;
  while (table < 2 * n) table <<= 1;
  grid.tableMask = table - 1;
  grid.cellStart.assign(table + 1, 0);
  grid.cellEntries.resize(n);
  grid.particleBucket.resize(n);
  parallelFor(static_cast<int64_t>(n), [&](int64_t i) { grid.particleBucket[i] = grid.bucketOf(grid.cellOf(x[i])); });
  // counting sort: serial count and scatter keep ascending particle order inside a bucket
  for (size_t i = 0; i < n; ++i) ++grid.cellStart[grid.particleBucket[i] + 1];
  for (uint32_t b = 0; b < table; ++b) grid.cellStart[b + 1] += grid.cellStart[b];
  // scatter with a cursor per bucket, taken from cellStart (shifted back afterwards)
  for (size_t i = 0; i < n; ++i) {
    const uint32_t b = grid.particleBucket[i];
    grid.cellEntries[grid.cellStart[b]++] = static_cast<uint32_t>(i);
  }
  for (uint32_t b = table; b > 0; --b) grid.cellStart[b] = grid.cellStart[b - 1];
  grid.cellStart[0] = 0;
}

void buildNeighborLists(const std::vector<Vec3>& x, const std::vector<float>& radius, const NeighborGrid& grid,
                        NeighborLists& lists) {
  const size_t n = x.size();
  lists.start.resize(n + 1);
  lists.start[0] = 0;
  auto visit = [&](size_t i, auto&& emit) {
    const Vec3 xi = x[i];
    const float hi = radius[i];
    grid.forEachCandidate(xi, [&](uint32_t j) {
      if (j == i) return;
      const float h = 0.5f * (hi + radius[j]);
      if ((xi - x[j]).squaredNorm() < h * h) emit(j);
    });
  };
  // pass 1 counts, pass 2 fills: two distance passes cost less memory than per-thread buffers
  parallelFor(static_cast<int64_t>(n), [&](int64_t i) {
    uint32_t c = 0;
    visit(static_cast<size_t>(i), [&](uint32_t) { ++c; });
    lists.start[i + 1] = c;
  });
  for (size_t i = 0; i < n; ++i) lists.start[i + 1] += lists.start[i];
  lists.index.resize(lists.start[n]);
  parallelFor(static_cast<int64_t>(n), [&](int64_t i) {
    uint32_t w = lists.start[i];
    visit(static_cast<size_t>(i), [&](uint32_t j) { lists.index[w++] = j; });
  });
}

}  // namespace soak
