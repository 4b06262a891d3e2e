// springs of Chen et al. 2012 section 3.2 and their KES force laws (Eq. 9-14)
#include "garment/springs.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace soak {

namespace {

int64_t pairKey(int a, int b) {
  const int lo = std::min(a, b), hi = std::max(a, b);
  return (static_cast<int64_t>(lo) << 32) | static_cast<int64_t>(static_cast<uint32_t>(hi));
}

struct Candidate {
  int64_t key;
  int a, b;
  float area;  // m^2, S_r of Eq. 6/9
};

// sorts by key and keeps the first of each key that is not in `taken` (sorted keys)
std::vector<Candidate> uniqueNotIn(std::vector<Candidate> c, const std::vector<int64_t>& taken) {
  std::stable_sort(c.begin(), c.end(), [](const Candidate& x, const Candidate& y) { return x.key < y.key; });
  std::vector<Candidate> out;
  for (const Candidate& x : c) {
    if (!out.empty() && out.back().key == x.key) continue;
    if (std::binary_search(taken.begin(), taken.end(), x.key)) continue;
    out.push_back(x);
  }
  return out;
}

struct HalfEdge {
  int64_t key;
  int opposite;   // third vertex of the triangle
  int triangle;
};

// every triangle's three edges as (key, opposite vertex, triangle), sorted by edge then triangle,
// and each triangle's rest area (m^2)
std::vector<HalfEdge> sortedHalfEdges(const std::vector<Vec3>& rest, const std::vector<std::array<int, 3>>& triangles,
                                      std::vector<double>& triArea) {
  triArea.resize(triangles.size());
  std::vector<HalfEdge> half;
  half.reserve(triangles.size() * 3);
  for (size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    const Vec3d a = rest[tri[0]].cast<double>(), b = rest[tri[1]].cast<double>(), c = rest[tri[2]].cast<double>();
    triArea[t] = 0.5 * (b - a).cross(c - a).norm();
    for (int k = 0; k < 3; ++k) half.push_back({pairKey(tri[k], tri[(k + 1) % 3]), tri[(k + 2) % 3], int(t)});
  }
  std::sort(half.begin(), half.end(), [](const HalfEdge& x, const HalfEdge& y) {
    return x.key != y.key ? x.key < y.key : x.triangle < y.triangle;
  });
  return half;
}

// stretch: unique edges, each with a third of the area of its triangles (sorted by key, as `half`);
// shear: the opposite vertices across an interior edge, with the edge's area share
void stretchAndShear(const std::vector<HalfEdge>& half, const std::vector<double>& triArea,
                     std::vector<Candidate>& stretch, std::vector<Candidate>& shear) {
  for (size_t s = 0; s < half.size();) {
    size_t e = s;
    double area = 0.0;
    while (e < half.size() && half[e].key == half[s].key) area += triArea[half[e++].triangle] / 3.0;
    const int a = static_cast<int>(half[s].key >> 32), b = static_cast<int>(half[s].key & 0xffffffff);
    stretch.push_back({half[s].key, a, b, static_cast<float>(area)});
    if (e - s == 2 && half[s].opposite != half[s + 1].opposite)
      shear.push_back({pairKey(half[s].opposite, half[s + 1].opposite), half[s].opposite, half[s + 1].opposite,
                       static_cast<float>(area)});
    s = e;
  }
}

// bend: for every edge (a, b), the pair (a, c) with c the neighbour of b that continues a -> b most
// straightly (cosine >= bendStraightness), with the mean area share of edges (a, b) and (b, c)
std::vector<Candidate> bendCandidates(const std::vector<Vec3>& rest, const std::vector<Candidate>& stretch,
                                      const SpringBuildOptions& options) {
  const int n = static_cast<int>(rest.size());
  std::vector<Candidate> bend;
  // 1-ring with the index of the stretch spring of each edge
  std::vector<std::vector<std::pair<int, int>>> ring(n);
  for (int k = 0; k < static_cast<int>(stretch.size()); ++k) {
    ring[stretch[k].a].push_back({stretch[k].b, k});
    ring[stretch[k].b].push_back({stretch[k].a, k});
  }
  for (auto& r : ring) std::sort(r.begin(), r.end());
  for (int a = 0; a < n; ++a) {
    for (const auto& [b, ab] : ring[a]) {
      const Vec3d dir = (rest[b] - rest[a]).cast<double>().normalized();
      int best = -1, bestEdge = -1;
      double bestCos = options.bendStraightness;
      for (const auto& [c, bc] : ring[b]) {
        if (c == a) continue;
        const double cosTurn = dir.dot((rest[c] - rest[b]).cast<double>().normalized());
        if (cosTurn >= bestCos && (best < 0 || cosTurn > bestCos)) {
          best = c;
          bestEdge = bc;
          bestCos = cosTurn;
        }
      }
      if (best >= 0 && best != a)
        bend.push_back({pairKey(a, best), a, best, 0.5f * (stretch[ab].area + stretch[bestEdge].area)});
    }
  }
  return bend;
}

// the springs of the three kinds in order, with rest length l0 and width L0 = S_r / l0 (Eq. 9)
void appendSprings(SpringSet& out, const std::vector<Vec3>& rest, const std::vector<Candidate>* const kinds[3]) {
  for (int k = 0; k < 3; ++k) {
    out.kindStart[k] = out.size();
    for (const Candidate& c : *kinds[k]) {
      const int lo = std::min(c.a, c.b), hi = std::max(c.a, c.b);
      const float l0 = (rest[hi] - rest[lo]).norm();
      out.ids.push_back({lo, hi});
      out.restLength.push_back(l0);
      out.width.push_back(l0 > 0.0f ? c.area / l0 : 0.0f);
    }
  }
  out.kindStart[3] = out.size();
}

// the seams after the mesh springs: rest length = the starting gap, no width
void appendSeams(SpringSet& out, const std::vector<Vec3>& rest, const std::vector<std::array<int, 2>>& seams) {
  std::vector<int64_t> taken;
  for (const auto& id : out.ids) taken.push_back(pairKey(id[0], id[1]));
  std::sort(taken.begin(), taken.end());
  std::vector<int64_t> added;
  for (const auto& pr : seams) {
    const int64_t key = pairKey(pr[0], pr[1]);
    if (pr[0] == pr[1] || std::binary_search(taken.begin(), taken.end(), key)) continue;
    if (std::find(added.begin(), added.end(), key) != added.end()) continue;
    added.push_back(key);
    const int lo = std::min(pr[0], pr[1]), hi = std::max(pr[0], pr[1]);
    out.ids.push_back({lo, hi});
    out.restLength.push_back((rest[hi] - rest[lo]).norm());
    out.width.push_back(0.0f);
  }
  out.kindStart[4] = out.size();
}

// the CSR of the springs at each vertex (counts, prefix sums, then each spring in ascending order)
void indexSpringsByVertex(SpringSet& out) {
  const int n = out.numVertices;
  out.vertexStart.assign(n + 1, 0);
  for (const auto& id : out.ids) {
    ++out.vertexStart[id[0] + 1];
    ++out.vertexStart[id[1] + 1];
  }
  for (int v = 0; v < n; ++v) out.vertexStart[v + 1] += out.vertexStart[v];
  out.vertexSpring.assign(out.vertexStart[n], 0);
  std::vector<int> fill(out.vertexStart.begin(), out.vertexStart.end() - 1);
  for (int s = 0; s < out.size(); ++s) {
    out.vertexSpring[fill[out.ids[s][0]]++] = s;
    out.vertexSpring[fill[out.ids[s][1]]++] = s;
  }
}

}  // namespace

