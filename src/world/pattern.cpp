// sewing patterns: outline sampling, seam pairing, CGAL triangulation and placement (pattern.hpp)
#include "world/pattern.hpp"

#include <soak/error.hpp>

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_size_criteria_2.h>
#include <CGAL/Delaunay_mesh_vertex_base_2.h>
#include <CGAL/Delaunay_mesher_no_edge_refinement_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/lloyd_optimize_mesh_2.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

namespace soak {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Delaunay_mesh_vertex_base_2<Kernel>;
using Fb = CGAL::Delaunay_mesh_face_base_2<Kernel>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Kernel, Tds, CGAL::Exact_predicates_tag>;
using Criteria = CGAL::Delaunay_mesh_size_criteria_2<Cdt>;
using Mesher = CGAL::Delaunay_mesher_no_edge_refinement_2<Cdt, Criteria>;

constexpr double kPi = 3.14159265358979323846;

// the path of a part of the pattern in errors: "<source>.panels[1]", or "<file>: at panels[1]" for a
// source ending in a space
std::string at(const std::string& source, const std::string& path) {
  return source + (!source.empty() && source.back() == ' ' ? "" : ".") + path;
}

double cross2(const Vec2d& a, const Vec2d& b) { return a.x() * b.y() - a.y() * b.x(); }

bool segmentsCross(const Vec2d& p, const Vec2d& q, const Vec2d& r, const Vec2d& s) {
  const double d1 = cross2(q - p, r - p), d2 = cross2(q - p, s - p);
  const double d3 = cross2(s - r, p - r), d4 = cross2(s - r, q - r);
  return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0)) && d1 != 0 && d2 != 0 && d3 != 0 && d4 != 0;
}

double signedArea(const std::vector<Vec2d>& o) {
  double a = 0.0;
  for (size_t i = 0; i < o.size(); ++i) a += cross2(o[i], o[(i + 1) % o.size()]);
  return 0.5 * a;
}

void checkPanel(const PatternPanel& p, const std::string& where) {
  const size_t n = p.outline.size();
  if (n < 3) throw Error(fmt::format("{}.outline: expected at least 3 corners, got {}", where, n));
  for (size_t i = 0; i < n; ++i) {
    if (!p.outline[i].allFinite())
      throw Error(fmt::format("{}.outline[{}]: expected finite numbers", where, i));
    if ((p.outline[i] - p.outline[(i + 1) % n]).norm() < 1e-6)
      throw Error(fmt::format("{}.outline[{}]: expected a corner apart from the next one, got the same point", where, i));
  }
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // adjacent through the closing segment
      if (segmentsCross(p.outline[i], p.outline[(i + 1) % n], p.outline[j], p.outline[(j + 1) % n]))
        throw Error(fmt::format("{}.outline: expected a simple polygon, got segment {} crossing segment {}", where, i, j));
    }
  if (signedArea(p.outline) <= 0.0)
    throw Error(fmt::format("{}.outline: expected counter-clockwise corners (seen from the garment's outside), "
                            "got clockwise", where));
  if (!(p.bend >= 0.0)) throw Error(fmt::format("{}.bend: expected a radius >= 0 m, got {}", where, p.bend));
  if (p.bend > 0.0)
    for (const Vec2d& c : p.outline)
      if (std::abs(c.x()) > kPi * p.bend)
        throw Error(fmt::format("{}.bend: expected a radius that wraps the panel at most half way round (|u| <= "
                                "pi bend = {:.4g} m), got a corner at u = {}", where, kPi * p.bend, c.x()));
}

// a stretch of outline as a polyline: its corners and their arc lengths
struct Polyline {
  std::vector<int> corners;
  std::vector<double> at;  // m, arc length at each corner
  double length() const { return at.back(); }
};

Polyline polyline(const PatternPanel& p, const PatternEdge& e) {
  Polyline pl;
  const int n = static_cast<int>(p.outline.size());
  for (int c = e.from;; c = (c + 1) % n) {
    pl.at.push_back(pl.corners.empty() ? 0.0 : pl.at.back() + (p.outline[c] - p.outline[pl.corners.back()]).norm());
    pl.corners.push_back(c);
    if (c == e.to) break;
  }
  return pl;
}

// the point at arc length s along the polyline
Vec2d pointAt(const PatternPanel& p, const Polyline& pl, double s) {
  for (size_t k = 0; k + 1 < pl.corners.size(); ++k) {
    if (s > pl.at[k + 1] && k + 2 < pl.corners.size()) continue;
    const double len = pl.at[k + 1] - pl.at[k];
    const double t = std::clamp((s - pl.at[k]) / len, 0.0, 1.0);
    return (1.0 - t) * p.outline[pl.corners[k]] + t * p.outline[pl.corners[k + 1]];
  }
  return p.outline[pl.corners.back()];
}

