// vertex-triangle and edge-edge self-collision of implicit garments (self_collision.hpp)
#include "garment/self_collision.hpp"

#include "core/parallel.hpp"
#include "garment/self_collision_resolve.hpp"
#include "world/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace soak {

namespace {

constexpr float kMaxPushes = 1.0f;  // thicknesses

// whether the vertex, from signed distance dist0 at the start to dist1 at the end (opposite signs),
// crossed the triangle's plane inside the triangle: at the fraction s = dist0 / (dist0 - dist1) of the
// step, all four points moved linearly, its projection on the triangle then has barycentric
// coordinates >= -kCrossingSlack. A vertex that went round the triangle's edge (a fold sliding over
// itself) crossed the plane outside it and is on its new side legitimately
constexpr float kCrossingSlack = 0.1f;
bool crossedInside(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1, float dist0, float dist1) {
  const float s = dist0 / (dist0 - dist1);
  std::array<Vec3, 4> xs;
  for (int k = 0; k < 4; ++k) xs[k] = x0[k] + s * (x1[k] - x0[k]);
  const Vec3 nraw = (xs[2] - xs[1]).cross(xs[3] - xs[1]);
  const float area2 = nraw.squaredNorm();
  if (!(area2 > 1e-24f)) return true;  // degenerate at the crossing: keep the start's side
  for (int k = 1; k <= 3; ++k) {
    const Vec3& u = xs[k % 3 + 1];
    const Vec3& t = xs[(k + 1) % 3 + 1];
    if ((u - xs[0]).cross(t - xs[0]).dot(nraw) / area2 < -kCrossingSlack) return false;
  }
  return true;
}

// the common case, without a square root: the vertex is on the same side of the triangle's plane at
// the start and the end, and at least d from it at the end
bool clearOnItsSide(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1, float d) {
  const Vec3 n1raw = (x1[2] - x1[1]).cross(x1[3] - x1[1]);
  const float dist1raw = (x1[0] - x1[1]).dot(n1raw);  // dist1 |n1raw|
  const Vec3 n0raw = (x0[2] - x0[1]).cross(x0[3] - x0[1]);
  const float dist0raw = (x0[0] - x0[1]).dot(n0raw);
  return n0raw.squaredNorm() > 1e-24f && dist0raw * dist1raw > 0.0f && dist1raw * dist1raw >= d * d * n1raw.squaredNorm();
}

// the unit normals of a test's plane at the start and the end (the triangle's, or the two edges'
// common one), when both are well defined and turned by less than 60 degrees in the step
bool stepNormals(const Vec3& n0raw, const Vec3& n1raw, float minRaw2, Vec3& n0, Vec3& n1) {
  if (!(n0raw.squaredNorm() > minRaw2) || !(n1raw.squaredNorm() > minRaw2)) return false;
  n0 = n0raw.normalized();
  n1 = n1raw.normalized();
  return n0.dot(n1) >= 0.5f;
}

}  // namespace

// whether the vertex went through the triangle during the step: from one side of its plane to the
// other, crossing it inside the triangle (crossedInside), the triangle turning by less than 60
// degrees (as pushVertexOffTriangle: a flipped triangle has no side)
bool passedThrough(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1) {
  const Vec3 n0raw = (x0[2] - x0[1]).cross(x0[3] - x0[1]), n1raw = (x1[2] - x1[1]).cross(x1[3] - x1[1]);
  if (!((x0[0] - x0[1]).dot(n0raw) * (x1[0] - x1[1]).dot(n1raw) < 0.0f)) return false;  // the same side: the common case
  Vec3 n0, n1;
  if (!stepNormals(n0raw, n1raw, 1e-24f, n0, n1)) return false;
  const float dist0 = (x0[0] - x0[1]).dot(n0), dist1 = (x1[0] - x1[1]).dot(n1);
  return dist0 * dist1 < 0.0f && crossedInside(x0, x1, dist0, dist1);
}

