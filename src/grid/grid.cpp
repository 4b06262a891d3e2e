#include "grid/grid.hpp"

#include "core/kernels.hpp"
#include "core/parallel.hpp"
#include "core/simd.hpp"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <limits>

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

namespace {

// the candidate ranges of the last cell looked up: particles in the same cell share them, and
// consecutive particles (cloth rows, water sorted by cell) are mostly in the same cell. Each range
// keeps the offset of its cell, so a particle skips the cells its reach does not touch (a bucket
// shared by two cells gets offset 0 and is never skipped).
struct RangeCache {
  Eigen::Vector3i cell{0, 0, 0};
  bool valid = false;
  int count = 0;
  uint32_t ranges[27][2];
  uint32_t buckets[27];
  int8_t offset[27][3];
  void lookup(const NeighborGrid& grid, const Eigen::Vector3i& c) {
    if (valid && c == cell) return;
    count = 0;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const uint32_t b = grid.bucketOf(c + Eigen::Vector3i(dx, dy, dz));
          if (grid.cellStart[b] == grid.cellStart[b + 1]) continue;
          int dup = -1;
          for (int s = 0; s < count; ++s)
            if (buckets[s] == b) dup = s;
          if (dup >= 0) {
            offset[dup][0] = offset[dup][1] = offset[dup][2] = 0;
            continue;
          }
          buckets[count] = b;
          ranges[count][0] = grid.cellStart[b];
          ranges[count][1] = grid.cellStart[b + 1];
          offset[count][0] = static_cast<int8_t>(dx);
          offset[count][1] = static_cast<int8_t>(dy);
          offset[count][2] = static_cast<int8_t>(dz);
          ++count;
        }
    cell = c;
    valid = true;
  }
  // whether the range r can hold a particle within reach of x (f: x's place inside its cell, 0..cellSize)
  static bool touches(const int8_t* o, const float* f, float cellSize, float reach2) {
    float d2 = 0.0f;
    for (int a = 0; a < 3; ++a) {
      const float d = o[a] < 0 ? f[a] : (o[a] > 0 ? cellSize - f[a] : 0.0f);
      d2 += d * d;
    }
    return d2 < reach2;
  }
};

// the dense grid of buildNeighborLists: false (and nothing built) when the bounding box of x has
// more than 8 cells a particle plus 2^20 cells (4 MiB of starts), or no particles. The 2^20 keep a
// scene's domain dense once spray reaches its walls (Fig. 3(a): 75 x 56 x 75 cells for 25.6k
// particles), where the hashed buckets are slower than the whole dense search
bool buildDenseCells(const std::vector<Vec3>& x, float cs, NeighborLists& lists) {
  const size_t n = x.size();
  if (n == 0 || !(cs > 0.0f)) return false;
  Vec3 lo = x[0], hi = x[0];
  for (const Vec3& p : x) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  if (!lo.allFinite() || !hi.allFinite()) return false;
  const Vec3 span = (hi - lo) / cs;
  const double cells = (std::floor(double(span.x())) + 1) * (std::floor(double(span.y())) + 1) * (std::floor(double(span.z())) + 1);
  if (cells > 8.0 * double(n) + 1048576.0) return false;  // 1M-particle block: 8n, 32 B a particle
  lists.denseOrigin = lo;
  lists.denseDims = {static_cast<int>(span.x()) + 1, static_cast<int>(span.y()) + 1, static_cast<int>(span.z()) + 1};
  const Eigen::Vector3i& d = lists.denseDims;
  lists.denseCell.resize(n);
  parallelFor(static_cast<int64_t>(n), [&](int64_t i) {
    const Vec3 c = (x[i] - lo) / cs;
    const int cx = std::min(static_cast<int>(c.x()), d.x() - 1), cy = std::min(static_cast<int>(c.y()), d.y() - 1),
              cz = std::min(static_cast<int>(c.z()), d.z() - 1);
    lists.denseCell[i] = static_cast<uint32_t>((cz * d.y() + cy) * d.x() + cx);
  });
  // counting sort, ascending particle order inside a cell
  std::vector<uint32_t>& start = lists.denseStart;
  start.assign(static_cast<size_t>(cells) + 1, 0);
  for (size_t i = 0; i < n; ++i) ++start[lists.denseCell[i] + 1];
  for (size_t c = 0; c + 1 < start.size(); ++c) start[c + 1] += start[c];
  lists.denseEntries.resize(n);
  for (size_t i = 0; i < n; ++i) lists.denseEntries[start[lists.denseCell[i]]++] = static_cast<uint32_t>(i);
  for (size_t c = start.size() - 1; c > 0; --c) start[c] = start[c - 1];
  start[0] = 0;
  return true;
}