SpringSet buildSprings(const std::vector<Vec3>& rest, const std::vector<std::array<int, 3>>& triangles,
                       const SpringBuildOptions& options, const std::vector<std::array<int, 2>>& seams) {
  std::vector<double> triArea;
  const std::vector<HalfEdge> half = sortedHalfEdges(rest, triangles, triArea);
  std::vector<Candidate> stretch, shear;
  stretchAndShear(half, triArea, stretch, shear);
  std::vector<int64_t> taken;
  for (const Candidate& c : stretch) taken.push_back(c.key);  // already sorted and unique
  std::vector<Candidate> bend = bendCandidates(rest, stretch, options);
  // a pair that is both a straight skip-one pair and a pair across an edge is a bend spring
  bend = uniqueNotIn(std::move(bend), taken);
  for (const Candidate& c : bend) taken.push_back(c.key);
  std::sort(taken.begin(), taken.end());
  shear = uniqueNotIn(std::move(shear), taken);

  SpringSet out;
  out.numVertices = static_cast<int>(rest.size());
  const std::vector<Candidate>* const kinds[3] = {&stretch, &shear, &bend};
  appendSprings(out, rest, kinds);
  appendSeams(out, rest, seams);
  indexSpringsByVertex(out);
  return out;
}

SpringSet buildPieceSprings(const Model& model, int piece, const SpringBuildOptions& options) {
  const ClothPiece& pc = model.pieces[static_cast<size_t>(piece)];
  std::vector<Vec3> rest(model.clothRestPosition.begin() + pc.firstParticle,
                         model.clothRestPosition.begin() + pc.firstParticle + pc.particleCount);
  std::vector<std::array<int, 3>> tris(static_cast<size_t>(pc.triangleCount));
  for (int t = 0; t < pc.triangleCount; ++t)
    for (int k = 0; k < 3; ++k) tris[t][k] = model.triangles[pc.firstTriangle + t][k] - pc.firstParticle;
  return buildSprings(rest, tris, options, pc.seams);
}

