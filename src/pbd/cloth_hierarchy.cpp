// The PBD cloth's coarse levels (solver.clothHierarchy; Müller 2008, "Hierarchical position based
// dynamics"): before each small step's constraint iterations, the sheet's particles are brought within
// the distances of a few coarser meshes, coarsest first, and each level's moves are interpolated to the
// particles of the level below it, so that the load a pin holds reaches the whole sheet within one small
// step instead of a few edges an iteration (docs/models.md, Eq. 8, "The coarse levels").
#include "pbd/cloth.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

namespace soak {

// one coarse level: a subset of the next finer level's particles (a maximal independent set of its
// graph, the pins always in), joined where they are neighbours or share a neighbour there
struct ClothHierarchy {
  struct Level {
    std::vector<int> members;                 // cloth particle ids
    std::vector<std::array<int, 2>> edges;    // indices into members
    std::vector<float> rest;                  // m, the edges' distances on the rest shape
    // the finer level's particles that are not members, each moved by its parents' moves, weighted
    std::vector<int> children;                // cloth particle ids
    std::vector<int> parentStart;             // CSR over children: parents [parentStart[c], parentStart[c + 1])
    std::vector<int> parents;                 // indices into members
    std::vector<float> weights;               // sum to 1 over a child's parents
    std::vector<float> invMass;               // 1/kg per member: its own mass plus its children's shares
  };
  std::vector<Level> levels;  // levels[0] the finest coarse level
  int numCloth = 0, maxLevels = 0;  // what it was built for
  std::vector<Vec3> start;    // m, the displacement at the hierarchy's start (solveHierarchyFrom)
  std::vector<float> mass;    // kg per cloth particle: its own, or lumped at the coarsest level it is in
};

namespace {

// a level's graph: the neighbours of each member, as indices into members
using Graph = std::vector<std::vector<int>>;

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
// neighbours is taken; returns the taken ones' indices into members
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

float restDistance(const Model& model, int i, int j) {
  return (model.clothRestPosition[i] - model.clothRestPosition[j]).norm();
}

// builds the level of the taken members of (members, graph), and its own graph into `next`
void buildLevel(const Model& model, const std::vector<int>& members, const Graph& graph, const std::vector<int>& taken,
                ClothHierarchy::Level& level, Graph& next) {
  std::vector<int> local(members.size(), -1);
  for (size_t c = 0; c < taken.size(); ++c) {
    local[taken[c]] = static_cast<int>(c);
    level.members.push_back(members[taken[c]]);
  }
  // each other particle's parents: its taken neighbours, weighted by the inverse rest distance
  level.parentStart.push_back(0);
  for (size_t a = 0; a < members.size(); ++a) {
    if (local[a] >= 0) continue;
    float sum = 0.0f;
    const size_t first = level.parents.size();
    for (int b : graph[a])
      if (local[b] >= 0) {
        const float w = 1.0f / std::max(restDistance(model, members[a], members[b]), 1e-9f);
        level.parents.push_back(local[b]);
        level.weights.push_back(w);
        sum += w;
      }
    if (level.parents.size() == first) continue;  // no taken neighbour: only when the set is not maximal
    for (size_t k = first; k < level.weights.size(); ++k) level.weights[k] /= sum;
    level.children.push_back(members[a]);
    level.parentStart.push_back(static_cast<int>(level.parents.size()));
  }
  // the level's edges: taken particles that are neighbours or share a neighbour below
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
      if (d > static_cast<int>(c)) {
        level.edges.push_back({static_cast<int>(c), d});
        level.rest.push_back(restDistance(model, level.members[c], level.members[d]));
      }
  }
}

void build(const Model& model, int maxLevels, ClothHierarchy& h) {
  h.numCloth = model.numCloth;
  h.maxLevels = maxLevels;
  std::vector<int> members;
  Graph graph;
  fineGraph(model, members, graph);
  for (int l = 0; l < maxLevels; ++l) {
    const std::vector<int> taken = coarsen(model, members, graph);
    if (taken.size() < 4 || taken.size() == members.size()) break;  // nothing left to join
    ClothHierarchy::Level level;
    Graph next;
    buildLevel(model, members, graph, taken, level, next);
    if (level.edges.empty()) break;
    members = level.members;
    graph = std::move(next);
    h.levels.push_back(std::move(level));
  }
}

// each member's inverse mass: its own mass plus the shares of the finer level's particles it carries
// (weights over their parents), so a coarse move keeps the momentum of the particles it moves; a pinned
// member (inverse mass 0) stays put. Computed from the present (wet) masses, finest level first
void lumpMasses(ClothHierarchy& h, const float* invMass, int numCloth) {
  std::vector<float>& mass = h.mass;
  mass.resize(static_cast<size_t>(numCloth));
  for (int i = 0; i < numCloth; ++i) mass[i] = invMass[i] > 0.0f ? 1.0f / invMass[i] : 0.0f;
  for (ClothHierarchy::Level& level : h.levels) {
    std::vector<float>& lumped = level.invMass;  // the masses first, inverted below
    lumped.resize(level.members.size());
    for (size_t c = 0; c < level.members.size(); ++c) lumped[c] = mass[level.members[c]];
    for (size_t c = 0; c < level.children.size(); ++c)
      for (int k = level.parentStart[c]; k < level.parentStart[c + 1]; ++k)
        lumped[level.parents[k]] += level.weights[k] * mass[level.children[c]];
    for (size_t c = 0; c < level.members.size(); ++c) {
      const int i = level.members[c];
      mass[i] = lumped[c];
      lumped[c] = invMass[i] > 0.0f && lumped[c] > 0.0f ? 1.0f / lumped[c] : 0.0f;  // held: stays put
    }
  }
}

// one Gauss-Seidel pass over the level's edges, each only when stretched beyond its rest distance
// (C = |x_a - x_b| - r > 0): a coarse edge that pushed would stop the finer mesh from folding
void projectLevel(const ClothHierarchy::Level& level, const Vec3* base, Vec3* d) {
  for (size_t e = 0; e < level.edges.size(); ++e) {
    const int ca = level.edges[e][0], cb = level.edges[e][1];
    const float wa = level.invMass[ca], wb = level.invMass[cb];
    if (wa + wb <= 0.0f) continue;
    const int a = level.members[ca], b = level.members[cb];
    const Vec3 x = (base[a] - base[b]) + (d[a] - d[b]);  // x_a - x_b of x = base + d
    const float len = x.norm();
    const float C = len - level.rest[e];
    if (!(C > 0.0f)) continue;
    const Vec3 s = (C / ((wa + wb) * len)) * x;
    d[a] -= wa * s;
    d[b] += wb * s;
  }
}

}  // namespace

