// closest points on triangles, closed-surface checks and pseudo-normals (mesh_distance.hpp)
#include "world/mesh_distance.hpp"

#include <soak/error.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace soak {

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

namespace {

// a triangle's edge k as (lo, hi) vertices and its direction along them
struct Half {
  int lo, hi, dir, tri, k;
};

// "(a, b)" (fmt: the inlined string concatenation draws a false -Wrestrict warning)
std::string edgeText(int a, int b) { return fmt::format("({}, {})", a, b); }

}  // namespace

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

double signedVolume(const std::vector<Vec3d>& x, const std::vector<std::array<int, 3>>& tri) {
  double volume = 0.0;
  for (const auto& t : tri) volume += x[t[0]].dot(x[t[1]].cross(x[t[2]])) / 6.0;
  return volume;
}

void featureNormals(const std::vector<Vec3d>& x, const std::vector<std::array<int, 3>>& tri,
                    const std::vector<std::array<int, 3>>& twin, FeatureNormals& out) {
  out.face.resize(tri.size());
  for (size_t t = 0; t < tri.size(); ++t)
    out.face[t] = (x[tri[t][1]] - x[tri[t][0]]).cross(x[tri[t][2]] - x[tri[t][0]]).normalized();  // zero stays zero
  out.edge.resize(tri.size());
  out.vertex.assign(x.size(), Vec3d::Zero());
  for (size_t t = 0; t < tri.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int a = tri[t][k], b = tri[t][(k + 1) % 3];
      // the twin of edge (a, b) is the triangle that holds both a and b besides t
      int other = -1;
      for (int slot = 0; slot < 3; ++slot) {
        const int o = twin[t][slot];
        if (o < 0) continue;
        const auto& ot = tri[o];
        const bool hasA = ot[0] == a || ot[1] == a || ot[2] == a, hasB = ot[0] == b || ot[1] == b || ot[2] == b;
        if (hasA && hasB) other = o;
      }
      out.edge[t][k] = out.face[t] + (other >= 0 ? out.face[other] : out.face[t]);
      // vertex pseudo-normal: each face weighted by its angle at the vertex
      const Vec3d e1 = (x[b] - x[a]).normalized(), e2 = (x[tri[t][(k + 2) % 3]] - x[a]).normalized();
      out.vertex[a] += std::acos(std::clamp(e1.dot(e2), -1.0, 1.0)) * out.face[t];
    }
  }
}

void nearerTriangle(const std::vector<Vec3d>& x, const std::vector<std::array<int, 3>>& tri,
                    const FeatureNormals& normals, int t, const Vec3d& p, NearestOnMesh& best) {
  const auto& tr = tri[t];
  int feature = kFace;
  const Vec3d q = closestOnTriangle(p, x[tr[0]], x[tr[1]], x[tr[2]], &feature);
  const double d2 = (p - q).squaredNorm();
  if (!(d2 < best.dist2)) return;
  const Vec3d* n = &normals.face[t];
  if (feature >= kVertex0) n = &normals.vertex[tr[feature - kVertex0]];
  else if (feature >= kEdge0) n = &normals.edge[t][feature - kEdge0];
  best.dist2 = d2;
  best.sign = (p - q).dot(*n) < 0.0 ? -1.0 : 1.0;
  best.triangle = t;
  best.point = q;
  best.pseudoNormal = *n;
}

}  // namespace soak
