// the PBD cloth constraints of a model's cloth: stretch (Eq. 8) and bend (Eq. 9) of Shao 2017 section
// 3.2, one per edge of the PBD pieces, graph-coloured and scheduled for the parallel solver (cloth.cpp)
#include <algorithm>
#include <numeric>

#include "pbd/cloth.hpp"
#include "world/mesh.hpp"

namespace soak {

namespace {

// greedy first-fit colouring in constraint order: the smallest colour that none of the
// constraint's particles uses yet. Deterministic because the constraint order is.
template <size_t N>
std::vector<int> greedyColors(const std::vector<std::array<int, N>>& ids, int numParticles, int& numColors) {
  std::vector<std::vector<int>> used(numParticles);  // colours already touching each particle
  std::vector<int> color(ids.size());
  std::vector<int> forbidden;
  numColors = 0;
  for (size_t k = 0; k < ids.size(); ++k) {
    forbidden.clear();
    for (int v : ids[k]) forbidden.insert(forbidden.end(), used[v].begin(), used[v].end());
    std::sort(forbidden.begin(), forbidden.end());
    int c = 0;
    for (int f : forbidden) {
      if (f == c)
        ++c;
      else if (f > c)
        break;
    }
    color[k] = c;
    numColors = std::max(numColors, c + 1);
    for (int v : ids[k]) used[v].push_back(c);
  }
  return color;
}

template <class T>
void permute(std::vector<T>& a, const std::vector<int>& order) {
  std::vector<T> out(a.size());
  for (size_t k = 0; k < order.size(); ++k) out[k] = a[order[k]];
  a.swap(out);
}

// the slab of each cloth particle: numSlabs runs of equal count along the rest shape's longest axis
std::vector<int> restSlabs(const std::vector<Vec3>& rest, int numSlabs) {
  const int n = static_cast<int>(rest.size());
  std::vector<int> slab(rest.size(), 0);
  if (n == 0) return slab;
  Vec3 lo = rest[0], hi = rest[0];
  for (const Vec3& x : rest) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  int axis = 0;
  (hi - lo).maxCoeff(&axis);
  std::vector<int> order(rest.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return rest[a][axis] < rest[b][axis]; });
  for (int k = 0; k < n; ++k) slab[order[k]] = static_cast<int>(static_cast<int64_t>(k) * numSlabs / n);
  return slab;
}

// stable reorder by (group, colour) and the blocks of the schedule (ConstraintSchedule in model.hpp)
template <size_t N>
std::vector<int> scheduleOrder(const std::vector<std::array<int, N>>& ids, const std::vector<int>& color, int numColors,
                               const std::vector<int>& slab, int numSlabs, ConstraintSchedule& schedule) {
  const int groups = 2 * numSlabs;
  std::vector<int> group(ids.size());
  for (size_t k = 0; k < ids.size(); ++k) {
    int lo = numSlabs, hi = -1;
    for (int v : ids[k]) lo = std::min(lo, slab[v]), hi = std::max(hi, slab[v]);
    group[k] = lo == hi ? lo : (hi == lo + 1 ? numSlabs + lo : groups - 1);
  }
  std::vector<int> order(ids.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int x, int y) { return std::pair(group[x], color[x]) < std::pair(group[y], color[y]); });
  schedule.numSlabs = numSlabs;
  schedule.numColors = numColors;
  schedule.blockStart.clear();
  std::vector<int> blockGroup;
  for (size_t k = 0; k < order.size(); ++k) {
    const int g = group[order[k]], c = color[order[k]];
    if (k > 0 && g == group[order[k - 1]] && c == color[order[k - 1]]) continue;
    schedule.blockStart.push_back(static_cast<int>(k));
    blockGroup.push_back(g);
  }
  schedule.blockStart.push_back(static_cast<int>(order.size()));
  // blocks come group by group: group g's are [groupBlock[g], groupBlock[g + 1])
  schedule.groupBlock.assign(static_cast<size_t>(groups) + 1, 0);
  for (int g : blockGroup) ++schedule.groupBlock[static_cast<size_t>(g) + 1];
  for (int g = 0; g < groups; ++g) schedule.groupBlock[static_cast<size_t>(g) + 1] += schedule.groupBlock[static_cast<size_t>(g)];
  return order;
}

