#include "pbd/tethers.hpp"

#include "core/parallel.hpp"

#include <algorithm>
#include <limits>
#include <queue>
#include <utility>

namespace soak {

namespace {

// shortest path lengths along edges from one source (Dijkstra over the 1-ring adjacency)
void pathLengths(const Model& model, int source, std::vector<float>& dist) {
  dist.assign(static_cast<size_t>(model.numCloth), std::numeric_limits<float>::infinity());
  using Item = std::pair<float, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  dist[source] = 0.0f;
  queue.push({0.0f, source});
  while (!queue.empty()) {
    const auto [d, i] = queue.top();
    queue.pop();
    if (d > dist[i]) continue;
    for (int k = model.vertexNeighborStart[i]; k < model.vertexNeighborStart[i + 1]; ++k) {
      const int j = model.vertexNeighbors[k];
      const float nd = d + (model.clothRestPosition[i] - model.clothRestPosition[j]).norm();
      if (nd < dist[j]) {
        dist[j] = nd;
        queue.push({nd, j});
      }
    }
  }
}

}  // namespace

void buildTethers(Model& model, int maxAnchors) {
  const int n = model.numCloth;
  std::vector<std::vector<std::pair<float, int>>> candidates(static_cast<size_t>(n));
  std::vector<float> dist;
  for (const ClothPiece& piece : model.pieces) {
    if (piece.solver == ClothSolver::Implicit) continue;  // pins are filtered in the implicit solve
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
    for (size_t k = 0; k < keep; ++k) {
      t.anchor.push_back(c[k].second);
      t.length.push_back(c[k].first);
    }
    t.start[i + 1] = static_cast<int>(t.anchor.size());
  }
}

void solveTethers(const Model& model, Particles& p) {
  const Tethers& t = model.tethers;
  if (t.anchor.empty()) return;
  parallelFor(model.numCloth, [&](int64_t i) {
    for (int k = t.start[i]; k < t.start[i + 1]; ++k) {
      const Vec3 d = p.xPred[i] - p.xPred[t.anchor[k]];
      const float len = d.norm();
      if (len > t.length[k]) p.xPred[i] = p.xPred[t.anchor[k]] + d * (t.length[k] / len);
    }
  });
}

}  // namespace soak
