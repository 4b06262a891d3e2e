// signed distance grids of closed triangle meshes. Distances are exact to the nearest triangle
// (searched through a bucket grid of triangles, ring by ring); signs come from angle-weighted
// pseudo-normals (Baerentzen & Aanaes 2005), which are exact on a closed oriented mesh.
#include "world/mesh_sdf.hpp"

#include "world/mesh_distance.hpp"

#include <soak/error.hpp>

#include "core/parallel.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace soak {

namespace {

// a checked, outward-oriented mesh in double with the pseudo-normals of every feature
struct PreparedMesh {
  std::vector<Vec3d> x;
  std::vector<std::array<int, 3>> tri;
  FeatureNormals normals;
};

// the mesh in double; throws on a non-finite position or an index out of range
void copyChecked(const TriangleMesh& mesh, const std::string& source, PreparedMesh& m) {
  const int nv = static_cast<int>(mesh.vertices.size());
  if (mesh.triangles.empty()) throw errorAt(source, "mesh collider", "the mesh has no triangles");
  m.x.resize(nv);
  for (int v = 0; v < nv; ++v) {
    if (!mesh.vertices[v].allFinite())
      throw errorAt(source, "mesh collider, vertex " + std::to_string(v), "position is not finite");
    m.x[v] = mesh.vertices[v].cast<double>();
  }
  m.tri = mesh.triangles;
  for (size_t t = 0; t < m.tri.size(); ++t)
    for (int k = 0; k < 3; ++k)
      if (m.tri[t][k] < 0 || m.tri[t][k] >= nv)
        throw errorAt(source, "mesh collider, triangle " + std::to_string(t),
                      "vertex index " + std::to_string(m.tri[t][k]) + " is out of range [0, " + std::to_string(nv) +
                          ")");
}

// checked, closed, flipped outward when its normals pointed inwards, with its pseudo-normals;
// throws on a degenerate triangle
PreparedMesh prepare(const TriangleMesh& mesh, const std::string& source) {
  PreparedMesh m;
  copyChecked(mesh, source, m);
  const std::vector<std::array<int, 3>> twin = twinTriangles(m.tri, source);
  if (signedVolume(m.x, m.tri) < 0.0)
    for (auto& t : m.tri) std::swap(t[1], t[2]);
  featureNormals(m.x, m.tri, twin, m.normals);
  for (size_t t = 0; t < m.tri.size(); ++t)
    if (!(m.normals.face[t].squaredNorm() > 0.0))
      throw errorAt(source, "mesh collider, triangle " + std::to_string(t), "degenerate triangle (zero area)");
  return m;
}

// triangles binned by bounding box into buckets of kBucket^3 grid cells, as lists per bucket (CSR)
constexpr int kBucket = 4;

struct TriangleBuckets {
  Vec3d lo;            // m, the grid's node (0, 0, 0)
  double size = 0.0;   // m, kBucket cells
  std::array<int, 3> n{0, 0, 0};
  std::vector<int> start, tris;  // bucket b holds tris[start[b] .. start[b + 1])