// piece of each triangle, for the per-piece material of its constraints
std::vector<int> trianglePieces(const Model& model) {
  std::vector<int> piece(model.triangles.size(), 0);
  for (int k = 0; k < static_cast<int>(model.pieces.size()); ++k) {
    const ClothPiece& p = model.pieces[k];
    std::fill(piece.begin() + p.firstTriangle, piece.begin() + p.firstTriangle + p.triangleCount, k);
  }
  return piece;
}

}  // namespace

// 1 / k with k = B |e|^2 / (A1 + A2): the hinge energy k theta^2 / 2 is then the plate energy B kappa^2 / 2
// of a cylindrical bend along the edges of a right-triangle or an equilateral lattice (docs/models.md,
// Eq. 9; Grinspun et al.'s discrete shells' 3 |e|^2 / (A1 + A2) counts such a bend three times)
float hingeCompliance(const ClothMaterial& mat, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  if (mat.bendCompliance >= 0.0f) return mat.bendCompliance;
  const Vec3d e = (b - a).cast<double>();
  const double areas = 0.5 * (e.cross((c - a).cast<double>()).norm() + e.cross((d - a).cast<double>()).norm());
  return static_cast<float>(areas / (static_cast<double>(mat.bendRigidity) * e.squaredNorm()));
}

void buildClothConstraints(Model& model) {
  const int n = model.numCloth;
  const std::vector<int> triPiece = trianglePieces(model);
  const std::vector<EdgeRef> edges = collectEdges(model.triangles);
  StretchConstraints stretch;
  BendConstraints bend;
  for (size_t s = 0; s < edges.size();) {
    size_t e = s;
    while (e < edges.size() && edges[e].lo == edges[s].lo && edges[e].hi == edges[s].hi) ++e;
    const EdgeRef& first = edges[s];
    const ClothMaterial& mat = model.pieces[triPiece[first.triangle]].material;
    if (model.pieces[triPiece[first.triangle]].solver == ClothSolver::Implicit) {  // springs in src/garment instead
      s = e;
      continue;
    }

    // Eq. 8: one stretch constraint per unique edge, rest length from the rest shape
    stretch.ids.push_back({first.lo, first.hi});
    stretch.restLength.push_back((model.clothRestPosition[first.lo] - model.clothRestPosition[first.hi]).norm());
    stretch.compliance.push_back(mat.stretchCompliance);

    // Eq. 9: one bend constraint per interior edge, oriented by the first triangle's winding
    if (e - s == 2) {
      const std::array<int, 4> ids{first.a, first.b, first.opposite, edges[s + 1].opposite};
      Vec3 grad[4];
      const auto& x = model.clothRestPosition;
      bend.ids.push_back(ids);
      bend.restAngle.push_back(bendConstraint(x[ids[0]], x[ids[1]], x[ids[2]], x[ids[3]], 0.0f, grad));
      bend.compliance.push_back(hingeCompliance(mat, x[ids[0]], x[ids[1]], x[ids[2]], x[ids[3]]));
    }
    s = e;
  }

  // slabs of about 1500 particles, at most 8 (the solver's parallel phases, src/pbd/cloth.cpp)
  const int numSlabs = std::clamp(n / 1500, 1, 8);
  const std::vector<int> slab = restSlabs(model.clothRestPosition, numSlabs);
  int numColors = 0;
  std::vector<int> color = greedyColors(stretch.ids, n, numColors);
  std::vector<int> order = scheduleOrder(stretch.ids, color, numColors, slab, numSlabs, stretch.schedule);
  permute(stretch.ids, order);
  permute(stretch.restLength, order);
  permute(stretch.compliance, order);

  color = greedyColors(bend.ids, n, numColors);
  order = scheduleOrder(bend.ids, color, numColors, slab, numSlabs, bend.schedule);
  permute(bend.ids, order);
  permute(bend.restAngle, order);
  permute(bend.compliance, order);

  model.stretch = std::move(stretch);
  model.bend = std::move(bend);
}

}  // namespace soak