// the arc-length fractions a seam's two sides are sampled at: n uniform segments (the longer side at
// most edgeLength a piece), the inner corners of both sides, and no two points closer than a quarter
// segment (a's corners win over b's, corners over uniform points)
std::vector<double> seamFractions(const Polyline& a, const Polyline& b, bool reverse, double edgeLength) {
  const int n = std::max(1, static_cast<int>(std::ceil(std::max(a.length(), b.length()) / edgeLength - 1e-9)));
  std::vector<std::pair<double, int>> cand;  // (fraction, rank: 0 a's corner, 1 b's corner, 2 uniform)
  for (size_t k = 1; k + 1 < a.at.size(); ++k) cand.push_back({a.at[k] / a.length(), 0});
  for (size_t k = 1; k + 1 < b.at.size(); ++k) {
    const double fb = b.at[k] / b.length();
    cand.push_back({reverse ? fb : 1.0 - fb, 1});
  }
  for (int k = 1; k < n; ++k) cand.push_back({double(k) / n, 2});
  std::stable_sort(cand.begin(), cand.end(), [](const auto& x, const auto& y) { return x.second < y.second; });
  const double tol = 0.25 / n;
  std::vector<double> kept = {0.0, 1.0};
  for (const auto& c : cand) {
    const double f = c.first;
    const bool near = std::any_of(kept.begin(), kept.end(), [&](double g) { return std::abs(g - f) < tol; });
    if (!near) kept.push_back(f);
  }
  std::sort(kept.begin(), kept.end());
  return kept;
}

// one side of a seam on its panel's outline, in the panel's counter-clockwise order
struct Stretch {
  PatternEdge edge;
  std::vector<Vec2d> points;  // from the `from` corner to the `to` corner
  std::vector<int> ring;      // the points' indices in the panel's boundary ring (filled by buildRing)
};

// the panel's boundary: every corner and outline point in counter-clockwise order, the stretches'
// points where seams run, uniform points of at most edgeLength elsewhere
std::vector<Vec2d> buildRing(const PatternPanel& p, int panel, std::vector<Stretch>& stretches, double edgeLength,
                             const std::string& where) {
  const int n = static_cast<int>(p.outline.size());
  std::vector<int> startsAt(static_cast<size_t>(n), -1), covered(static_cast<size_t>(n), -1);
  for (size_t s = 0; s < stretches.size(); ++s) {
    const PatternEdge& e = stretches[s].edge;
    if (e.panel != panel) continue;
    for (int c = e.from; c != e.to; c = (c + 1) % n) {
      if (covered[c] >= 0)
        throw Error(fmt::format("{}: expected each outline segment in at most one seam, got segment {} in seams {} "
                                "and {}", where, c, covered[c] / 2, s / 2));
      covered[c] = static_cast<int>(s);
    }
    startsAt[e.from] = static_cast<int>(s);
  }
  int start = 0;
  for (int c = 0; c < n; ++c)
    if (startsAt[c] >= 0 || covered[c] < 0) {
      start = c;
      break;
    }
  std::vector<Vec2d> ring;
  int c = start;
  do {
    if (startsAt[c] >= 0) {
      Stretch& st = stretches[startsAt[c]];
      st.ring.clear();
      for (size_t k = 0; k + 1 < st.points.size(); ++k) {
        st.ring.push_back(static_cast<int>(ring.size()));
        ring.push_back(st.points[k]);
      }
      c = st.edge.to;
      continue;
    }
    const Vec2d a = p.outline[c], b = p.outline[(c + 1) % n];
    const int pieces = std::max(1, static_cast<int>(std::ceil((b - a).norm() / edgeLength - 1e-9)));
    for (int k = 0; k < pieces; ++k) ring.push_back(a + (double(k) / pieces) * (b - a));
    c = (c + 1) % n;
  } while (c != start);
  // a stretch's last point is the ring point emitted at its end corner
  for (Stretch& st : stretches) {
    if (st.edge.panel != panel) continue;
    for (size_t k = 0; k < ring.size(); ++k)
      if ((ring[k] - st.points.back()).squaredNorm() == 0.0) st.ring.push_back(static_cast<int>(k));
    if (st.ring.size() != st.points.size())
      throw Error(fmt::format("{}: internal error: a seam's end corner is not on the outline", where));
  }
  return ring;
}

