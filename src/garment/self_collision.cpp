// vertex-triangle self-collision of implicit garments (self_collision.hpp)
#include "garment/self_collision.hpp"

#include "core/parallel.hpp"

#include <algorithm>
#include <cmath>

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
  std::array<float, 4> b{};
  for (int k = 1; k <= 3; ++k) {
    const Vec3& u = x1[k % 3 + 1];
    const Vec3& t = x1[(k + 1) % 3 + 1];
    b[k] = (u - q).cross(t - q).dot(n1) / area2;
    if (b[k] < 0.0f) return false;  // outside: the neighbouring triangle's business
  }
  const float denom = w[0] + b[1] * b[1] * w[1] + b[2] * b[2] * w[2] + b[3] * b[3] * w[3];
  if (!(denom > 0.0f)) return false;
  // the gap to close, at most kMaxPushes thicknesses a push: a deeper crossing closes over the passes
  // and steps, and no single push stretches the springs around it by more than that (uncapped, the
  // pushes' spring energy fed faster motion and more pushes until the Fig. 9 shirt diverged)
  const float gap = std::clamp(side * d - dist1, -kMaxPushes * d, kMaxPushes * d);
  const float push = gap / denom;  // along n1, shared by inverse mass and weight
  x1[0] += w[0] * push * n1;
  for (int k = 1; k <= 3; ++k) x1[k] -= b[k] * w[k] * push * n1;
  Vec3 rel = v[0];
  for (int k = 1; k <= 3; ++k) rel -= b[k] * v[k];
  const float approach = side * rel.dot(n1);
  if (approach < 0.0f) {  // inelastic: the velocity towards each other is removed
    const float j = -approach / denom;
    v[0] += w[0] * j * side * n1;
    for (int k = 1; k <= 3; ++k) v[k] -= b[k] * w[k] * j * side * n1;
  }
  return true;
}