SelfCollisionMesh buildSelfCollisionMesh(int count, std::vector<std::array<int, 3>> tris,
                                         const std::vector<std::array<int, 2>>& seams) {
  SelfCollisionMesh m;
  m.triangles = std::move(tris);
  m.group.resize(static_cast<size_t>(count));
  std::iota(m.group.begin(), m.group.end(), 0);
  const auto root = [&](int v) {
    while (m.group[v] != v) v = m.group[v] = m.group[m.group[v]];
    return v;
  };
  for (const auto& [a, b] : seams) {
    const int ra = root(a), rb = root(b);
    m.group[std::max(ra, rb)] = std::min(ra, rb);
  }
  for (int v = 0; v < count; ++v) m.group[v] = root(v);
  std::vector<std::array<int, 2>> ringPairs;  // (group, group sharing a triangle with it): an edge's ends
  for (const EdgeRef& e : collectEdges(m.triangles)) {  // sorted by (lo, hi)
    if (!m.edges.empty() && m.edges.back() == std::array<int, 2>{e.lo, e.hi}) continue;
    m.edges.push_back({e.lo, e.hi});
    ringPairs.push_back({m.group[e.lo], m.group[e.hi]});
    ringPairs.push_back({m.group[e.hi], m.group[e.lo]});
  }
  std::sort(ringPairs.begin(), ringPairs.end());
  ringPairs.erase(std::unique(ringPairs.begin(), ringPairs.end()), ringPairs.end());
  m.ringStart.assign(static_cast<size_t>(count) + 1, 0);
  for (const auto& [g, h] : ringPairs) ++m.ringStart[g + 1];
  for (int g = 0; g < count; ++g) m.ringStart[g + 1] += m.ringStart[g];
  for (const auto& pr : ringPairs) m.ring.push_back(pr[1]);
  return m;
}

bool SelfCollisionMesh::neighbours(int a, int b) const {
  return std::binary_search(ring.begin() + ringStart[a], ring.begin() + ringStart[a + 1], b);
}

namespace {

// moves the four points along the unit n so that n . sum_k a_k x_k grows by `gap`, point k by
// w_k a_k times a common push (w: inverse masses; momentum is kept), and removes their velocity
// towards each other, side n . sum_k a_k v_k < 0 (inelastic). False where nothing can move
bool sharePush(const std::array<float, 4>& a, const Vec3& n, float side, float gap, std::array<Vec3, 4>& x1,
               std::array<Vec3, 4>& v, const std::array<float, 4>& w) {
  float denom = 0.0f;
  for (int k = 0; k < 4; ++k) denom += a[k] * a[k] * w[k];
  if (!(denom > 0.0f)) return false;
  const float push = gap / denom;
  for (int k = 0; k < 4; ++k) x1[k] += w[k] * a[k] * push * n;
  Vec3 rel = Vec3::Zero();
  for (int k = 0; k < 4; ++k) rel += a[k] * v[k];
  const float approach = side * rel.dot(n);
  if (approach < 0.0f) {
    const float j = -approach / denom;
    for (int k = 0; k < 4; ++k) v[k] += w[k] * a[k] * j * side * n;
  }
  return true;
}

// the gap to close, at most kMaxPushes thicknesses a push: a deeper crossing closes over the passes
// and steps, and no single push stretches the springs around it by more than that (uncapped, the
// pushes' spring energy fed faster motion and more pushes until the Fig. 9 shirt diverged)
float cappedGap(float side, float dist, float d) {
  return std::clamp(side * d - dist, -kMaxPushes * d, kMaxPushes * d);
}

}  // namespace