  int of(double x, int a) const { return std::clamp(static_cast<int>(std::floor((x - lo[a]) / size)), 0, n[a] - 1); }
  int64_t index(int i, int j, int k) const { return i + int64_t(n[0]) * (j + int64_t(n[1]) * k); }
};

// the grid over the mesh's bounding box plus padding: origin (lo, m), dims and room for the values;
// throws when it would have more than kMaxSdfNodes nodes
SdfGrid layGrid(const PreparedMesh& m, float cellSize, float padding, const std::string& source, Vec3d& lo) {
  lo = m.x[0];
  Vec3d hi = m.x[0];
  for (const Vec3d& x : m.x) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  const double h = cellSize;
  lo -= Vec3d::Constant(padding);
  hi += Vec3d::Constant(padding);
  SdfGrid g;
  g.cellSize = cellSize;
  g.origin = lo.cast<float>();
  int64_t nodes = 1;
  for (int a = 0; a < 3; ++a) {
    const double cells = std::ceil((hi[a] - lo[a]) / h - 1e-9);
    if (cells + 1.0 > static_cast<double>(kMaxSdfNodes))
      throw errorAt(source, "mesh collider", "the grid would be too large; choose a coarser resolution");
    g.dims[a] = static_cast<int>(cells) + 1;
    nodes *= g.dims[a];
  }
  if (nodes > kMaxSdfNodes)
    throw errorAt(source, "mesh collider",
                  "the grid would have " + std::to_string(nodes) + " nodes (more than 256^3); choose a coarser " +
                      "resolution than " + std::to_string(cellSize) + " m");
  g.value.resize(nodes);
  return g;
}

// every triangle in each bucket its bounding box touches: counted in a first pass, listed in a second
TriangleBuckets bucketTriangles(const PreparedMesh& m, const SdfGrid& g, const Vec3d& lo) {
  TriangleBuckets tb;
  tb.lo = lo;
  tb.size = kBucket * static_cast<double>(g.cellSize);
  for (int a = 0; a < 3; ++a) tb.n[a] = (g.dims[a] - 1) / kBucket + 1;
  const int64_t numBuckets = int64_t(tb.n[0]) * tb.n[1] * tb.n[2];
  tb.start.assign(numBuckets + 1, 0);
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<int> fill(tb.start.begin(), tb.start.end() - 1);
    for (int t = 0; t < static_cast<int>(m.tri.size()); ++t) {
      Vec3d tl = m.x[m.tri[t][0]], th = tl;
      for (int k = 1; k < 3; ++k) {
        tl = tl.cwiseMin(m.x[m.tri[t][k]]);
        th = th.cwiseMax(m.x[m.tri[t][k]]);
      }
      for (int k = tb.of(tl[2], 2); k <= tb.of(th[2], 2); ++k)
        for (int j = tb.of(tl[1], 1); j <= tb.of(th[1], 1); ++j)
          for (int i = tb.of(tl[0], 0); i <= tb.of(th[0], 0); ++i) {
            const int64_t b = tb.index(i, j, k);
            if (pass == 0) ++tb.start[b + 1];
            else tb.tris[fill[b]++] = t;
          }
    }
    if (pass == 0) {
      for (int64_t b = 0; b < numBuckets; ++b) tb.start[b + 1] += tb.start[b];
      tb.tris.resize(tb.start[numBuckets]);
    }
  }
  return tb;
}

// the signed distance from p, in bucket (bi, bj, bk), to the nearest triangle: the buckets ring by
// ring until the next ring is farther than the nearest triangle found
double nearestInRings(const PreparedMesh& m, const TriangleBuckets& tb, const Vec3d& p, int bi, int bj, int bk) {
  const std::array<int, 3>& nb = tb.n;
  const int maxRing = std::max({nb[0], nb[1], nb[2]});
  NearestOnMesh best;
  // ring r holds the buckets at Chebyshev distance r; anything beyond it is >= r bucket sizes away
  for (int r = 0; r <= maxRing; ++r) {
    for (int c = std::max(bk - r, 0); c <= std::min(bk + r, nb[2] - 1); ++c)
      for (int b = std::max(bj - r, 0); b <= std::min(bj + r, nb[1] - 1); ++b)
        for (int a = std::max(bi - r, 0); a <= std::min(bi + r, nb[0] - 1); ++a) {
          if (std::max({std::abs(a - bi), std::abs(b - bj), std::abs(c - bk)}) != r) continue;
          const int64_t bucket = tb.index(a, b, c);
          for (int s = tb.start[bucket]; s < tb.start[bucket + 1]; ++s) nearerTriangle(m.x, m.tri, m.normals, tb.tris[s], p, best);
        }
    const double reach = r * tb.size;
    if (best.dist2 <= reach * reach) break;
  }
  return best.sign * std::sqrt(best.dist2);
}

}  // namespace

double exactMeshDistance(const TriangleMesh& mesh, const Vec3d& p) {
  const PreparedMesh m = prepare(mesh, "mesh");
  NearestOnMesh best;
  for (int t = 0; t < static_cast<int>(m.tri.size()); ++t) nearerTriangle(m.x, m.tri, m.normals, t, p, best);
  return best.sign * std::sqrt(best.dist2);
}