float kesPoleStrain(const KesLaw& law) { return law.a2 > 0.0f ? 1.0f / law.a2 : std::numeric_limits<float>::infinity(); }

float kesContinuationStrain(const KesLaw& law, float strainLimit) {
  return law.a2 > 0.0f ? strainLimit / law.a2 : std::numeric_limits<float>::infinity();
}

float kesStretchStress(float eps, const KesLaw& law, float strainLimit, float* dsigma) {
  const float a = std::abs(eps);
  const float sign = eps < 0.0f ? -1.0f : 1.0f;
  // Eq. 11 and its derivative Eq. 13: sigma' = a1 (1 + 2 a2 |eps|) / (1 - a2 |eps|)^4
  auto law11 = [&](float e, float* d) {
    const float q = 1.0f - law.a2 * e;
    const float q3 = q * q * q;
    *d = law.a1 * (1.0f + 2.0f * law.a2 * e) / (q3 * q);
    return law.a1 * e / q3;
  };
  if (const float ec = kesContinuationStrain(law, strainLimit); a > ec) {
    float dc;
    const float sc = law11(ec, &dc);
    if (dsigma) *dsigma = dc;
    return sign * (sc + dc * (a - ec));
  }
  float d;
  const float s = law11(a, &d);
  if (dsigma) *dsigma = d;
  return sign * s;
}

float kesBendStress(float eps, const KesLaw& law, float* dsigma) {
  const float a = std::abs(eps);
  if (dsigma) *dsigma = law.a1 + 2.0f * law.a2 * a;
  return law.a1 * eps + law.a2 * eps * a;  // Eq. 14
}

double kesStretchEnergy(double eps, const KesLaw& law, float strainLimit) {
  const double a = std::abs(eps);
  auto w = [&](double e) {
    const double q = 1.0 - law.a2 * e;
    return law.a1 * e * e / (2.0 * q * q);
  };
  if (const double ec = kesContinuationStrain(law, strainLimit); a > ec) {
    const double q = 1.0 - law.a2 * ec;
    const double sc = law.a1 * ec / (q * q * q);
    const double dc = law.a1 * (1.0 + 2.0 * law.a2 * ec) / (q * q * q * q);
    const double r = a - ec;
    return w(ec) + sc * r + 0.5 * dc * r * r;
  }
  return w(a);
}

double kesBendEnergy(double eps, const KesLaw& law) {
  const double a = std::abs(eps);
  return 0.5 * law.a1 * a * a + law.a2 * a * a * a / 3.0;
}