bool pushVertexOffTriangle(const std::array<Vec3, 4>& x0, std::array<Vec3, 4>& x1, std::array<Vec3, 4>& v,
                           const std::array<float, 4>& w, float d) {
  const Vec3 n1raw = (x1[2] - x1[1]).cross(x1[3] - x1[1]);
  const float area2 = n1raw.norm();
  if (!(area2 > 1e-12f)) return false;
  const Vec3 n1 = n1raw / area2;
  const float dist1 = (x1[0] - x1[1]).dot(n1);
  const Vec3 n0raw = (x0[2] - x0[1]).cross(x0[3] - x0[1]);
  const Vec3 n0 = n0raw.squaredNorm() > 1e-24f ? Vec3(n0raw.normalized()) : n1;
  // a triangle that turned by more than 60 degrees in one step (crumpling, or inverting) has no side
  // to compare: with its normal flipped, a vertex that never crossed it would be pushed through it
  if (n0.dot(n1) < 0.5f) return false;
  const float dist0 = (x0[0] - x0[1]).dot(n0);
  // the side the vertex started on; a vertex that started in the plane keeps the side it ends on
  float side = std::abs(dist0) > 1e-7f ? (dist0 > 0.0f ? 1.0f : -1.0f) : (dist1 >= 0.0f ? 1.0f : -1.0f);
  // ended on the other side: put back only if it went through the triangle, not round its edge
  if (side * dist1 < 0.0f && !crossedInside(x0, x1, dist0, dist1)) side = -side;
  if (side * dist1 >= d) return false;
  // barycentric coordinates of the vertex's projection on the triangle's plane at the end
  const Vec3 q = x1[0] - dist1 * n1;
  std::array<float, 4> a{1.0f, 0.0f, 0.0f, 0.0f};
  for (int k = 1; k <= 3; ++k) {
    const Vec3& u = x1[k % 3 + 1];
    const Vec3& t = x1[(k + 1) % 3 + 1];
    a[k] = -(u - q).cross(t - q).dot(n1) / area2;
    if (a[k] > 0.0f) return false;  // outside: the neighbouring triangle's business
  }
  // n1 . (x - sum_k b_k x_k) is the vertex's height over the triangle
  return sharePush(a, n1, side, cappedGap(side, dist1, d), x1, v, w);
}

namespace {

// the closest points of the lines through edges (p0, p1) and (q0, q1): p0 + s (p1 - p0) and
// q0 + t (q1 - q0); false where the edges are within about 6 degrees of parallel (their distance is
// then a vertex's, for the vertex-triangle test)
bool closestOnLines(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1, float& s, float& t) {
  const Vec3 e1 = p1 - p0, e2 = q1 - q0, r = q0 - p0;
  const float a = e1.squaredNorm(), b = e1.dot(e2), c = e2.squaredNorm(), f = e1.dot(r), g = e2.dot(r);
  const float det = a * c - b * b;  // |e1 x e2|^2
  if (!(det > 0.01f * a * c)) return false;
  s = (f * c - b * g) / det;
  t = (b * f - a * g) / det;
  return true;
}

// whether edges A (x[0], x[1]) and B (x[2], x[3]), from signed distance dist0 at the start to dist1 at
// the end (opposite signs), passed through each other: at the fraction dist0 / (dist0 - dist1) of the
// step, the points moving linearly, the lines' closest points lie within both edges (kCrossingSlack
// of an edge's length beyond its ends). Edges that slid past each other's ends keep their new side
// the closest points s, t of the edges' lines at the fraction dist0 / (dist0 - dist1) of the step (the
// points moving linearly), when the edges are not within about 6 degrees of parallel then
bool closestAtCrossing(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1, float dist0, float dist1,
                       float& s, float& t) {
  const float f = dist0 / (dist0 - dist1);
  std::array<Vec3, 4> xs;
  for (int k = 0; k < 4; ++k) xs[k] = x0[k] + f * (x1[k] - x0[k]);
  return closestOnLines(xs[0], xs[1], xs[2], xs[3], s, t);
}

bool edgesCrossed(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1, float dist0, float dist1) {
  float s, t;
  if (!closestAtCrossing(x0, x1, dist0, dist1, s, t)) return true;  // parallel then: keep the start's side
  const auto within = [](float u) { return u >= -kCrossingSlack && u <= 1.0f + kCrossingSlack; };
  return within(s) && within(t);
}

}  // namespace