namespace {

constexpr uint32_t kBucketBits = 16;
constexpr int kPasses = 3;  // Gauss-Seidel passes: a push can undo an earlier one nearby

uint32_t bucketOf(int64_t i, int64_t j, int64_t k) {
  const uint64_t h = uint64_t(i) * 73856093ULL ^ uint64_t(j) * 19349663ULL ^ uint64_t(k) * 83492791ULL;
  return static_cast<uint32_t>(h & ((1u << kBucketBits) - 1));
}

// hashes every triangle into the cells its end-of-step box, padded by `pad`, overlaps (counting sort)
void hashTriangles(const std::vector<std::array<int, 3>>& tris, const Vec3* x1, float cell, float pad,
                   SelfCollisionScratch& s) {
  const size_t nt = tris.size();
  s.cellLo.resize(nt);
  s.cellHi.resize(nt);
  s.boxLo.resize(nt);
  s.boxHi.resize(nt);
  s.bucketStart.assign((1u << kBucketBits) + 1, 0);
  for (size_t t = 0; t < nt; ++t) {
    Vec3 lo = x1[tris[t][0]], hi = lo;
    for (int k = 1; k < 3; ++k) {
      lo = lo.cwiseMin(x1[tris[t][k]]);
      hi = hi.cwiseMax(x1[tris[t][k]]);
    }
    s.boxLo[t] = lo - Vec3::Constant(pad);
    s.boxHi[t] = hi + Vec3::Constant(pad);
    for (int a = 0; a < 3; ++a) {
      s.cellLo[t][a] = static_cast<int>(std::floor((lo[a] - pad) / cell));
      s.cellHi[t][a] = static_cast<int>(std::floor((hi[a] + pad) / cell));
    }
  }
  const auto forCells = [&](size_t t, auto&& f) {
    for (int i = s.cellLo[t][0]; i <= s.cellHi[t][0]; ++i)
      for (int j = s.cellLo[t][1]; j <= s.cellHi[t][1]; ++j)
        for (int k = s.cellLo[t][2]; k <= s.cellHi[t][2]; ++k) f(bucketOf(i, j, k));
  };
  for (size_t t = 0; t < nt; ++t) forCells(t, [&](uint32_t b) { ++s.bucketStart[b + 1]; });
  for (size_t b = 0; b + 1 < s.bucketStart.size(); ++b) s.bucketStart[b + 1] += s.bucketStart[b];
  s.entry.resize(s.bucketStart.back());
  std::vector<uint32_t> fill(s.bucketStart.begin(), s.bucketStart.end() - 1);
  for (size_t t = 0; t < nt; ++t) forCells(t, [&](uint32_t b) { s.entry[fill[b]++] = static_cast<int>(t); });
}

// the four particles of one test (ids local to the piece), gathered and written back
struct Four {
  std::array<int, 4> id;
  std::array<Vec3, 4> x0, x1, v;
  std::array<float, 4> w;
  Four(const std::array<int, 4>& ids, const Vec3* x0s, const Vec3* x1s, const Vec3* vs, const std::vector<float>& inv)
      : id(ids) {
    for (int k = 0; k < 4; ++k) {
      x0[k] = x0s[id[k]];
      x1[k] = x1s[id[k]];
      v[k] = vs[id[k]];
      w[k] = inv[id[k]];
    }
  }
  void store(Vec3* x1s, Vec3* vs, std::vector<uint8_t>& moved) const {
    for (int k = 0; k < 4; ++k) {
      x1s[id[k]] = x1[k];
      vs[id[k]] = v[k];
      moved[id[k]] = 1;
    }
  }
};

// calls f(triangle) for every triangle whose padded box holds point q (those hashed into q's cell)
template <typename F>
void forTrianglesAt(const Vec3& q, float cell, const SelfCollisionScratch& s, F&& f) {
  const uint32_t b = bucketOf(static_cast<int>(std::floor(q.x() / cell)), static_cast<int>(std::floor(q.y() / cell)),
                              static_cast<int>(std::floor(q.z() / cell)));
  for (uint32_t e = s.bucketStart[b]; e < s.bucketStart[b + 1]; ++e) {
    const int t = s.entry[e];
    if ((q.array() < s.boxLo[t].array()).any() || (q.array() > s.boxHi[t].array()).any()) continue;
    f(t);
  }
}

constexpr int64_t kVertexChunk = 256;
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
// triangle whose padded box holds it and that does not hold its seam group, unless it is clear by
// kNearThicknesses on its side or its projection is one thickness less far outside the triangle.
// Chunks of vertices in parallel, joined in order: the same pairs for any thread count
void findPairs(const std::vector<std::array<int, 3>>& tris, const std::vector<int>& group, int count,
               const std::vector<float>& invMass, const Vec3* x0, const Vec3* x1, float cell, float thickness,
               SelfCollisionScratch& s) {
  const float near = kNearThicknesses * thickness, outside = near - thickness;
  const int64_t chunks = (count + kVertexChunk - 1) / kVertexChunk;
  fillChunks(chunks, s.chunkPairs, omp_get_max_threads(), [] { return 0; },
             [&](int, int64_t c, std::vector<std::array<int, 2>>& out) {
               const int end = static_cast<int>(std::min<int64_t>(count, (c + 1) * kVertexChunk));
               for (int i = static_cast<int>(c * kVertexChunk); i < end; ++i) {
                 if (invMass[i] == 0.0f) continue;
                 forTrianglesAt(x1[i], cell, s, [&](int t) {
                   const auto& tri = tris[t];
                   if (group[tri[0]] == group[i] || group[tri[1]] == group[i] || group[tri[2]] == group[i]) return;
                   const std::array<Vec3, 4> a0{x0[i], x0[tri[0]], x0[tri[1]], x0[tri[2]]};
                   const std::array<Vec3, 4> a1{x1[i], x1[tri[0]], x1[tri[1]], x1[tri[2]]};
                   if (!clearOnItsSide(a0, a1, near) && projectsNear(a1, outside)) out.push_back({i, t});
                 });
               }
             });
  s.pairs.clear();
  for (int64_t c = 0; c < chunks; ++c) s.pairs.insert(s.pairs.end(), s.chunkPairs[c].begin(), s.chunkPairs[c].end());
}

}  // namespace

int selfCollide(const std::vector<std::array<int, 3>>& tris, const std::vector<int>& group, int first, int count,
                const std::vector<float>& invMass, float thickness, Particles& p, SelfCollisionScratch& s) {
  if (tris.empty() || count == 0) return 0;
  const Vec3* x0 = p.x.data() + first;
  Vec3* x1 = p.xPred.data() + first;
  Vec3* vel = p.v.data() + first;
  float edge = 0.0f;
  for (const auto& t : tris) edge += (x1[t[1]] - x1[t[0]]).norm();
  s.moved.assign(static_cast<size_t>(count), 0);
  // a vertex within the thickness of a triangle lies in its box padded by the thickness; the boxes
  // are built once, so the pad holds another thickness for the pushes of the passes. Not the step's
  // motion: a fast garment would make the cells, and every candidate list, as large as the piece
  const float pad = 2.0f * thickness;
  const float cell = std::max(edge / float(tris.size()), 2.0f * pad);
  hashTriangles(tris, x1, cell, pad, s);
  findPairs(tris, group, count, invMass, x0, x1, cell, thickness, s);
  int pushes = 0;
  for (int pass = 0; pass < kPasses; ++pass) {
    for (const auto& [i, t] : s.pairs) {
      const auto& tri = tris[t];
      Four f({i, tri[0], tri[1], tri[2]}, x0, x1, vel, invMass);
      if (!pushVertexOffTriangle(f.x0, f.x1, f.v, f.w, thickness)) continue;
      f.store(x1, vel, s.moved);
      ++pushes;
    }
  }
  return pushes;
}

}  // namespace soak