SdfGrid buildSdfGrid(const TriangleMesh& mesh, float cellSize, float padding, const std::string& source) {
  if (!(cellSize > 0.0f) || !std::isfinite(cellSize))
    throw errorAt(source, "mesh collider", "resolution (cell size) must be a positive length in m");
  if (!(padding >= 0.0f)) throw errorAt(source, "mesh collider", "padding must be >= 0 m");
  const PreparedMesh m = prepare(mesh, source);
  Vec3d lo;
  SdfGrid g = layGrid(m, cellSize, padding, source, lo);
  const TriangleBuckets buckets = bucketTriangles(m, g, lo);
  const double h = cellSize;
  parallelFor(static_cast<int64_t>(g.value.size()), [&](int64_t n) {
    const int i = static_cast<int>(n % g.dims[0]);
    const int j = static_cast<int>((n / g.dims[0]) % g.dims[1]);
    const int k = static_cast<int>(n / (int64_t(g.dims[0]) * g.dims[1]));
    const Vec3d p = lo + h * Vec3d(i, j, k);
    g.value[n] = static_cast<float>(nearestInRings(m, buckets, p, i / kBucket, j / kBucket, k / kBucket));
  });
  return g;
}

float sampleSdf(const SdfGrid& g, const Vec3& p, Vec3* gradient) {
  const float h = g.cellSize;
  Vec3 u = (p - g.origin) / h;
  Vec3 clamped;
  for (int a = 0; a < 3; ++a) clamped[a] = std::clamp(u[a], 0.0f, static_cast<float>(g.dims[a] - 1));
  const Vec3 outside = (u - clamped) * h;
  int base[3];
  float f[3];
  for (int a = 0; a < 3; ++a) {
    base[a] = std::min(static_cast<int>(std::floor(clamped[a])), std::max(g.dims[a] - 2, 0));
    f[a] = clamped[a] - static_cast<float>(base[a]);
  }
  auto at = [&](int di, int dj, int dk) {
    const int i = std::min(base[0] + di, g.dims[0] - 1), j = std::min(base[1] + dj, g.dims[1] - 1),
              k = std::min(base[2] + dk, g.dims[2] - 1);
    return g.value[i + int64_t(g.dims[0]) * (j + int64_t(g.dims[1]) * k)];
  };
  float c[2][2][2];
  for (int dk = 0; dk < 2; ++dk)
    for (int dj = 0; dj < 2; ++dj)
      for (int di = 0; di < 2; ++di) c[di][dj][dk] = at(di, dj, dk);
  auto lerp = [](float a, float b, float t) { return a + t * (b - a); };
  // trilinear value and its exact partial derivatives
  const float c00 = lerp(c[0][0][0], c[1][0][0], f[0]), c10 = lerp(c[0][1][0], c[1][1][0], f[0]);
  const float c01 = lerp(c[0][0][1], c[1][0][1], f[0]), c11 = lerp(c[0][1][1], c[1][1][1], f[0]);
  const float c0 = lerp(c00, c10, f[1]), c1 = lerp(c01, c11, f[1]);
  const float d = lerp(c0, c1, f[2]);
  const float outLen = outside.norm();
  if (gradient) {
    if (outLen > 0.0f) {
      *gradient = outside / outLen;
    } else {
      const float dx0 = lerp(c[1][0][0] - c[0][0][0], c[1][1][0] - c[0][1][0], f[1]);
      const float dx1 = lerp(c[1][0][1] - c[0][0][1], c[1][1][1] - c[0][1][1], f[1]);
      const Vec3 gr(lerp(dx0, dx1, f[2]), lerp(c10 - c00, c11 - c01, f[2]), c1 - c0);
      const float len = gr.norm();
      *gradient = len > 0.0f ? Vec3(gr / len) : Vec3(0, 1, 0);
    }
  }
  return d + outLen;
}

Collider makeMeshCollider(const std::string& name, const TriangleMesh& mesh, float cellSize, float padding,
                          const std::string& source) {
  Collider c;
  c.name = name;
  c.shape = ColliderShape::Mesh;
  c.sdf = std::make_shared<const SdfGrid>(buildSdfGrid(mesh, cellSize, padding, source));
  c.keys = {Keyframe{}};
  return c;
}

Collider loadMeshCollider(const std::string& name, const std::string& path, float cellSize, float padding) {
  return makeMeshCollider(name, loadObjMesh(path), cellSize, padding, path);
}

}  // namespace soak