// whether the edges crossed from one side of each other to the other during the step, their lines'
// closest points inside both at that moment (as edgesCrossed; not where they were within about 6
// degrees of parallel at the start, the end or the crossing, whose sides are noise)
bool edgesPassedThrough(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1) {
  const Vec3 e0a = x0[1] - x0[0], e0b = x0[3] - x0[2], e1a = x1[1] - x1[0], e1b = x1[3] - x1[2];
  const Vec3 n0raw = e0a.cross(e0b), n1raw = e1a.cross(e1b);
  if (!((x0[2] - x0[0]).dot(n0raw) * (x1[2] - x1[0]).dot(n1raw) < 0.0f)) return false;  // the same side: the common case
  Vec3 n0, n1;
  const float minRaw2 = 0.01f * std::min(e0a.squaredNorm() * e0b.squaredNorm(), e1a.squaredNorm() * e1b.squaredNorm());
  if (!stepNormals(n0raw, n1raw, std::max(minRaw2, 1e-24f), n0, n1)) return false;
  const float dist0 = (x0[2] - x0[0]).dot(n0), dist1 = (x1[2] - x1[0]).dot(n1);
  float s, t;
  return dist0 * dist1 < 0.0f && closestAtCrossing(x0, x1, dist0, dist1, s, t) && s >= 0.0f && s <= 1.0f && t >= 0.0f &&
         t <= 1.0f;
}

bool pushEdgeOffEdge(const std::array<Vec3, 4>& x0, std::array<Vec3, 4>& x1, std::array<Vec3, 4>& v,
                     const std::array<float, 4>& w, float d) {
  float s, t;
  // closest points past an end: a vertex's business (vertex-triangle); in one sheet, the lines of two
  // edges meet outside at least one of them
  if (!closestOnLines(x1[0], x1[1], x1[2], x1[3], s, t) || s < 0.0f || s > 1.0f || t < 0.0f || t > 1.0f) return false;
  const Vec3 n1 = (x1[1] - x1[0]).cross(x1[3] - x1[2]).normalized();
  const Vec3 n0raw = (x0[1] - x0[0]).cross(x0[3] - x0[2]);
  // edges that turned by more than 60 degrees against each other in one step have no side to compare
  if (!(n0raw.squaredNorm() > 1e-24f) || n0raw.normalized().dot(n1) < 0.5f) return false;
  const Vec3 n0 = n0raw.normalized();
  const float dist0 = (x0[2] - x0[0]).dot(n0), dist1 = (x1[2] - x1[0]).dot(n1);  // B's line over A's
  float side = std::abs(dist0) > 1e-7f ? (dist0 > 0.0f ? 1.0f : -1.0f) : (dist1 >= 0.0f ? 1.0f : -1.0f);
  if (side * dist1 < 0.0f && !edgesCrossed(x0, x1, dist0, dist1)) side = -side;
  if (side * dist1 >= d) return false;
  // n1 . ((q0 + t e2) - (p0 + s e1)) is B's closest point's height over A's
  const std::array<float, 4> a{s - 1.0f, -s, 1.0f - t, t};
  return sharePush(a, n1, side, cappedGap(side, dist1, d), x1, v, w);
}

namespace {

constexpr uint32_t kBucketBits = 16;

uint32_t bucketOf(int64_t i, int64_t j, int64_t k) {
  const uint64_t h = uint64_t(i) * 73856093ULL ^ uint64_t(j) * 19349663ULL ^ uint64_t(k) * 83492791ULL;
  return static_cast<uint32_t>(h & ((1u << kBucketBits) - 1));
}

}  // namespace

