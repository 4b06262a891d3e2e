// signed distance grids of closed triangle meshes. Distances are exact to the nearest triangle
// (searched through a bucket grid of triangles, ring by ring); signs come from angle-weighted
// pseudo-normals (Baerentzen & Aanaes 2005), which are exact on a closed oriented mesh.
#include "world/mesh_sdf.hpp"

#include <soak/error.hpp>

#include "core/parallel.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace soak {

namespace {

// closest-point features of a triangle: the face, edge k (vertices k, k+1) or vertex k
enum Feature { kFace = 0, kEdge0 = 1, kVertex0 = 4 };

// closest point on triangle (a, b, c) to p (Ericson, Real-Time Collision Detection 5.1.5), with the
// feature it lies on
Vec3d closestOnTriangle(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c, int* feature) {
  const Vec3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return *feature = kVertex0 + 0, a;
  const Vec3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return *feature = kVertex0 + 1, b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    *feature = kEdge0 + 0;
    return a + (d1 / (d1 - d3)) * ab;
  }
  const Vec3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return *feature = kVertex0 + 2, c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    *feature = kEdge0 + 2;  // edge (c, a)
    return a + (d2 / (d2 - d6)) * ac;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    *feature = kEdge0 + 1;  // edge (b, c)
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  }
  const double denom = 1.0 / (va + vb + vc);
  *feature = kFace;
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// a checked, outward-oriented mesh in double with the pseudo-normals of every feature
struct PreparedMesh {
  std::vector<Vec3d> x;
  std::vector<std::array<int, 3>> tri;
  std::vector<Vec3d> faceNormal;               // unit
  std::vector<std::array<Vec3d, 3>> edgeNormal;  // per triangle edge k (k, k+1): sum of both faces
  std::vector<Vec3d> vertexNormal;             // angle-weighted sum of the faces around
};

// "(a, b)" (fmt: the inlined string concatenation draws a false -Wrestrict warning)
std::string edgeText(int a, int b) { return fmt::format("({}, {})", a, b); }

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

// a triangle's edge k as (lo, hi) vertices and its direction along them
struct Half {
  int lo, hi, dir, tri, k;
};

// twin[t][k]: the triangle across edge k of triangle t. Throws unless the mesh is closed and
// consistently oriented: every directed edge (a, b) has exactly one twin (b, a)
std::vector<std::array<int, 3>> twinTriangles(const std::vector<std::array<int, 3>>& tri, const std::string& source) {
  std::vector<Half> halves;
  halves.reserve(tri.size() * 3);
  for (int t = 0; t < static_cast<int>(tri.size()); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = tri[t][k], b = tri[t][(k + 1) % 3];
      halves.push_back({std::min(a, b), std::max(a, b), a < b ? 0 : 1, t, k});
    }
  std::sort(halves.begin(), halves.end(), [](const Half& p, const Half& q) {
    if (p.lo != q.lo) return p.lo < q.lo;
    if (p.hi != q.hi) return p.hi < q.hi;
    return p.tri < q.tri;
  });
  std::vector<std::array<int, 3>> twin(tri.size(), {-1, -1, -1});
  for (size_t s = 0; s < halves.size();) {
    size_t e = s;
    while (e < halves.size() && halves[e].lo == halves[s].lo && halves[e].hi == halves[s].hi) ++e;
    const std::string edge = edgeText(halves[s].lo, halves[s].hi);
    if (e - s != 2)
      throw errorAt(source, "mesh collider, edge " + edge,
                    "the edge belongs to " + std::to_string(e - s) +
                        " triangle(s); a mesh collider must be a closed surface (every edge in exactly two "
                        "triangles)");
    if (halves[s].dir == halves[s + 1].dir)
      throw errorAt(source, "mesh collider, edge " + edge,
                    "triangles " + std::to_string(halves[s].tri) + " and " + std::to_string(halves[s + 1].tri) +
                        " run the same way along the edge; expected a consistently oriented surface");
    twin[halves[s].tri][halves[s].k] = halves[s + 1].tri;
    twin[halves[s + 1].tri][halves[s + 1].k] = halves[s].tri;
    s = e;
  }
  return twin;
}

// flips every triangle when the signed volume (divergence theorem) is negative: the normals pointed
// inwards
void orientOutward(PreparedMesh& m) {
  double volume = 0.0;
  for (const auto& t : m.tri) volume += m.x[t[0]].dot(m.x[t[1]].cross(m.x[t[2]])) / 6.0;
  if (volume < 0.0)
    for (auto& t : m.tri) std::swap(t[1], t[2]);
}