// the dense grid's cell of a point p (clamped to the grid) and p's place inside it (0 .. cs a side)
void denseCellOf(const NeighborLists& lists, const Vec3& p, float cs, int cell[3], float f[3]) {
  const Eigen::Vector3i& d = lists.denseDims;
  const Vec3 c = (p - lists.denseOrigin) / cs;
  for (int a = 0; a < 3; ++a) {
    cell[a] = std::min(static_cast<int>(c[a]), d[a] - 1);
    f[a] = p[a] - (lists.denseOrigin[a] + cs * cell[a]);
  }
}

// the candidates of a particle at p in the dense grid: for each of the 9 rows (y, z) around its cell
// that its reach touches, the cells x - 1 .. x + 1 it touches as one range of the entries
int denseRowRanges(const NeighborLists& lists, const Vec3& p, float cs, float reach2, uint32_t (*ranges)[2]) {
  const Eigen::Vector3i& d = lists.denseDims;
  int cell[3];
  float f[3];
  denseCellOf(lists, p, cs, cell, f);
  // squared distance from p to the neighbouring slab at offset o along axis a (0 for its own)
  const auto gap2 = [&](int a, int o) {
    const float g = o < 0 ? f[a] : (o > 0 ? cs - f[a] : 0.0f);
    return g * g;
  };
  int count = 0;
  for (int oz = -1; oz <= 1; ++oz) {
    const int z = cell[2] + oz;
    if (z < 0 || z >= d.z()) continue;
    for (int oy = -1; oy <= 1; ++oy) {
      const int y = cell[1] + oy;
      if (y < 0 || y >= d.y()) continue;
      const float yz2 = gap2(1, oy) + gap2(2, oz);
      if (yz2 >= reach2) continue;
      const int x0 = cell[0] > 0 && yz2 + gap2(0, -1) < reach2 ? cell[0] - 1 : cell[0];
      const int x1 = cell[0] + 1 < d.x() && yz2 + gap2(0, 1) < reach2 ? cell[0] + 1 : cell[0];
      const size_t row = static_cast<size_t>(z * d.y() + y) * d.x();
      const uint32_t k0 = lists.denseStart[row + x0], k1 = lists.denseStart[row + x1 + 1];
      if (k0 == k1) continue;
      ranges[count][0] = k0;
      ranges[count][1] = k1;
      ++count;
    }
  }
  return count;
}

// the distance from a point at f (0..cs inside its cell, along one axis) to the cells o cells away
// along that axis (0 for its own)
inline float slabGap(float f, int o, float cs) {
  return o < 0 ? f + static_cast<float>(-o - 1) * cs : (o > 0 ? static_cast<float>(o - 1) * cs + (cs - f) : 0.0f);
}