template <typename F>
void BoxGrid::forCells(size_t t, F&& f) const {
  for (int i = cellLo[t][0]; i <= cellHi[t][0]; ++i)
    for (int j = cellLo[t][1]; j <= cellHi[t][1]; ++j)
      for (int k = cellLo[t][2]; k <= cellHi[t][2]; ++k) f(bucketOf(i, j, k));
}

// hashes every primitive into the cells its box over its sweep (its points at x0 and x1), padded by
// `pad`, overlaps (counting sort)
template <size_t K>
void BoxGrid::build(const std::span<const std::array<int, K>> prims, const Vec3* x0, const Vec3* x1, float cellSize,
                    float padding) {
  const size_t np = prims.size();
  cell = cellSize;
  pad = padding;
  cellLo.resize(np);
  cellHi.resize(np);
  boxLo.resize(np);
  boxHi.resize(np);
  bucketStart.assign((1u << kBucketBits) + 1, 0);
  for (size_t t = 0; t < np; ++t) {
    Vec3 lo = x1[prims[t][0]], hi = lo;
    for (size_t k = 0; k < K; ++k) {  // the primitive's sweep: its points at the start and the end
      lo = lo.cwiseMin(x1[prims[t][k]]).cwiseMin(x0[prims[t][k]]);
      hi = hi.cwiseMax(x1[prims[t][k]]).cwiseMax(x0[prims[t][k]]);
    }
    boxLo[t] = lo - Vec3::Constant(pad);
    boxHi[t] = hi + Vec3::Constant(pad);
    for (int a = 0; a < 3; ++a) {
      cellLo[t][a] = static_cast<int>(std::floor((lo[a] - pad) / cell));
      cellHi[t][a] = static_cast<int>(std::floor((hi[a] + pad) / cell));
    }
  }
  for (size_t t = 0; t < np; ++t) forCells(t, [&](uint32_t b) { ++bucketStart[b + 1]; });
  for (size_t b = 0; b + 1 < bucketStart.size(); ++b) bucketStart[b + 1] += bucketStart[b];
  entry.resize(bucketStart.back());
  std::vector<uint32_t> fill(bucketStart.begin(), bucketStart.end() - 1);
  for (size_t t = 0; t < np; ++t)
    forCells(t, [&](uint32_t b) { entry[fill[b]++] = {static_cast<int>(t), boxLo[t], boxHi[t]}; });
}