// unit face normals; throws on a degenerate triangle
void faceNormals(PreparedMesh& m, const std::string& source) {
  m.faceNormal.resize(m.tri.size());
  for (size_t t = 0; t < m.tri.size(); ++t) {
    const Vec3d n = (m.x[m.tri[t][1]] - m.x[m.tri[t][0]]).cross(m.x[m.tri[t][2]] - m.x[m.tri[t][0]]);
    if (!(n.norm() > 0.0))
      throw errorAt(source, "mesh collider, triangle " + std::to_string(t), "degenerate triangle (zero area)");
    m.faceNormal[t] = n.normalized();
  }
}

// the pseudo-normals of the edges (sum of both faces) and the vertices (angle-weighted sum of the
// faces around). Twins are found by their vertices, so orientOutward's swap does not disturb them
void featureNormals(PreparedMesh& m, const std::vector<std::array<int, 3>>& twin) {
  m.edgeNormal.resize(m.tri.size());
  m.vertexNormal.assign(m.x.size(), Vec3d::Zero());
  for (size_t t = 0; t < m.tri.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int a = m.tri[t][k], b = m.tri[t][(k + 1) % 3];
      // the twin of edge (a, b) is the triangle that holds both a and b besides t
      int other = -1;
      for (int slot = 0; slot < 3; ++slot) {
        const int o = twin[t][slot];
        if (o < 0) continue;
        const auto& ot = m.tri[o];
        const bool hasA = ot[0] == a || ot[1] == a || ot[2] == a, hasB = ot[0] == b || ot[1] == b || ot[2] == b;
        if (hasA && hasB) other = o;
      }
      m.edgeNormal[t][k] = m.faceNormal[t] + (other >= 0 ? m.faceNormal[other] : m.faceNormal[t]);
      // vertex pseudo-normal: each face weighted by its angle at the vertex
      const Vec3d e1 = (m.x[b] - m.x[a]).normalized(), e2 = (m.x[m.tri[t][(k + 2) % 3]] - m.x[a]).normalized();
      m.vertexNormal[a] += std::acos(std::clamp(e1.dot(e2), -1.0, 1.0)) * m.faceNormal[t];
    }
  }
}

PreparedMesh prepare(const TriangleMesh& mesh, const std::string& source) {
  PreparedMesh m;
  copyChecked(mesh, source, m);
  const std::vector<std::array<int, 3>> twin = twinTriangles(m.tri, source);
  orientOutward(m);
  faceNormals(m, source);
  featureNormals(m, twin);
  return m;
}

// unsigned squared distance from p to triangle t and the sign from the nearest feature's normal
struct Nearest {
  double dist2 = std::numeric_limits<double>::infinity();
  double sign = 1.0;
};

void testTriangle(const PreparedMesh& m, int t, const Vec3d& p, Nearest& best) {
  const auto& tr = m.tri[t];
  int feature = kFace;
  const Vec3d q = closestOnTriangle(p, m.x[tr[0]], m.x[tr[1]], m.x[tr[2]], &feature);
  const double d2 = (p - q).squaredNorm();
  if (!(d2 < best.dist2)) return;
  const Vec3d* n = &m.faceNormal[t];
  if (feature >= kVertex0) n = &m.vertexNormal[tr[feature - kVertex0]];
  else if (feature >= kEdge0) n = &m.edgeNormal[t][feature - kEdge0];
  best.dist2 = d2;
  best.sign = (p - q).dot(*n) < 0.0 ? -1.0 : 1.0;
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
  Nearest best;
  // ring r holds the buckets at Chebyshev distance r; anything beyond it is >= r bucket sizes away
  for (int r = 0; r <= maxRing; ++r) {
    for (int c = std::max(bk - r, 0); c <= std::min(bk + r, nb[2] - 1); ++c)
      for (int b = std::max(bj - r, 0); b <= std::min(bj + r, nb[1] - 1); ++b)
        for (int a = std::max(bi - r, 0); a <= std::min(bi + r, nb[0] - 1); ++a) {
          if (std::max({std::abs(a - bi), std::abs(b - bj), std::abs(c - bk)}) != r) continue;
          const int64_t bucket = tb.index(a, b, c);
          for (int s = tb.start[bucket]; s < tb.start[bucket + 1]; ++s) testTriangle(m, tb.tris[s], p, best);
        }
    const double reach = r * tb.size;
    if (best.dist2 <= reach * reach) break;
  }
  return best.sign * std::sqrt(best.dist2);
}

}  // namespace

double exactMeshDistance(const TriangleMesh& mesh, const Vec3d& p) {
  const PreparedMesh m = prepare(mesh, "mesh");
  Nearest best;
  for (int t = 0; t < static_cast<int>(m.tri.size()); ++t) testTriangle(m, t, p, best);
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