void ClothHierarchyDeleter::operator()(ClothHierarchy* h) const { delete h; }

void solveHierarchyFrom(const Model& model, const Vec3* base, Vec3* displacement, const float* invMass,
                        ClothScratch& scratch) {
  const int maxLevels = model.solver.clothHierarchy;
  if (maxLevels <= 0 || model.numCloth == 0) return;
  if (!scratch.hierarchy || scratch.hierarchy->numCloth != model.numCloth || scratch.hierarchy->maxLevels != maxLevels) {
    scratch.hierarchy.reset(new ClothHierarchy);
    build(model, maxLevels, *scratch.hierarchy);
  }
  ClothHierarchy& h = *scratch.hierarchy;
  if (h.levels.empty()) return;
  lumpMasses(h, invMass, model.numCloth);
  h.start.assign(displacement, displacement + model.numCloth);
  // coarsest first; a level's children take their parents' moves since the start (what the coarser
  // levels and this one moved them by), weighted
  for (auto level = h.levels.rbegin(); level != h.levels.rend(); ++level) {
    projectLevel(*level, base, displacement);
    for (size_t c = 0; c < level->children.size(); ++c) {
      Vec3 move = Vec3::Zero();
      for (int k = level->parentStart[c]; k < level->parentStart[c + 1]; ++k) {
        const int i = level->members[level->parents[k]];
        move += level->weights[k] * (displacement[i] - h.start[i]);
      }
      const int child = level->children[c];
      if (invMass[child] > 0.0f) displacement[child] += move;
    }
  }
}

}  // namespace soak