namespace {

// whether the box [lo, hi] misses the entry's box: the six comparisons joined without branches (the
// scans' hot test; the result is `(hi < en.lo).any() || (lo > en.hi).any()`)
inline bool outsideBox(const Vec3& lo, const Vec3& hi, const BoxGrid::Entry& en) {
  return (hi.x() < en.lo.x()) | (hi.y() < en.lo.y()) | (hi.z() < en.lo.z()) | (lo.x() > en.hi.x()) |
         (lo.y() > en.hi.y()) | (lo.z() > en.hi.z());
}

// the cells [cLo, cHi] of the box [lo, hi]
void cellsOf(const Vec3& lo, const Vec3& hi, float cell, std::array<int, 3>& cLo, std::array<int, 3>& cHi) {
  for (int a = 0; a < 3; ++a) {
    cLo[a] = static_cast<int>(std::floor(lo[a] / cell));
    cHi[a] = static_cast<int>(std::floor(hi[a] / cell));
  }
}

// f(ci, cj, ck) for every cell of [cLo, cHi]
template <typename F>
void forCellRange(const std::array<int, 3>& cLo, const std::array<int, 3>& cHi, F&& f) {
  for (int ci = cLo[0]; ci <= cHi[0]; ++ci)
    for (int cj = cLo[1]; cj <= cHi[1]; ++cj)
      for (int ck = cLo[2]; ck <= cHi[2]; ++ck) f(ci, cj, ck);
}

// whether cell c is the first (the lowest in each axis) that a query from cLo shares with a
// primitive whose cells start at pLo: a pair met in several cells is counted there only
bool firstSharedCell(const std::array<int, 3>& c, const std::array<int, 3>& cLo, const std::array<int, 3>& pLo) {
  return c[0] == std::max(cLo[0], pLo[0]) && c[1] == std::max(cLo[1], pLo[1]) && c[2] == std::max(cLo[2], pLo[2]);
}

// calls f(triangle) once for every triangle whose padded box overlaps the box [lo, hi] (a vertex's
// sweep): met in every cell both share, counted in the first
template <typename F>
void forTrianglesMeeting(const Vec3& lo, const Vec3& hi, const BoxGrid& g, F&& f) {
  std::array<int, 3> cLo, cHi;
  cellsOf(lo, hi, g.cell, cLo, cHi);
  forCellRange(cLo, cHi, [&](int ci, int cj, int ck) {
    const uint32_t b = bucketOf(ci, cj, ck);
    for (uint32_t e = g.bucketStart[b]; e < g.bucketStart[b + 1]; ++e) {
      const BoxGrid::Entry& en = g.entry[e];
      if (!outsideBox(lo, hi, en) && firstSharedCell({ci, cj, ck}, cLo, g.cellLo[en.id])) f(en.id);
    }
  });
}

// calls f(j) once for every edge j after edge i whose padded box overlaps i's own (unpadded) box: j
// is met in every cell both boxes share, and counted in the first (the lowest in each axis); within a
// bucket an edge's entries are adjacent (it can land twice in one through two cells)
template <typename F>
void forEdgesMeeting(size_t i, const BoxGrid& g, F&& f) {
  const Vec3 lo = g.boxLo[i] + Vec3::Constant(g.pad), hi = g.boxHi[i] - Vec3::Constant(g.pad);
  std::array<int, 3> cLo, cHi;
  cellsOf(lo, hi, g.cell, cLo, cHi);
  forCellRange(cLo, cHi, [&](int ci, int cj, int ck) {
    const uint32_t b = bucketOf(ci, cj, ck);
    const auto begin = g.entry.begin() + g.bucketStart[b], end = g.entry.begin() + g.bucketStart[b + 1];
    const auto after = std::upper_bound(begin, end, int(i), [](int v, const BoxGrid::Entry& en) { return v < en.id; });
    for (auto e = after; e != end; ++e) {
      const int j = e->id;
      if (e != after && (e - 1)->id == j) continue;
      if (!outsideBox(lo, hi, *e) && firstSharedCell({ci, cj, ck}, cLo, g.cellLo[j])) f(j);
    }
  });
}

constexpr int64_t kChunk = 256;  // vertices or edges a chunk of the parallel pair search
// a pair is kept while its vertex is closer than this many thicknesses to the triangle's plane (or
// on the other side), its projection less than one thickness fewer outside the triangle: a pair left
// out needs more than a thickness of motion (a push's most) to come within reach of the push
constexpr float kNearThicknesses = 2.0f;

// whether the vertex's projection on the triangle's plane lies within `near` of the triangle (the
// push acts only on a projection inside it): a sheet's own neighbouring triangles, nearly in the
// vertex's plane, are not kept
bool projectsNear(const std::array<Vec3, 4>& x1, float near) {
  const Vec3 n = (x1[2] - x1[1]).cross(x1[3] - x1[1]);
  const float area2 = n.norm();
  if (!(area2 > 1e-12f)) return true;
  for (int k = 1; k <= 3; ++k) {
    const Vec3& u = x1[k % 3 + 1];
    const Vec3& t = x1[(k + 1) % 3 + 1];
    // (u - x) x (t - x) . n / |n| is the projection's signed distance to the edge's line times |t - u|
    if ((u - x1[0]).cross(t - x1[0]).dot(n) < -near * area2 * (t - u).norm()) return false;
  }
  return true;
}

// the step's proximity pairs (vertex, triangle), in vertex order: every free vertex with every
// triangle whose padded box meets its sweep and that does not hold its seam group, unless it is clear
// by kNearThicknesses on its side or its projection is one thickness less far outside the triangle,
// and it did not pass through the triangle during the step. Chunks of vertices in parallel, joined in
// order: the same pairs for any thread count
void findPairs(const std::vector<std::array<int, 3>>& tris, const std::vector<int>& group, int count,
               const std::vector<float>& invMass, const Vec3* x0, const Vec3* x1, float thickness,
               SelfCollisionScratch& s) {
  const float near = kNearThicknesses * thickness, outside = near - thickness;
  const int64_t chunks = (count + kChunk - 1) / kChunk;
  fillChunks(chunks, s.chunkPairs, omp_get_max_threads(), [] { return 0; },
             [&](int, int64_t c, std::vector<std::array<int, 2>>& out) {
               const int end = static_cast<int>(std::min<int64_t>(count, (c + 1) * kChunk));
               for (int i = static_cast<int>(c * kChunk); i < end; ++i) {
                 if (invMass[i] == 0.0f) continue;
                 // its sweep; a vertex that moved less than the pad meets every triangle it could pass
                 // through at its end already (the point it passed lies in the triangle's sweep)
                 const bool slow = (x1[i] - x0[i]).cwiseAbs().maxCoeff() <= s.triangles.pad;
                 const Vec3 lo = slow ? x1[i] : x0[i].cwiseMin(x1[i]), hi = slow ? x1[i] : x0[i].cwiseMax(x1[i]);
                 forTrianglesMeeting(lo, hi, s.triangles, [&](int t) {
                   const auto& tri = tris[t];
                   if (group[tri[0]] == group[i] || group[tri[1]] == group[i] || group[tri[2]] == group[i]) return;
                   const std::array<Vec3, 4> a0{x0[i], x0[tri[0]], x0[tri[1]], x0[tri[2]]};
                   const std::array<Vec3, 4> a1{x1[i], x1[tri[0]], x1[tri[1]], x1[tri[2]]};
                   if ((!clearOnItsSide(a0, a1, near) && projectsNear(a1, outside)) || passedThrough(a0, a1))
                     out.push_back({i, t});
                 });
               }
             });
  s.pairs.clear();
  for (int64_t c = 0; c < chunks; ++c) s.pairs.insert(s.pairs.end(), s.chunkPairs[c].begin(), s.chunkPairs[c].end());
}

// whether edges A (x[0], x[1]) and B (x[2], x[3]) are clear by `near` on the side they started on,
// or their lines' closest points lie more than `outside` beyond an end of either: not within reach
bool edgesApart(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1, float near, float outside) {
  float s, t;
  if (!closestOnLines(x1[0], x1[1], x1[2], x1[3], s, t)) return true;
  const float ma = outside / (x1[1] - x1[0]).norm(), mb = outside / (x1[3] - x1[2]).norm();
  if (s < -ma || s > 1.0f + ma || t < -mb || t > 1.0f + mb) return true;
  const Vec3 n1 = (x1[1] - x1[0]).cross(x1[3] - x1[2]), n0 = (x0[1] - x0[0]).cross(x0[3] - x0[2]);
  const float dist1raw = (x1[2] - x1[0]).dot(n1), dist0raw = (x0[2] - x0[0]).dot(n0);
  return dist0raw * dist1raw > 0.0f && dist1raw * dist1raw >= near * near * n1.squaredNorm();
}

// the step's edge-edge pairs (A, B), A < B, in A's order: edges with a free vertex, no seam group in
// common and none sharing a triangle with the other's, B's padded box overlapping A's box (boxes over
// their sweeps), unless apart (edgesApart, as findPairs) and not passed through each other during the
// step. Chunks in parallel, joined in order
void findEdgePairs(const SelfCollisionMesh& mesh, const std::vector<float>& invMass, const Vec3* x0, const Vec3* x1,
                   float thickness, SelfCollisionScratch& s) {
  const auto& edges = mesh.edges;
  const auto& group = mesh.group;
  const float near = kNearThicknesses * thickness, outside = near - thickness;
  const int64_t count = static_cast<int64_t>(edges.size()), chunks = (count + kChunk - 1) / kChunk;
  fillChunks(chunks, s.chunkPairs, omp_get_max_threads(), [] { return 0; },
             [&](int, int64_t c, std::vector<std::array<int, 2>>& out) {
               const int64_t end = std::min(count, (c + 1) * kChunk);
               for (int64_t i = c * kChunk; i < end; ++i) {
                 const auto& ea = edges[size_t(i)];
                 const bool free = invMass[ea[0]] > 0.0f || invMass[ea[1]] > 0.0f;
                 if (!free) continue;
                 const int ga = group[ea[0]], gb = group[ea[1]];
                 forEdgesMeeting(size_t(i), s.edges, [&](int j) {
                   const auto& eb = edges[size_t(j)];
                   const int gc = group[eb[0]], gd = group[eb[1]];
                   if (gc == ga || gc == gb || gd == ga || gd == gb) return;
                   const std::array<Vec3, 4> a0{x0[ea[0]], x0[ea[1]], x0[eb[0]], x0[eb[1]]};
                   const std::array<Vec3, 4> a1{x1[ea[0]], x1[ea[1]], x1[eb[0]], x1[eb[1]]};
                   const bool within = !edgesApart(a0, a1, near, outside) || edgesPassedThrough(a0, a1);
                   if (!within || mesh.neighbours(ga, gc) || mesh.neighbours(ga, gd) || mesh.neighbours(gb, gc) ||
                       mesh.neighbours(gb, gd))
                     return;
                   out.push_back({int(i), j});
                 });
               }
             });
  s.edgePairs.clear();
  for (int64_t c = 0; c < chunks; ++c)
    s.edgePairs.insert(s.edgePairs.end(), s.chunkPairs[c].begin(), s.chunkPairs[c].end());
}

}  // namespace