// the candidates of a particle at p whose reach spans more than one cell (a support radius above the
// cell size: `buildNeighborLists`): every cell within `reach` of p, as ranges of the entries, in a
// fixed order. Dense grid: one range per row (y, z) for the cells of the row it touches; hashed grid:
// one range per bucket, each bucket once (buckets: the caller's scratch)
void wideRanges(const NeighborGrid& grid, const NeighborLists& lists, bool dense, const Vec3& p, float cs, float reach,
                std::vector<uint32_t>& ranges, std::vector<uint32_t>& buckets) {  // ranges: [begin, end) pairs, flat
  ranges.clear();
  const float reach2 = reach * reach;
  const int R = static_cast<int>(std::ceil(reach / cs));
  if (dense) {
    const Eigen::Vector3i& d = lists.denseDims;
    int cell[3];
    float f[3];
    denseCellOf(lists, p, cs, cell, f);
    for (int oz = -R; oz <= R; ++oz) {
      const int z = cell[2] + oz;
      if (z < 0 || z >= d.z()) continue;
      for (int oy = -R; oy <= R; ++oy) {
        const int y = cell[1] + oy;
        if (y < 0 || y >= d.y()) continue;
        const float gy = slabGap(f[1], oy, cs), gz = slabGap(f[2], oz, cs), yz2 = gy * gy + gz * gz;
        if (yz2 >= reach2) continue;
        // cell x of the row is within reach
        const auto reaches = [&](int x) {
          const float gx = slabGap(f[0], x - cell[0], cs);
          return yz2 + gx * gx < reach2;
        };
        int x0 = cell[0], x1 = cell[0];
        while (x0 > 0 && x0 > cell[0] - R && reaches(x0 - 1)) --x0;
        while (x1 + 1 < d.x() && x1 < cell[0] + R && reaches(x1 + 1)) ++x1;
        const size_t row = static_cast<size_t>(z * d.y() + y) * d.x();
        const uint32_t k0 = lists.denseStart[row + x0], k1 = lists.denseStart[row + x1 + 1];
        if (k0 != k1) ranges.insert(ranges.end(), {k0, k1});
      }
    }
    return;
  }
  // more cells than buckets: every bucket is in reach, the whole table is the one range
  if (std::pow(2.0 * R + 1.0, 3.0) > static_cast<double>(grid.tableMask) + 1.0) {
    if (!grid.cellEntries.empty()) ranges.insert(ranges.end(), {0u, static_cast<uint32_t>(grid.cellEntries.size())});
    return;
  }
  const Eigen::Vector3i c = grid.cellOf(p);
  const float f[3] = {p.x() - cs * c.x(), p.y() - cs * c.y(), p.z() - cs * c.z()};
  buckets.clear();
  for (int oz = -R; oz <= R; ++oz)
    for (int oy = -R; oy <= R; ++oy)
      for (int ox = -R; ox <= R; ++ox) {
        const float gx = slabGap(f[0], ox, cs), gy = slabGap(f[1], oy, cs), gz = slabGap(f[2], oz, cs);
        if (gx * gx + gy * gy + gz * gz < reach2) buckets.push_back(grid.bucketOf(c + Eigen::Vector3i(ox, oy, oz)));
      }
  std::sort(buckets.begin(), buckets.end());
  buckets.erase(std::unique(buckets.begin(), buckets.end()), buckets.end());
  for (const uint32_t b : buckets)
    if (grid.cellStart[b] != grid.cellStart[b + 1]) ranges.insert(ranges.end(), {grid.cellStart[b], grid.cellStart[b + 1]});
}

// whether particles i and j are neighbours, |x_i - x_j| < h_ij (the lists' definition), from
// d = x_i - x_j and their radii (a template on the lane type: the vector scan and the scalar one)
template <class F>
inline auto withinSupport(F dx, F dy, F dz, F hi, F hj) {
  const F h = pairRadius(hi, hj);
  return dx * dx + dy * dy + dz * dz < h * h;
}

// one build of the lists (buildNeighborLists): its inputs, and its steps as member functions
struct ListBuilder {
  const std::vector<Vec3>& x;
  const std::vector<float>& radius;
  const NeighborGrid& grid;
  NeighborLists& lists;
  uint32_t firstWater;
  float cs;               // the grid's cell size
  bool parallel;
  bool dense = false;     // the dense grid (buildDenseCells) or the hashed grid's buckets
  const uint32_t* entries = nullptr;  // the candidates in cell order (lists.px .. ph: their positions, radii)
  float hMax = 0.0f;      // the largest radius