// the constrained Delaunay triangles of the points (the ring's first, then the rest) inside the
// ring, built from scratch in that order, each listed from its lowest vertex, in ascending order:
// the same triangles for the same points in any process (the mesher's own triangulation and face
// order depend on where its handles were allocated: a --set override changed the T-shirt's mesh)
void triangulatePoints(const std::vector<Vec2d>& points, size_t ringSize, const std::string& where,
                       std::vector<std::array<int, 3>>& triangles) {
  Cdt cdt;
  std::map<Cdt::Vertex_handle, int> index;
  std::vector<Cdt::Vertex_handle> handle;
  for (size_t k = 0; k < points.size(); ++k) {
    handle.push_back(cdt.insert(Cdt::Point(points[k].x(), points[k].y())));
    index[handle.back()] = static_cast<int>(k);
  }
  for (size_t k = 0; k < ringSize; ++k) cdt.insert_constraint(handle[k], handle[(k + 1) % ringSize]);
  // outside: the faces reached from the infinite ones without crossing the outline
  std::set<Cdt::Face_handle> outside;
  std::vector<Cdt::Face_handle> todo;
  for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f)
    if (cdt.is_infinite(f) && outside.insert(f).second) todo.push_back(f);
  while (!todo.empty()) {
    const Cdt::Face_handle f = todo.back();
    todo.pop_back();
    for (int k = 0; k < 3; ++k)
      if (!cdt.is_constrained({f, k}) && outside.insert(f->neighbor(k)).second) todo.push_back(f->neighbor(k));
  }
  triangles.clear();
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    if (outside.count(f)) continue;
    std::array<int, 3> t{index[f->vertex(0)], index[f->vertex(1)], index[f->vertex(2)]};  // counter-clockwise
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    triangles.push_back(t);
  }
  std::sort(triangles.begin(), triangles.end());
  std::map<std::pair<int, int>, int> edgeUses;
  for (const auto& t : triangles)
    for (int k = 0; k < 3; ++k) ++edgeUses[std::minmax(t[k], t[(k + 1) % 3])];
  const size_t boundaryEdges = static_cast<size_t>(
      std::count_if(edgeUses.begin(), edgeUses.end(), [](const auto& e) { return e.second == 1; }));
  if (boundaryEdges != ringSize || index.size() != points.size())
    throw Error(fmt::format("{}: internal error: the mesher changed the outline ({} boundary edges, {} outline "
                            "points)", where, boundaryEdges, ringSize));
}

