#include "pbd/tethers.hpp"

#include "core/parallel.hpp"

#include <algorithm>
#include <limits>
#include <queue>
#include <utility>

namespace soak {

namespace {

// shortest path lengths from one source over the rest shape, along mesh edges and across the chords
// to the 2-ring. Edges alone overestimate the geodesic direction by direction (on a grid with one
// diagonal, 41% across the other diagonal), so tethers were slack one way and tight the other, and a
// sheet pinned at its corners creased along its middles; the 2-ring chords bring it within a few %
void pathLengths(const Model& model, int source, std::vector<float>& dist) {
  dist.assign(static_cast<size_t>(model.numCloth), std::numeric_limits<float>::infinity());
  using Item = std::pair<float, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  dist[source] = 0.0f;
  queue.push({0.0f, source});
  while (!queue.empty()) {
    // not a structured binding: the lambda below captures it, which C++17 forbids and not every C++20 compiler allows
    const float d = queue.top().first;
    const int i = queue.top().second;
    queue.pop();
    if (d > dist[i]) continue;
    const auto relax = [&](int j) {
      const float nd = d + (model.clothRestPosition[i] - model.clothRestPosition[j]).norm();
      if (nd < dist[j]) {
        dist[j] = nd;
        queue.push({nd, j});
      }
    };
    for (int k = model.vertexNeighborStart[i]; k < model.vertexNeighborStart[i + 1]; ++k) {
      const int j = model.vertexNeighbors[k];
      relax(j);
      for (int l = model.vertexNeighborStart[j]; l < model.vertexNeighborStart[j + 1]; ++l) relax(model.vertexNeighbors[l]);
    }
  }
}

}  // namespace

void buildTethers(Model& model, int maxAnchors) {
  const int n = model.numCloth;
  std::vector<std::vector<std::pair<float, int>>> candidates(static_cast<size_t>(n));
  std::vector<float> dist, slackOf(static_cast<size_t>(n), 0.0f);
  for (const ClothPiece& piece : model.pieces) {
    if (piece.solver == ClothSolver::Implicit) continue;  // pins are filtered in the implicit solve
    std::fill_n(slackOf.begin() + piece.firstParticle, piece.particleCount, piece.material.tetherSlack);
    std::vector<int> pins;
    for (int i = piece.firstParticle; i < piece.firstParticle + piece.particleCount; ++i)
      if (model.clothPinned[i]) pins.push_back(i);
    // many pins (a pinned edge or region): sample them evenly, a tether to every one is not needed
    const size_t stride = std::max<size_t>(1, pins.size() / 64);
    for (size_t k = 0; k < pins.size(); k += stride) {
      pathLengths(model, pins[k], dist);
      for (int i = piece.firstParticle; i < piece.firstParticle + piece.particleCount; ++i)
        if (!model.clothPinned[i] && dist[i] < std::numeric_limits<float>::infinity())
          candidates[i].push_back({dist[i], pins[k]});
    }
  }
  Tethers& t = model.tethers;
  t.start.assign(static_cast<size_t>(n) + 1, 0);
  t.anchor.clear();
  t.length.clear();
  for (int i = 0; i < n; ++i) {
    auto& c = candidates[i];
    std::sort(c.begin(), c.end());
    const size_t keep = std::min(c.size(), static_cast<size_t>(maxAnchors));
    const float slack = slackOf[static_cast<size_t>(i)];
    for (size_t k = 0; k < keep; ++k) {
      t.anchor.push_back(c[k].second);
      t.length.push_back(c[k].first * (1.0f + slack));
    }
    t.start[i + 1] = static_cast<int>(t.anchor.size());
  }
}

namespace {

// the anchor-to-particle vector d brought back onto the sphere |d| = length when outside it
bool pullIn(Vec3& d, float length) {
  const float len = d.norm();
  if (len <= length) return false;
  d *= length / len;
  return true;
}

}  // namespace

void solveTethers(const Model& model, Particles& p) {
  const Tethers& t = model.tethers;
  if (t.anchor.empty()) return;
  parallelFor(model.numCloth, [&](int64_t i) {
    for (int k = t.start[i]; k < t.start[i + 1]; ++k) {
      Vec3 d = p.xPred[i] - p.xPred[t.anchor[k]];
      if (pullIn(d, t.length[k])) p.xPred[i] = p.xPred[t.anchor[k]] + d;
    }
  });
}

void solveTethersFrom(const Model& model, const Vec3* base, Vec3* displacement) {
  const Tethers& t = model.tethers;
  if (t.anchor.empty()) return;
  parallelFor(model.numCloth, [&](int64_t i) {
    for (int k = t.start[i]; k < t.start[i + 1]; ++k) {
      const int a = t.anchor[k];
      Vec3 d = (base[i] - base[a]) + (displacement[i] - displacement[a]);
      if (pullIn(d, t.length[k])) displacement[i] = (base[a] - base[i]) + displacement[a] + d;
    }
  });
}

}  // namespace soak