  void sortCandidates();
  void findBig();
  void scan(size_t i, const uint32_t* ranges, int count, float cutoff, std::vector<uint32_t>& cl,
            std::vector<uint32_t>& wa, uint32_t& nCloth, uint32_t& nWater) const;
  void buildBigLists();
  void invertBigLists();
  void neighboursOf(size_t i, RangeCache& cache, std::vector<uint32_t>& cl, std::vector<uint32_t>& wa,
                    uint32_t& nCloth, uint32_t& nWater) const;
  void reserveIndex();
  void fillLists();
};

// the candidates in the order of the dense grid's cells (or the hashed grid's buckets), with their
// positions and radii in contiguous arrays in that order
void ListBuilder::sortCandidates() {
  const size_t n = x.size();
  for (std::vector<float>* v : {&lists.px, &lists.py, &lists.pz, &lists.ph}) v->resize(n);
  // a dense grid over the particles' bounding box (cells of the same size, x fastest) when it has no
  // more than 8 cells a particle plus 2^20: then the three cells of a row around a particle are one range
  // of the sorted entries, 9 ranges of about 3 cells instead of 27 of one. Else the hashed grid's buckets
  dense = buildDenseCells(x, cs, lists);
  lists.dense = dense;
  entries = dense ? lists.denseEntries.data() : grid.cellEntries.data();
  parallelFor(static_cast<int64_t>(n), [&](int64_t k) {
    const uint32_t j = entries[k];
    lists.px[k] = x[j].x();
    lists.py[k] = x[j].y();
    lists.pz[k] = x[j].z();
    lists.ph[k] = radius[j];
  });
}

// Particles whose support radius exceeds the cell size ("big": drips that grew while they hung, see
// neighborCellSize) are searched over every cell within their reach, and the others' candidates
// skip them: a big particle's pairs come from its own search and are handed to its neighbours'
// lists. One grown drip no longer makes every particle search cells of its size.
void ListBuilder::findBig() {
  lists.big.clear();
  hMax = 0.0f;
  for (size_t i = 0; i < x.size(); ++i) {
    hMax = std::max(hMax, radius[i]);
    if (radius[i] > cs) lists.big.push_back(static_cast<uint32_t>(i));
  }
}