SelfCollisionPushes selfCollide(const SelfCollisionMesh& mesh, int first, int count, const std::vector<float>& invMass,
                                float thickness, Particles& p, SelfCollisionScratch& s) {
  const auto& tris = mesh.triangles;
  const auto& edges = mesh.edges;
  if (tris.empty() || count == 0) return {};
  const Vec3* x0 = p.x.data() + first;
  Vec3* x1 = p.xPred.data() + first;
  Vec3* vel = p.v.data() + first;
  float edge = 0.0f;
  for (const auto& t : tris) edge += (x1[t[1]] - x1[t[0]]).norm();
  s.moved.assign(static_cast<size_t>(count), 0);
  // a vertex within the thickness of a triangle lies in its box padded by the thickness; the boxes
  // are built once, so the pad holds another thickness for the pushes of the passes. Not the step's
  // motion: a fast garment would make the cells, and every candidate list, as large as the piece.
  // The edges' boxes are padded by one thickness only, in cells of two mean edges (about two cells
  // an axis a box): a pair coming within reach through the passes' pushes waits for the next step.
  // The two grids are built at once, a thread each (a build is a serial counting sort)
  const float pad = 2.0f * thickness;
#pragma omp parallel sections num_threads(std::min(2, omp_get_max_threads()))
  {
#pragma omp section
    s.triangles.build<3>(tris, x0, x1, std::max(edge / float(tris.size()), 2.0f * pad), pad);
#pragma omp section
    s.edges.build<2>(edges, x0, x1, 2.0f * edge / float(tris.size()), thickness);
  }
  findPairs(tris, mesh.group, count, invMass, x0, x1, thickness, s);
  findEdgePairs(mesh, invMass, x0, x1, thickness, s);
  SelfCollisionPushes pushes = pushPairs(mesh, invMass, thickness, x0, x1, vel, s);
  pushes.reverted = impactZones(mesh, invMass, x0, x1, vel, s);
  return pushes;
}

}  // namespace soak
