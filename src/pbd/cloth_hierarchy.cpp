// The PBD cloth's coarse levels (solver.clothHierarchy; after Müller 2008, "Hierarchical position based
// dynamics"): before each small step's constraint iterations, the distances between the centres of a few
// coarser meshes' clusters of particles are brought within their rest values, coarsest first, so that the
// load a pin holds reaches the whole sheet within one small step instead of a few edges an iteration
// (docs/models.md, Eq. 8, "The coarse levels"). Then solver.clothPinPasses passes over the inextensible
// edges near the pins, where that load concentrates (docs/models.md, Eq. 8, "The pins' neighbourhood").
#include "pbd/cloth.hpp"

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

namespace soak {

// each level's coarse edges, each a constraint C = |sum_i c_i x_i| - r over the particles of its two
// clusters (c_i = phi_a,i - phi_b,i, so sum_i c_i = 0)
struct ClothHierarchy {
  struct Level {
    std::vector<int> termStart;   // CSR over the level's edges: terms [termStart[e], termStart[e + 1])
    std::vector<int> particle;    // cloth particle id of a term
    std::vector<float> coef;      // its c_i
    std::vector<float> rest;      // m, r of each edge: |sum_i c_i X_i| on the rest shape X
  };
  std::vector<Level> levels;  // levels[0] the finest coarse level used (the second set: see build)
  Level pinRegion;            // the inextensible fine edges near the pins, each two terms (+1, -1)
  int numCloth = 0, maxLevels = 0, pinRings = 0;  // what it was built for
};

namespace {

// a level's graph: the neighbours of each member, as indices into members
using Graph = std::vector<std::vector<int>>;

// a cluster: (cloth particle id, phi) pairs, phi summing to 1
using Cluster = std::vector<std::pair<int, float>>;

// the fine graph: the 1-ring of each PBD cloth particle (implicit pieces have their own solver)
void fineGraph(const Model& model, std::vector<int>& members, Graph& graph) {
  const int n = model.numCloth;
  std::vector<int> local(static_cast<size_t>(n), -1);
  for (int i = 0; i < n; ++i)
    if (!model.implicitCloth(i)) {
      local[i] = static_cast<int>(members.size());
      members.push_back(i);
    }
  graph.assign(members.size(), {});
  for (size_t a = 0; a < members.size(); ++a) {
    const int i = members[a];
    for (int k = model.vertexNeighborStart[i]; k < model.vertexNeighborStart[i + 1]; ++k)
      if (local[model.vertexNeighbors[k]] >= 0) graph[a].push_back(local[model.vertexNeighbors[k]]);
  }
}

// the next level of (members, graph): the pins, then greedily in order every particle none of whose
// neighbours is taken (a maximal independent set); returns the taken ones' indices into members
std::vector<int> coarsen(const Model& model, const std::vector<int>& members, const Graph& graph) {
  std::vector<uint8_t> taken(members.size(), 0), blocked(members.size(), 0);
  const auto take = [&](size_t a) {
    taken[a] = 1;
    for (int b : graph[a]) blocked[b] = 1;
  };
  for (size_t a = 0; a < members.size(); ++a)
    if (model.clothPinned[members[a]]) take(a);
  for (size_t a = 0; a < members.size(); ++a)
    if (!taken[a] && !blocked[a]) take(a);
  std::vector<int> out;
  for (size_t a = 0; a < members.size(); ++a)
    if (taken[a]) out.push_back(static_cast<int>(a));
  return out;
}

// each taken particle's cluster: itself (weight 1) and each other particle of the level below that has
// it as a neighbour, weighted by its inverse rest distance over all its taken neighbours; phi = the
// weights over their sum. local: index among the taken, or -1
std::vector<Cluster> clusters(const Model& model, const std::vector<int>& members, const Graph& graph,
                              const std::vector<int>& local, size_t count) {
  std::vector<Cluster> out(count);
  for (size_t a = 0; a < members.size(); ++a) {
    if (local[a] >= 0) {
      out[local[a]].push_back({members[a], 1.0f});
      continue;
    }
    Cluster parents;
    float sum = 0.0f;
    for (int b : graph[a])
      if (local[b] >= 0) {
        const float dist = (model.clothRestPosition[members[a]] - model.clothRestPosition[members[b]]).norm();
        parents.push_back({local[b], 1.0f / std::max(dist, 1e-9f)});
        sum += parents.back().second;
      }
    for (const auto& [c, w] : parents) out[c].push_back({members[a], w / sum});
  }
  for (Cluster& c : out) {
    float sum = 0.0f;
    for (const auto& t : c) sum += t.second;
    for (auto& t : c) t.second /= sum;
  }
  return out;
}

// the constraint of the edge between clusters a and b: the terms phi_a - phi_b, merged per particle
// (slot: per cloth particle, its term's index in the edge or -1; left all -1)
void addEdge(const Model& model, const Cluster& a, const Cluster& b, std::vector<int>& slot,
             ClothHierarchy::Level& level) {
  const size_t first = level.particle.size();
  const auto add = [&](int i, float c) {
    if (slot[i] >= 0) {
      level.coef[slot[i]] += c;
      return;
    }
    slot[i] = static_cast<int>(level.particle.size());
    level.particle.push_back(i);
    level.coef.push_back(c);
  };
  for (const auto& [i, phi] : a) add(i, phi);
  for (const auto& [i, phi] : b) add(i, -phi);
  // sum_k c_k X_k with the X taken relative to the first term's, as projectLevel reads positions, so a
  // piece far from the origin gets the same r
  const Vec3 origin = model.clothRestPosition[level.particle[first]];
  Vec3 rest = Vec3::Zero();
  for (size_t k = first; k < level.particle.size(); ++k) {
    rest += level.coef[k] * (model.clothRestPosition[level.particle[k]] - origin);
    slot[level.particle[k]] = -1;
  }
  level.termStart.push_back(static_cast<int>(level.particle.size()));
  level.rest.push_back(rest.norm());
}

// builds the level of the taken members of (members, graph): its edges join taken particles that are
// neighbours or share a neighbour below; its own graph goes to `next`. False: too many terms
bool buildLevel(const Model& model, const std::vector<int>& members, const Graph& graph, const std::vector<int>& taken,
                ClothHierarchy::Level& level, Graph& next) {
  // a mesh of bounded valence has a few dozen terms a particle; a hub vertex (a fan of thousands of
  // triangles) would give its square: such a level is not built
  const size_t maxTerms = 64 * static_cast<size_t>(model.numCloth);
  std::vector<int> slot(static_cast<size_t>(model.numCloth), -1);
  std::vector<int> local(members.size(), -1);
  for (size_t c = 0; c < taken.size(); ++c) local[taken[c]] = static_cast<int>(c);
  const std::vector<Cluster> cluster = clusters(model, members, graph, local, taken.size());
  level.termStart.assign(1, 0);
  next.assign(taken.size(), {});
  for (size_t c = 0; c < taken.size(); ++c) {
    const int a = taken[c];
    for (int b : graph[a]) {
      if (local[b] >= 0) next[c].push_back(local[b]);
      else
        for (int e : graph[b])
          if (local[e] >= 0 && e != a) next[c].push_back(local[e]);
    }
    std::sort(next[c].begin(), next[c].end());
    next[c].erase(std::unique(next[c].begin(), next[c].end()), next[c].end());
    for (int d : next[c])
      if (d > static_cast<int>(c)) addEdge(model, cluster[c], cluster[d], slot, level);
    if (level.particle.size() > maxTerms) return false;
  }
  return true;
}

// the inextensible stretch edges (compliance 0) of the PBD cloth with both ends within `rings` edges of a
// pinned particle: a pin holds the load of the cloth below it, which reaches it through these few edges,
// so the constraint error of a few iterations concentrates on them (a point support's stress rises as
// 1/distance). Edges between two pins hold nothing and are left out.
ClothHierarchy::Level pinRegion(const Model& model, int rings) {
  const int n = model.numCloth;
  std::vector<uint8_t> near(static_cast<size_t>(n), 0);  // within `rings` edges of a pin
  std::vector<int> front, next;
  for (int i = 0; i < n; ++i)
    if (model.clothPinned[i] && !model.implicitCloth(i)) {
      near[i] = 1;
      front.push_back(i);
    }
  for (int r = 1; r <= rings && !front.empty(); ++r, front.swap(next)) {  // breadth first over the 1-rings
    next.clear();
    for (int i : front)
      for (int k = model.vertexNeighborStart[i]; k < model.vertexNeighborStart[i + 1]; ++k)
        if (const int j = model.vertexNeighbors[k]; !near[j] && !model.implicitCloth(j)) {
          near[j] = 1;
          next.push_back(j);
        }
  }
  ClothHierarchy::Level level;
  level.termStart.assign(1, 0);
  const StretchConstraints& st = model.stretch;
  for (size_t k = 0; k < st.ids.size(); ++k) {
    const auto [a, b] = st.ids[k];
    if (st.compliance[k] != 0.0f || !near[a] || !near[b] || (model.clothPinned[a] && model.clothPinned[b]))
      continue;
    level.particle.insert(level.particle.end(), {a, b});
    level.coef.insert(level.coef.end(), {1.0f, -1.0f});
    level.termStart.push_back(static_cast<int>(level.particle.size()));
    level.rest.push_back(st.restLength[k]);
  }
  return level;
}

void build(const Model& model, int maxLevels, int pinRings, ClothHierarchy& h) {
  h.numCloth = model.numCloth;
  h.maxLevels = maxLevels;
  h.pinRings = pinRings;
  if (pinRings > 0) h.pinRegion = pinRegion(model, pinRings);
  std::vector<int> members;
  Graph graph;
  fineGraph(model, members, graph);
  // the first set, two fine edges apart, only shapes the next: the constraint iterations already carry
  // a move that far, and its edges (15 terms each on a triangulated grid) would cost more than the rest
  for (int l = 0; maxLevels > 0 && l <= maxLevels; ++l) {
    const std::vector<int> taken = coarsen(model, members, graph);
    if (taken.size() < 4 || taken.size() == members.size()) break;  // nothing left to join
    ClothHierarchy::Level level;
    Graph next;
    if (!buildLevel(model, members, graph, taken, level, next) || level.rest.empty()) break;
    std::vector<int> kept(taken.size());
    for (size_t c = 0; c < taken.size(); ++c) kept[c] = members[taken[c]];
    members = std::move(kept);
    graph = std::move(next);
    if (l > 0) h.levels.push_back(std::move(level));
  }
}

// one Gauss-Seidel pass over the level's edges, each only while its clusters' centres are farther apart
// than at rest (C > 0: one-sided, a coarse edge that pushed would stop the finer mesh from folding),
// projected as any PBD constraint over the particles it reads: d_i -= w_i c_i (C / sum_j w_j c_j^2) n,
// a projection in the mass metric (momentum kept: sum_i c_i = 0; held particles, w = 0, stay)
void projectLevel(const ClothHierarchy::Level& level, const Vec3* base, Vec3* d, const float* w) {
  for (size_t e = 0; e + 1 < level.termStart.size(); ++e) {
    const int first = level.termStart[e], end = level.termStart[e + 1];
    const Vec3 origin = base[level.particle[first]];  // sum_i c_i = 0: the base enters as differences
    Vec3 x = Vec3::Zero();
    float den = 0.0f;
    for (int k = first; k < end; ++k) {
      const int i = level.particle[k];
      const float c = level.coef[k];
      x += c * ((base[i] - origin) + d[i]);
      den += w[i] * c * c;
    }
    const float len = x.norm();
    const float C = len - level.rest[e];
    if (!(C > 0.0f) || !(den > 0.0f)) continue;
    const Vec3 step = (C / (den * len)) * x;
    for (int k = first; k < end; ++k) d[level.particle[k]] -= (w[level.particle[k]] * level.coef[k]) * step;
  }
}

}  // namespace

void ClothHierarchyDeleter::operator()(ClothHierarchy* h) const { delete h; }

void solveHierarchyFrom(const Model& model, const Vec3* base, Vec3* displacement, const float* invMass,
                        ClothScratch& scratch) {
  const int maxLevels = model.solver.clothHierarchy, pinPasses = model.solver.clothPinPasses;
  const int pinRings = pinPasses > 0 ? model.solver.clothPinRings : 0;
  if ((maxLevels <= 0 && pinPasses <= 0) || model.numCloth == 0) return;
  ClothHierarchy* h = scratch.hierarchy.get();
  if (!h || h->numCloth != model.numCloth || h->maxLevels != maxLevels || h->pinRings != pinRings) {
    scratch.hierarchy.reset(h = new ClothHierarchy);
    build(model, maxLevels, pinRings, *h);
  }
  for (auto level = h->levels.rbegin(); level != h->levels.rend(); ++level)
    projectLevel(*level, base, displacement, invMass);
  // the pins' neighbourhood after the levels, which have just moved the cloth under it toward rest
  for (int pass = 0; pass < pinPasses; ++pass) projectLevel(h->pinRegion, base, displacement, invMass);
}

}  // namespace soak