// the neighbours of i among the candidates of ranges [ranges[2r], ranges[2r + 1]) of the entries,
// cloth ones to cl[nCloth ..) and water ones to wa[nWater ..), in candidate order. Candidates with
// a radius above `cutoff` are skipped. Branch free: every candidate is written, the cursor advances
// only for neighbours (wide lanes: all of them to wa first, one store a vector, and the cloth ones
// moved to cl afterwards when there are any)
void ListBuilder::scan(size_t i, const uint32_t* ranges, int count, float cutoff, std::vector<uint32_t>& cl,
                       std::vector<uint32_t>& wa, uint32_t& nCloth, uint32_t& nWater) const {
  const float xi = x[i].x(), yi = x[i].y(), zi = x[i].z(), hi = radius[i];
  uint32_t ncl = nCloth, nwa = nWater;
  // locals, not members: the vector stores below may alias anything, and the compiler would load
  // every pointer again after each of them
  const float* const PX = lists.px.data();
  const float* const PY = lists.py.data();
  const float* const PZ = lists.pz.data();
  const float* const PH = lists.ph.data();
  const uint32_t* const E = entries;
#if SOAK_SIMD_WIDE
  // every neighbour to wa in candidate order, then the cloth ones (if any) moved to cl, both kept in
  // candidate order: the lists are the scalar loop's
  using simd::FloatW;
  simd::MaskW anyCloth{0};
  const uint32_t nwa0 = nwa;
  const FloatW vx = xi, vy = yi, vz = zi, vh = hi, vcut = cutoff;
  const simd::UintW self = simd::splat(static_cast<uint32_t>(i)), split = simd::splat(firstWater);
  for (int r = 0; r < count; ++r) {
    const uint32_t k0 = ranges[2 * r], k1 = ranges[2 * r + 1];
    if (nwa + (k1 - k0) + simd::kLanes > wa.size()) wa.resize(2 * (nwa + (k1 - k0) + simd::kLanes));  // whole-vector stores
    uint32_t* pw = wa.data();
    for (uint32_t k = k0; k < k1; k += simd::kLanes) {
      const simd::MaskW lanes = simd::firstLanes(k1 - k);
      const FloatW hj = simd::load(PH + k, lanes);
      const simd::UintW j = simd::load(E + k, lanes);
      const simd::MaskW in = lanes & withinSupport(vx - simd::load(PX + k, lanes), vy - simd::load(PY + k, lanes),
                                                   vz - simd::load(PZ + k, lanes), vh, hj) &
                             (hj <= vcut) & (j != self);
      anyCloth |= in & (j < split);
      simd::storeCompressed(pw + nwa, in, j);
      nwa += static_cast<uint32_t>(simd::count(in));
    }
  }
  if (simd::any(anyCloth)) {
    if (ncl + (nwa - nwa0) > cl.size()) cl.resize(2 * (ncl + (nwa - nwa0)));
    uint32_t keep = nwa0;
    for (uint32_t e = nwa0; e < nwa; ++e) {
      const uint32_t j = wa[e];
      if (j < firstWater)
        cl[ncl++] = j;
      else
        wa[keep++] = j;
    }
    nwa = keep;
  }
#else
  for (int r = 0; r < count; ++r) {
    const uint32_t k0 = ranges[2 * r], k1 = ranges[2 * r + 1];
    if (ncl + (k1 - k0) > cl.size()) cl.resize(2 * (ncl + (k1 - k0)));
    if (nwa + (k1 - k0) > wa.size()) wa.resize(2 * (nwa + (k1 - k0)));
    uint32_t* pc = cl.data();
    uint32_t* pw = wa.data();
    for (uint32_t k = k0; k < k1; ++k) {
      const uint32_t j = E[k];
      const uint32_t in = withinSupport(xi - PX[k], yi - PY[k], zi - PZ[k], hi, PH[k]) & (PH[k] <= cutoff) &
                          (j != static_cast<uint32_t>(i));
      const uint32_t isCloth = j < firstWater;
      pc[ncl] = j;
      pw[nwa] = j;
      ncl += in & isCloth;
      nwa += in & (isCloth ^ 1u);
    }
  }
#endif
  nCloth = ncl;
  nWater = nwa;
}

// each big particle's list (cloth part first), from every cell within (h_i + hMax) / 2, all candidates
void ListBuilder::buildBigLists() {
  const std::vector<uint32_t>& big = lists.big;
  lists.bigLists.resize(big.size());
  lists.bigCloth.resize(big.size());
  if (big.empty()) return;
#pragma omp parallel if (parallel && big.size() > 1)
  {
    std::vector<uint32_t> ranges, buckets, cl(256), wa(256);
#pragma omp for schedule(dynamic, 1)
    for (int64_t b = 0; b < static_cast<int64_t>(big.size()); ++b) {
      const size_t i = big[static_cast<size_t>(b)];
      wideRanges(grid, lists, dense, x[i], cs, 0.5f * (radius[i] + hMax) * 1.001f, ranges, buckets);  // margin for rounding
      uint32_t ncl = 0, nwa = 0;
      scan(i, ranges.data(), static_cast<int>(ranges.size() / 2), std::numeric_limits<float>::infinity(), cl, wa, ncl, nwa);
      std::vector<uint32_t>& out = lists.bigLists[static_cast<size_t>(b)];
      out.assign(cl.data(), cl.data() + ncl);
      out.insert(out.end(), wa.data(), wa.data() + nwa);
      lists.bigCloth[static_cast<size_t>(b)] = ncl;
    }
  }
}