// triangulates the ring (CGAL constrained Delaunay, refined to edgeLength without Steiner points on
// the outline, then Lloyd-smoothed); the first ring.size() vertices are the ring's, in order, the
// mesher's own after them in ascending (x, y)
void triangulateRing(const std::vector<Vec2d>& ring, double edgeLength, const std::string& where,
                     std::vector<Vec2d>& vertices, std::vector<std::array<int, 3>>& triangles) {
  Cdt cdt;
  std::vector<Cdt::Vertex_handle> handle;
  for (const Vec2d& q : ring) handle.push_back(cdt.insert(Cdt::Point(q.x(), q.y())));
  for (size_t k = 0; k < ring.size(); ++k) cdt.insert_constraint(handle[k], handle[(k + 1) % ring.size()]);
  // shape bound 0.125: smallest angle 20.7 degrees; the size bound caps the longest edge, and refined
  // edges come out at about 2/3 of it, so 1.5 edgeLength gives a median edge of about edgeLength
  Mesher mesher(cdt, Criteria(0.125, 1.5 * edgeLength));
  mesher.refine_mesh();
  CGAL::lloyd_optimize_mesh_2(cdt, CGAL::parameters::max_iteration_number = 10);
  const std::set<Cdt::Vertex_handle> onRing(handle.begin(), handle.end());
  std::vector<Vec2d> inner;
  for (auto v = cdt.finite_vertices_begin(); v != cdt.finite_vertices_end(); ++v)
    if (!onRing.count(v)) inner.emplace_back(v->point().x(), v->point().y());
  std::sort(inner.begin(), inner.end(), [](const Vec2d& a, const Vec2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  vertices = ring;
  vertices.insert(vertices.end(), inner.begin(), inner.end());
  triangulatePoints(vertices, ring.size(), where, triangles);
}

Vec3 place(const PatternPanel& p, const Vec2d& q) {
  const Vec3d right(std::cos(p.yaw), 0.0, -std::sin(p.yaw)), up(0.0, 1.0, 0.0);
  const Vec3d out = right.cross(up);
  double u = q.x(), w = 0.0;
  if (p.bend > 0.0) {
    u = p.bend * std::sin(q.x() / p.bend);
    w = p.bend * (std::cos(q.x() / p.bend) - 1.0);
  }
  return (p.origin + u * right + q.y() * up + w * out).cast<float>();
}

void checkEdge(const SewingPattern& pattern, const PatternEdge& e, const std::string& where) {
  if (e.panel < 0 || e.panel >= static_cast<int>(pattern.panels.size()))
    throw Error(fmt::format("{}.panel: expected a panel of the pattern, got index {}", where, e.panel));
  const int n = static_cast<int>(pattern.panels[e.panel].outline.size());
  for (const auto& [key, c] : {std::pair{"from", e.from}, std::pair{"to", e.to}})
    if (c < 0 || c >= n)
      throw Error(fmt::format("{}.{}: expected a corner index in [0, {}] of panel \"{}\", got {}", where, key, n - 1,
                              pattern.panels[e.panel].name, c));
  if (e.from == e.to) throw Error(fmt::format("{}: expected from != to, got both {}", where, e.from));
}

}  // namespace

double estimatedPatternVertices(const SewingPattern& pattern, double edgeLength) {
  double area = 0.0;
  for (const PatternPanel& p : pattern.panels) area += std::abs(signedArea(p.outline));
  return area / (0.5 * std::sqrt(3.0) * edgeLength * edgeLength);  // a vertex per two equilateral triangles
}

SewnGarment sewPattern(const SewingPattern& pattern, double edgeLength, const std::string& source) {
  if (pattern.panels.empty()) throw Error(fmt::format("{}: expected at least one panel, got none", at(source, "panels")));
  if (!(edgeLength > 0.0)) throw Error(fmt::format("{}: expected an edge length > 0 m, got {}", source, edgeLength));
  std::set<std::string> names;
  for (size_t i = 0; i < pattern.panels.size(); ++i) {
    const std::string where = at(source, fmt::format("panels[{}]", i));
    checkPanel(pattern.panels[i], where);
    if (!names.insert(pattern.panels[i].name).second)
      throw Error(fmt::format("{}.name: expected a name no other panel has, got \"{}\" again", where,
                              pattern.panels[i].name));
  }
  // both sides of every seam, sampled at the same fractions: stretches 2s (a) and 2s + 1 (b)
  std::vector<Stretch> stretches;
  for (size_t s = 0; s < pattern.seams.size(); ++s) {
    const PatternSeam& seam = pattern.seams[s];
    const std::string where = at(source, fmt::format("seams[{}]", s));
    checkEdge(pattern, seam.a, where + ".a");
    checkEdge(pattern, seam.b, where + ".b");
    const PatternPanel& pa = pattern.panels[seam.a.panel];
    const PatternPanel& pb = pattern.panels[seam.b.panel];
    const Polyline la = polyline(pa, seam.a), lb = polyline(pb, seam.b);
    const std::vector<double> f = seamFractions(la, lb, seam.reverse, edgeLength);
    Stretch a{seam.a, {}, {}}, b{seam.b, {}, {}};
    for (double x : f) a.points.push_back(pointAt(pa, la, x * la.length()));
    for (double x : f) b.points.push_back(pointAt(pb, lb, (seam.reverse ? x : 1.0 - x) * lb.length()));
    if (!seam.reverse) std::reverse(b.points.begin(), b.points.end());  // b's counter-clockwise order
    a.points.front() = pa.outline[seam.a.from];  // the corners exactly, not as rounded by pointAt
    a.points.back() = pa.outline[seam.a.to];
    b.points.front() = pb.outline[seam.b.from];
    b.points.back() = pb.outline[seam.b.to];
    stretches.push_back(std::move(a));
    stretches.push_back(std::move(b));
  }
  SewnGarment out;
  std::vector<int> firstVertex(pattern.panels.size());
  for (size_t i = 0; i < pattern.panels.size(); ++i) {
    const PatternPanel& p = pattern.panels[i];
    const std::string where = at(source, fmt::format("panels[{}]", i));
    const std::vector<Vec2d> ring = buildRing(p, static_cast<int>(i), stretches, edgeLength, where);
    std::vector<Vec2d> flat;
    std::vector<std::array<int, 3>> tris;
    triangulateRing(ring, edgeLength, where, flat, tris);
    firstVertex[i] = static_cast<int>(out.mesh.vertices.size());
    for (const Vec2d& q : flat) {
      out.mesh.vertices.push_back(place(p, q));
      out.panelOfVertex.push_back(static_cast<int>(i));
    }
    for (const auto& t : tris) out.mesh.triangles.push_back({t[0] + firstVertex[i], t[1] + firstVertex[i], t[2] + firstVertex[i]});
    out.panelNames.push_back(p.name);
  }
  std::set<std::array<int, 2>> pairs;
  for (size_t s = 0; s < pattern.seams.size(); ++s) {
    const Stretch& a = stretches[2 * s];
    const Stretch& b = stretches[2 * s + 1];
    const size_t m = a.ring.size();
    for (size_t k = 0; k < m; ++k) {
      const int va = firstVertex[a.edge.panel] + a.ring[k];
      const int vb = firstVertex[b.edge.panel] + b.ring[pattern.seams[s].reverse ? k : m - 1 - k];
      if (va != vb) pairs.insert({std::min(va, vb), std::max(va, vb)});
    }
  }
  out.seamPairs.assign(pairs.begin(), pairs.end());
  return out;
}

}  // namespace soak