float springStress(const SpringSet& springs, const SpringLaws& laws, int s, float eps, float* dsigma) {
  switch (springs.kind(s)) {
    case SpringKind::Stretch:
      return kesStretchStress(eps, laws.stretch, laws.strainLimit, dsigma);
    case SpringKind::Shear:
      return kesStretchStress(eps, laws.shear, laws.strainLimit, dsigma);
    case SpringKind::Bend:
      return kesBendStress(eps, laws.bend, dsigma);
    case SpringKind::Seam:
      break;
  }
  if (dsigma) *dsigma = 0.0f;
  return 0.0f;
}

void seamForce(float k, float r, const Vec3& xi, const Vec3& xj, Vec3d& fi, Eigen::Matrix3d* K) {
  const Vec3d d = (xj - xi).cast<double>();
  const double l = d.norm();
  if (!(l > 1e-9)) {
    fi.setZero();
    if (K) *K = double(k) * Eigen::Matrix3d::Identity();
    return;
  }
  const Vec3d u = d / l;
  fi = (double(k) * (l - r)) * u;
  if (K) {
    const Eigen::Matrix3d uu = u * u.transpose();
    *K = double(k) * (uu + (std::max(l - r, 0.0) / l) * (Eigen::Matrix3d::Identity() - uu));
  }
}

float springForce(const SpringSet& springs, const SpringLaws& laws, int s, const Vec3& xi, const Vec3& xj, Vec3d& fi,
                  Eigen::Matrix3d* K) {
  if (springs.kind(s) == SpringKind::Seam) {
    seamForce(laws.seamStiffness, 0.0f, xi, xj, fi, K);
    return 0.0f;
  }
  const double l0 = springs.restLength[s];
  const double L0 = springs.width[s];
  const Vec3d d = (xj - xi).cast<double>();
  const double l = d.norm();
  if (!(l > 1e-12 * l0) || !(l0 > 0.0)) {
    // coincident ends: no direction, no force; the spring keeps only its axial stiffness isotropically
    fi.setZero();
    if (K) {
      float ds = 0.0f;
      springStress(springs, laws, s, -1.0f, &ds);
      *K = (L0 * ds / l0) * Eigen::Matrix3d::Identity();
    }
    return -1.0f;
  }
  const Vec3d u = d / l;
  const float eps = static_cast<float>((l - l0) / l0);  // Eq. 7-8
  float ds = 0.0f;
  const double sigma = springStress(springs, laws, s, eps, &ds);
  fi = (L0 * sigma) * u;  // Eq. 12
  if (K) {
    const Eigen::Matrix3d uu = u * u.transpose();
    *K = L0 * ((ds / l0) * uu + (std::max(sigma, 0.0) / l) * (Eigen::Matrix3d::Identity() - uu));
  }
  return eps;
}

double elasticEnergy(const SpringSet& springs, const SpringLaws& laws, const Vec3* x) {
  double e = 0.0;
  for (int s = 0; s < springs.size(); ++s) {
    if (springs.kind(s) == SpringKind::Seam) {  // closed: 1/2 k l^2
      e += 0.5 * laws.seamStiffness * (x[springs.ids[s][1]] - x[springs.ids[s][0]]).cast<double>().squaredNorm();
      continue;
    }
    const double l0 = springs.restLength[s];
    const double eps = ((x[springs.ids[s][1]] - x[springs.ids[s][0]]).cast<double>().norm() - l0) / l0;
    double w = 0.0;
    switch (springs.kind(s)) {
      case SpringKind::Stretch:
        w = kesStretchEnergy(eps, laws.stretch, laws.strainLimit);
        break;
      case SpringKind::Shear:
        w = kesStretchEnergy(eps, laws.shear, laws.strainLimit);
        break;
      case SpringKind::Bend:
        w = kesBendEnergy(eps, laws.bend);
        break;
      case SpringKind::Seam:
        break;
    }
    e += springs.width[s] * l0 * w;
  }
  return e;
}

}  // namespace soak