// the big neighbours of every other particle, by ascending index: the big lists turned around
void ListBuilder::invertBigLists() {
  const size_t n = x.size();
  std::vector<uint32_t>& extraStart = lists.bigOfStart;
  std::vector<uint32_t>& extra = lists.bigOf;
  extraStart.clear();
  extra.clear();
  if (lists.big.empty()) return;
  extraStart.assign(n + 1, 0);
  for (size_t b = 0; b < lists.big.size(); ++b)
    for (const uint32_t j : lists.bigLists[b])
      if (radius[j] <= cs) ++extraStart[j + 1];
  for (size_t i = 0; i < n; ++i) extraStart[i + 1] += extraStart[i];
  extra.resize(extraStart[n]);
  std::vector<uint32_t> cursor(extraStart.begin(), extraStart.end() - 1);
  for (size_t b = 0; b < lists.big.size(); ++b)
    for (const uint32_t j : lists.bigLists[b])
      if (radius[j] <= cs) extra[cursor[j]++] = lists.big[b];
}

// the neighbours of i, cloth ones to cl[0 .. nCloth) and water ones to wa[0 .. nWater), in a
// fixed order. Cells the particle's reach does not touch are skipped.
void ListBuilder::neighboursOf(size_t i, RangeCache& cache, std::vector<uint32_t>& cl, std::vector<uint32_t>& wa,
                               uint32_t& nCloth, uint32_t& nWater) const {
  const float hi = radius[i];
  if (hi > cs) {  // a big particle: its list is made
    const std::vector<uint32_t>& big = lists.big;
    const size_t b = static_cast<size_t>(std::lower_bound(big.begin(), big.end(), static_cast<uint32_t>(i)) - big.begin());
    const std::vector<uint32_t>& own = lists.bigLists[b];
    nCloth = lists.bigCloth[b];
    nWater = static_cast<uint32_t>(own.size()) - nCloth;
    if (nCloth > cl.size()) cl.resize(nCloth);
    if (nWater > wa.size()) wa.resize(nWater);
    std::copy(own.begin(), own.begin() + nCloth, cl.begin());
    std::copy(own.begin() + nCloth, own.end(), wa.begin());
    return;
  }
  const float reach = 0.5f * (hi + cs) * 1.001f, reach2 = reach * reach;  // margin for rounding
  uint32_t ranges[27][2];
  int count = 0;
  if (dense) {
    count = denseRowRanges(lists, x[i], cs, reach2, ranges);
  } else {
    const Eigen::Vector3i c = grid.cellOf(x[i]);
    cache.lookup(grid, c);
    const float f[3] = {x[i].x() - cs * c.x(), x[i].y() - cs * c.y(), x[i].z() - cs * c.z()};
    for (int r = 0; r < cache.count; ++r) {
      if (!RangeCache::touches(cache.offset[r], f, cs, reach2)) continue;
      ranges[count][0] = cache.ranges[r][0];
      ranges[count][1] = cache.ranges[r][1];
      ++count;
    }
  }
  nCloth = nWater = 0;
  scan(i, &ranges[0][0], count, cs, cl, wa, nCloth, nWater);
  // then its big neighbours, after the others of its kind
  for (uint32_t e = lists.bigOf.empty() ? 0 : lists.bigOfStart[i], e1 = lists.bigOf.empty() ? 0 : lists.bigOfStart[i + 1];
       e < e1; ++e) {
    const uint32_t j = lists.bigOf[e];
    std::vector<uint32_t>& to = j < firstWater ? cl : wa;
    uint32_t& at = j < firstWater ? nCloth : nWater;
    if (at + 1 > to.size()) to.resize(2 * (at + 1));
    to[at++] = j;
  }
}

// room for the lists: last build's total and an eighth (exact on the first build, from a count
// pass), so the index array is not reallocated while it is filled. The room is kept while it holds
// the last total and a sixteenth: asking for last + last / 8 each time reallocated the array (fresh
// pages, touched serially) whenever the total had grown by one entry
void ListBuilder::reserveIndex() {
  const size_t last = lists.index.size();
  lists.index.clear();
  if (last > 0) {
    if (lists.index.capacity() < last + last / 16) lists.index.reserve(last + last / 8);
    return;
  }
  size_t total = 0;
#pragma omp parallel if (parallel) reduction(+ : total)
  {
    RangeCache cache;
    std::vector<uint32_t> cl(256), wa(256);
#pragma omp for schedule(static)
    for (int64_t i = 0; i < static_cast<int64_t>(x.size()); ++i) {
      uint32_t ncl, nwa;
      neighboursOf(static_cast<size_t>(i), cache, cl, wa, ncl, nwa);
      total += ncl + nwa;
    }
  }
  lists.index.reserve(total + total / 8);
}

