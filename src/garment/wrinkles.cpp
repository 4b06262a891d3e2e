// Chen et al. 2012 section 3.5: wrinkle disturbances from the most compressed spring (Eq. 25-26)
#include "garment/wrinkles.hpp"

#include <algorithm>
#include <cmath>
#include <deque>

namespace soak {

namespace {

uint64_t splitmix(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

bool insideCollider(const Model& model, const std::vector<ColliderPose>& poses, const Vec3& x, float margin) {
  const size_t n = std::min(model.colliders.size(), poses.size());
  for (size_t c = 0; c < n; ++c)
    if (colliderDistance(model.colliders[c], poses[c], x, nullptr) < margin) return true;
  return false;
}

}  // namespace

SphereIntersection intersectThreeSpheres(const Vec3& c1, float r1, const Vec3& c2, float r2, const Vec3& c3, float r3,
                                         float tolerance) {
  // Eq. 25 in the frame ex = (c2 - c1)/d, ey in the plane of the centres, ez = ex x ey
  SphereIntersection out;
  const Vec3d p1 = c1.cast<double>(), p2 = c2.cast<double>(), p3 = c3.cast<double>();
  const double d = (p2 - p1).norm();
  const double scale = std::max({d, (p3 - p1).norm(), 1e-30});
  if (!(d > 1e-9 * scale)) {
    out.degenerate = true;
    return out;
  }
  const Vec3d ex = (p2 - p1) / d;
  const double i = ex.dot(p3 - p1);
  const Vec3d rest = (p3 - p1) - i * ex;
  const double j = rest.norm();
  if (!(j > 1e-9 * scale)) {
    out.degenerate = true;
    return out;
  }
  const Vec3d ey = rest / j;
  const Vec3d ez = ex.cross(ey);
  const double R1 = r1, R2 = r2, R3 = r3;
  const double x = (R1 * R1 - R2 * R2 + d * d) / (2.0 * d);
  const double y = (R1 * R1 - R3 * R3 + i * i + j * j) / (2.0 * j) - (i / j) * x;
  const double z2 = R1 * R1 - x * x - y * y;
  const Vec3d base = p1 + x * ex + y * ey;
  const double tol = std::max(static_cast<double>(tolerance), 0.0);
  if (z2 < 0.0) {
    // the spheres miss each other, unless sphere 1 grown by the tolerance would reach (one tangent point)
    if (-z2 > 2.0 * R1 * tol + tol * tol) return out;
    out.count = 1;
    out.point[0] = base.cast<float>();
    return out;
  }
  const double z = std::sqrt(z2);
  if (z <= tol) {
    out.count = 1;
    out.point[0] = base.cast<float>();
    return out;
  }
  out.count = 2;
  out.point[0] = (base + z * ez).cast<float>();
  out.point[1] = (base - z * ez).cast<float>();
  return out;
}

float disturbanceCurvature(const Vec3& candidate, const Vec3& b, const Vec3& d) {
  const Vec3d v1 = (b - candidate).cast<double>(), v2 = (candidate - d).cast<double>();
  const double n1 = v1.norm(), n2 = v2.norm();
  if (!(n1 > 0.0) || !(n2 > 0.0)) return 0.0f;
  const double c = std::clamp(v1.dot(v2) / (n1 * n2), -1.0, 1.0);
  return static_cast<float>(2.0 / (n1 + n2) * std::acos(c));  // Eq. 26
}

int chooseDisturbance(const Vec3& a, const SphereIntersection& hits, const std::array<bool, 2>& collides,
                      const Vec3& b, const Vec3& d, float tieDistance, int coin) {
  if (hits.count <= 0) return -1;
  if (hits.count == 1) return collides[0] ? -1 : 0;  // step 2
  if (collides[0] && collides[1]) return -1;          // step 3
  if (collides[0]) return 1;
  if (collides[1]) return 0;
  const float d0 = (hits.point[0] - a).norm(), d1 = (hits.point[1] - a).norm();  // step 4
  if (std::abs(d0 - d1) > tieDistance) return d0 < d1 ? 0 : 1;
  const float k0 = disturbanceCurvature(hits.point[0], b, d), k1 = disturbanceCurvature(hits.point[1], b, d);
  if (std::abs(k0 - k1) > 1e-4f * std::max(std::abs(k0), std::abs(k1))) return k0 > k1 ? 0 : 1;  // steps 5-6
  return coin & 1;
}

namespace {

// one piece's springs at the current positions, as the disturbance model reads them
struct SpringView {
  const Model& model;
  const SpringSet& springs;
  const Particles& p;
  int first;       // the piece's first particle
  int stretchEnd;  // springs [0, stretchEnd) are the stretch springs
  const Vec3& pos(int v) const { return p.x[static_cast<size_t>(first + v)]; }
  bool pinned(int v) const { return model.clothPinned[static_cast<size_t>(first + v)] != 0; }
  float strain(int s) const {
    const float l0 = springs.restLength[s];
    return ((pos(springs.ids[s][1]) - pos(springs.ids[s][0])).norm() - l0) / l0;
  }
  // stretch springs of v, in spring order
  void stretchOf(int v, std::vector<int>& list) const {
    list.clear();
    for (int k = springs.vertexStart[v]; k < springs.vertexStart[v + 1]; ++k)
      if (springs.vertexSpring[k] < stretchEnd) list.push_back(springs.vertexSpring[k]);
  }
  float meanStrain(int v, std::vector<int>& list) const {
    stretchOf(v, list);
    float sum = 0.0f;
    for (int s : list) sum += strain(s);
    return list.empty() ? 0.0f : sum / static_cast<float>(list.size());
  }
};

// the most compressed stretch spring with both ends in subdomain k (lowest index on ties), compressed
// beyond the threshold; -1 if none
int mostCompressedSpring(const SpringView& view, const std::vector<int>& dom, int k, const std::vector<int>& owner,
                         float threshold, std::vector<int>& list) {
  const SpringSet& springs = view.springs;
  int best = -1;
  float bestEps = -threshold;
  for (int v : dom) {
    view.stretchOf(v, list);
    for (int s : list) {
      if (owner[springs.ids[s][0]] != k || owner[springs.ids[s][1]] != k) continue;
      const float e = view.strain(s);
      if (e < bestEps || (e == bestEps && best >= 0 && s < best)) {
        best = s;
        bestEps = e;
      }
    }
  }
  return best;
}

// C, D of Eq. 25: A's other stretch springs (not `best`, whose other end is B), most compressed first,
// with B, C, D not collinear; false if there are no two such
bool sideSprings(const SpringView& view, int a, int b, int best, std::vector<int>& list, int& sc, int& sd) {
  const SpringSet& springs = view.springs;
  view.stretchOf(a, list);
  std::vector<std::pair<float, int>> others;
  for (int s : list)
    if (s != best) others.push_back({view.strain(s), s});
  std::sort(others.begin(), others.end());
  const float l0ab = springs.restLength[best];
  for (size_t u = 0; u < others.size(); ++u)
    for (size_t w = u + 1; w < others.size(); ++w) {
      const Vec3 c = view.pos(springs.other(others[u].second, a)), d = view.pos(springs.other(others[w].second, a));
      if ((c - view.pos(b)).cross(d - view.pos(b)).norm() > 0.05f * l0ab * l0ab) {
        sc = others[u].second;
        sd = others[w].second;
        return true;
      }
    }
  return false;
}

}  // namespace

float disturbanceStrength(const WrinkleParams& params, float saturation) {
  const float s = std::clamp(std::isfinite(saturation) ? saturation : 0.0f, 0.0f, 1.0f);
  return params.dryStrength + (params.strength - params.dryStrength) * s;  // wetter cloth wrinkles more (section 3.5)
}

std::vector<PositionConstraint> computeDisturbances(const Model& model, int piece, const SpringSet& springs,
                                                    const std::vector<std::vector<int>>& subdomains,
                                                    const Particles& p, const std::vector<ColliderPose>& poses,
                                                    const WrinkleParams& params, uint64_t stepIndex,
                                                    std::span<const float> saturation) {
  std::vector<PositionConstraint> out;
  if (!params.enabled || params.interval < 1 || stepIndex % static_cast<uint64_t>(params.interval) != 0) return out;
  const SpringView view{model, springs, p, model.pieces[static_cast<size_t>(piece)].firstParticle, springs.kindStart[1]};
  const float margin = contactMargin(model, static_cast<int32_t>(piece + 1));
  std::vector<int> owner(static_cast<size_t>(springs.numVertices), -1);
  for (size_t k = 0; k < subdomains.size(); ++k)
    for (int v : subdomains[k]) owner[static_cast<size_t>(v)] = static_cast<int>(k);

  std::vector<int> list;
  for (size_t k = 0; k < subdomains.size(); ++k) {
    const std::vector<int>& dom = subdomains[k];
    if (dom.empty()) continue;
    // near equilibrium: the system energy (here the RMS speed) is low enough
    double v2 = 0.0;
    for (int v : dom) v2 += p.v[static_cast<size_t>(view.first + v)].squaredNorm();
    if (std::sqrt(v2 / static_cast<double>(dom.size())) > params.equilibriumSpeed) continue;
    const int best = mostCompressedSpring(view, dom, static_cast<int>(k), owner, params.compressionThreshold, list);
    if (best < 0) continue;
    // A: the free end whose stretch springs are more compressed on average
    int a = springs.ids[best][0], b = springs.ids[best][1];
    if (view.pinned(a) || (!view.pinned(b) && view.meanStrain(b, list) < view.meanStrain(a, list))) std::swap(a, b);
    if (view.pinned(a)) continue;
    int sc = -1, sd = -1;
    if (!sideSprings(view, a, b, best, list, sc, sd)) continue;
    const int c = springs.other(sc, a), d = springs.other(sd, a);
    const float l0ab = springs.restLength[best];
    // Eq. 25: where all three springs would be at rest length
    const SphereIntersection hits = intersectThreeSpheres(view.pos(b), l0ab, view.pos(c), springs.restLength[sc],
                                                          view.pos(d), springs.restLength[sd], 1e-4f * l0ab);
    if (hits.count == 0) continue;
    std::array<bool, 2> collides{false, false};
    for (int h = 0; h < hits.count; ++h) collides[h] = insideCollider(model, poses, hits.point[h], margin);
    const int coin = static_cast<int>(splitmix(splitmix(params.seed ^ (uint64_t(piece) << 32)) ^ (uint64_t(a) << 20) ^
                                               stepIndex) & 1u);
    const Vec3& pa = view.pos(a);
    const int pick = chooseDisturbance(pa, hits, collides, view.pos(b), view.pos(d), params.tieTolerance * l0ab, coin);
    // an imperfection is small: a target further than one rest length from A is not used (departure 14)
    if (pick < 0 || (hits.point[pick] - pa).norm() > l0ab) continue;
    const float strength = disturbanceStrength(params, static_cast<size_t>(a) < saturation.size() ? saturation[a] : 1.0f);
    if (strength > 0.0f) out.push_back({a, pa + strength * (hits.point[pick] - pa)});
  }
  return out;
}

std::vector<std::vector<int>> splitIntoPatches(int numVertices, const std::vector<std::array<int, 3>>& triangles,
                                               int targetSize) {
  const int n = std::max(numVertices, 0);
  const int target = std::max(targetSize, 1);
  std::vector<std::vector<int>> adj(static_cast<size_t>(n));
  for (const auto& t : triangles)
    for (int k = 0; k < 3; ++k) {
      adj[t[k]].push_back(t[(k + 1) % 3]);
      adj[t[(k + 1) % 3]].push_back(t[k]);
    }
  for (auto& a : adj) {
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
  }
  // breadth-first growth, target vertices per patch
  std::vector<int> patch(static_cast<size_t>(n), -1);
  std::vector<int> size;
  std::deque<int> queue;
  for (int seed = 0; seed < n; ++seed) {
    if (patch[seed] >= 0) continue;
    const int id = static_cast<int>(size.size());
    size.push_back(0);
    queue.assign(1, seed);
    patch[seed] = id;
    while (!queue.empty() && size[id] < target) {
      const int v = queue.front();
      queue.pop_front();
      ++size[id];
      for (int w : adj[v])
        if (patch[w] < 0 && size[id] + static_cast<int>(queue.size()) < target) {
          patch[w] = id;
          queue.push_back(w);
        }
    }
    for (int v : queue) patch[v] = -1;  // claimed but not reached: released for the next patch
    queue.clear();
  }
  // merge patches under half the target into their smallest neighbouring patch
  std::vector<int> parent(size.size());
  for (size_t i = 0; i < parent.size(); ++i) parent[i] = static_cast<int>(i);
  auto root = [&](int x) {
    while (parent[x] != x) x = parent[x];
    return x;
  };
  for (int id = 0; id < static_cast<int>(size.size()); ++id) {
    if (root(id) != id || size[id] * 2 >= target) continue;
    int into = -1;
    for (int v = 0; v < n; ++v) {
      if (root(patch[v]) != id) continue;
      for (int w : adj[v]) {
        const int r = root(patch[w]);
        if (r != id && (into < 0 || size[r] < size[into] || (size[r] == size[into] && r < into))) into = r;
      }
    }
    if (into < 0) continue;  // an isolated component: stays on its own
    parent[id] = into;
    size[into] += size[id];
  }
  std::vector<int> label(size.size(), -1);
  std::vector<std::vector<int>> out;
  for (int v = 0; v < n; ++v) {
    const int r = root(patch[v]);
    if (label[r] < 0) {
      label[r] = static_cast<int>(out.size());
      out.emplace_back();
    }
    out[label[r]].push_back(v);
  }
  return out;
}

}  // namespace soak
