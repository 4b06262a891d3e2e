// counts pairs of triangles of a cloth mesh that pass through each other (issue 23 point 3: "no cloth
// triangle crosses another"). Two triangles cross when an edge of one passes through the other's
// interior (Moller-Trumbore with the edge as a segment); triangles that share a vertex are not
// compared, and vertices joined by a seam count as one (a closed seam's two sides touch by design).
// A uniform grid of triangle bounding boxes finds the candidates.
#pragma once
#include <soak/math.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <unordered_map>
#include <vector>

namespace soak::testing {

// does segment p->q pass through the interior of triangle (a, b, c)? (the ends and the triangle's
// border shrunk by eps, so touching at a shared edge is not a crossing)
inline bool segmentThroughTriangle(const Vec3d& p, const Vec3d& q, const Vec3d& a, const Vec3d& b, const Vec3d& c,
                                   double eps = 1e-9) {
  const Vec3d d = q - p, e1 = b - a, e2 = c - a;
  const Vec3d h = d.cross(e2);
  const double det = e1.dot(h);
  if (std::abs(det) < 1e-18) return false;  // parallel
  const Vec3d s = p - a;
  const double u = s.dot(h) / det;
  const Vec3d qv = s.cross(e1);
  const double v = d.dot(qv) / det;
  const double t = e2.dot(qv) / det;
  return u > eps && v > eps && u + v < 1.0 - eps && t > eps && t < 1.0 - eps;
}

inline size_t countCrossingTriangles(const std::vector<Vec3>& x, const std::vector<std::array<int, 3>>& tris,
                                     const std::vector<std::array<int, 2>>& seams = {}) {
  std::vector<int> rep(x.size());
  std::iota(rep.begin(), rep.end(), 0);
  const auto find = [&](int v) {
    while (rep[v] != v) v = rep[v] = rep[rep[v]];
    return v;
  };
  for (const auto& [a, b] : seams) rep[find(a)] = find(b);
  double cell = 0.0;
  for (const auto& t : tris) cell += (x[t[0]] - x[t[1]]).norm();
  cell = std::max(cell / std::max<size_t>(tris.size(), 1), 1e-4);
  std::unordered_map<int64_t, std::vector<int>> grid;
  const auto key = [&](const Vec3& p, int k) { return int64_t(std::floor(p[k] / cell)); };
  for (size_t t = 0; t < tris.size(); ++t) {
    Vec3 lo = x[tris[t][0]], hi = lo;
    for (int k = 1; k < 3; ++k) {
      lo = lo.cwiseMin(x[tris[t][k]]);
      hi = hi.cwiseMax(x[tris[t][k]]);
    }
    for (int64_t i = key(lo, 0); i <= key(hi, 0); ++i)
      for (int64_t j = key(lo, 1); j <= key(hi, 1); ++j)
        for (int64_t k = key(lo, 2); k <= key(hi, 2); ++k)
          grid[(i * 73856093) ^ (j * 19349663) ^ (k * 83492791)].push_back(int(t));
  }
  std::vector<std::pair<int, int>> pairs;
  for (const auto& [cellKey, list] : grid)
    for (size_t m = 0; m < list.size(); ++m)
      for (size_t n = m + 1; n < list.size(); ++n) pairs.push_back({std::min(list[m], list[n]), std::max(list[m], list[n])});
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  size_t crossing = 0;
  for (const auto& [s, t] : pairs) {
    bool shared = false;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) shared = shared || find(tris[s][i]) == find(tris[t][j]);
    if (shared) continue;
    const auto through = [&](int edgeTri, int faceTri) {
      const Vec3d a = x[tris[faceTri][0]].cast<double>(), b = x[tris[faceTri][1]].cast<double>(),
                  c = x[tris[faceTri][2]].cast<double>();
      for (int e = 0; e < 3; ++e)
        if (segmentThroughTriangle(x[tris[edgeTri][e]].cast<double>(), x[tris[edgeTri][(e + 1) % 3]].cast<double>(), a, b, c))
          return true;
      return false;
    };
    if (through(s, t) || through(t, s)) ++crossing;
  }
  return crossing;
}

}  // namespace soak::testing