// one distance pass in chunks of particles that the threads take as they come (a folded or bunched
// part of the sheet has many more neighbours than the rest, so equal halves were unequal work): each
// chunk gathers into its own buffer, then the buffers are copied to the list in particle order, so
// the lists do not depend on which thread did what. Rounds of kRound chunks: the buffers hold one
// round, not a copy of the lists.
void ListBuilder::fillLists() {
  const size_t n = x.size();
  constexpr size_t kChunk = 256, kRound = 64;
  uint32_t* start = lists.start.data();
  uint32_t* mid = lists.mid.data();
  std::vector<size_t>& offset = lists.chunkOffset;
  struct Local {
    RangeCache cache;
    std::vector<uint32_t> cl = std::vector<uint32_t>(256), wa = std::vector<uint32_t>(256);
  };
  for (size_t r0 = 0; r0 < n; r0 += kChunk * kRound) {
    const int64_t chunks = static_cast<int64_t>(std::min(kRound, (n - r0 + kChunk - 1) / kChunk));
    const auto chunkRange = [&](int64_t c, size_t& lo, size_t& hi) {
      lo = r0 + static_cast<size_t>(c) * kChunk;
      hi = std::min(n, lo + kChunk);
    };
    const auto fill = [&](Local& t, int64_t c, std::vector<uint32_t>& out) {
      size_t lo, hi;
      chunkRange(c, lo, hi);
      for (size_t i = lo; i < hi; ++i) {
        uint32_t ncl, nwa;
        neighboursOf(i, t.cache, t.cl, t.wa, ncl, nwa);
        start[i + 1] = ncl + nwa;  // a count until the offsets are known
        mid[i] = ncl;
        out.insert(out.end(), t.cl.data(), t.cl.data() + ncl);
        out.insert(out.end(), t.wa.data(), t.wa.data() + nwa);
      }
    };
    const auto size = [&](const std::vector<size_t>& off) {
      const size_t total = off[static_cast<size_t>(chunks)];
      if (total > lists.index.capacity()) lists.index.reserve(total + total / 4);  // neighbours grew
      lists.index.resize(total);
    };
    const auto place = [&](int64_t c) {
      const std::vector<uint32_t>& out = lists.chunkBuffers[static_cast<size_t>(c)];
      std::copy(out.begin(), out.end(), lists.index.begin() + static_cast<std::ptrdiff_t>(offset[static_cast<size_t>(c)]));
      size_t sum = offset[static_cast<size_t>(c)], lo, hi;
      chunkRange(c, lo, hi);
      for (size_t i = lo; i < hi; ++i) {
        const uint32_t count = start[i + 1];
        mid[i] = static_cast<uint32_t>(sum) + mid[i];
        sum += count;
        start[i + 1] = static_cast<uint32_t>(sum);
      }
    };
    orderedChunks(chunks, lists.chunkBuffers, offset, start[r0], parallel, [] { return Local(); }, fill, size, place);
  }
}

}  // namespace

void buildNeighborLists(const std::vector<Vec3>& x, const std::vector<float>& radius, const NeighborGrid& grid,
                        NeighborLists& lists, uint32_t firstWater) {
  const size_t n = x.size();
  lists.firstWater = firstWater;
  lists.start.resize(n + 1);
  lists.mid.resize(n);
  lists.start[0] = 0;
  ListBuilder b{x, radius, grid, lists, firstWater, grid.cellSize, static_cast<int64_t>(n) >= kParallelGrain};
  b.sortCandidates();
  b.findBig();
  b.buildBigLists();
  b.invertBigLists();
  b.reserveIndex();
  b.fillLists();
}

}  // namespace soak
