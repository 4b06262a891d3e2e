// particle-particle self-collision of the PBD cloth (Müller et al. 2007, thickness d): with small steps,
// after each of them over the pairs found near at the substep's start; with one step, once after it
// over all neighbours (docs/models.md, "Cloth self-collision in the small steps")
#include "core/parallel.hpp"
#include "pbd/cloth.hpp"

#include <algorithm>
#include <cmath>

namespace soak {

namespace {

// a candidate pair is within (1 + kCandidateMargin) d plus the distance the two close in the substep
// at their relative speed, |v_i - v_j| h, at its start: the small steps' constraints move a particle by
// a small part of d, and a wider reach took every unconnected diagonal of a flat mesh (1.4 spacings)
constexpr float kCandidateMargin = 0.25f;

// what a pair (i, j) of one piece may push: d of i's piece where the piece is PBD with self-collision
// and i moves, 0 otherwise
float selfCollisionThickness(const Model& model, const Particles& p, int i) {
  const int piece = clothPiece(p.phase[i]);
  if (piece < 0 || piece >= static_cast<int>(model.pieces.size())) return 0.0f;
  const ClothMaterial& mat = model.pieces[piece].material;
  // an implicit piece has its own (garment/self_collision.hpp)
  if (!mat.selfCollision || p.invMass[i] == 0.0f || model.pieces[piece].solver != ClothSolver::Pbd) return 0.0f;
  return mat.thickness;
}

// whether j, closer to i than `reach`, is a pair of i's: not i's 1-ring neighbour, of the same piece,
// not both held, and apart by more than d at rest (pairs this close at rest belong together: fine
// meshes, seams; Eq. 8 keeps them). The distance comes first: nearly every neighbour is farther.
bool isPair(const Model& model, const Particles& p, int i, int j, float d, float reach, float& dist2) {
  dist2 = (p.xPred[i] - p.xPred[j]).squaredNorm();
  if (dist2 >= reach * reach || dist2 < 1e-24f) return false;
  const auto ring = model.vertexNeighbors.begin();
  if (std::binary_search(ring + model.vertexNeighborStart[i], ring + model.vertexNeighborStart[i + 1], j)) return false;
  if (j == i || p.phase[j] != p.phase[i] || p.invMass[i] + p.invMass[j] == 0.0f) return false;
  return (model.clothRestPosition[i] - model.clothRestPosition[j]).squaredNorm() > d * d;
}

// i's move away from j at distance dist < d: w_i/(w_i + w_j) (d - dist) x_ij/dist
Vec3 pushApart(const Particles& p, int i, int j, float d, float dist) {
  const float wi = p.invMass[i], wj = p.invMass[j];
  return (wi / (wi + wj) * (d - dist) / dist) * Vec3(p.xPred[i] - p.xPred[j]);
}

// adds the gathered moves delta[r] to particle owner[r] (owner null: particle r), r < count (Jacobi: the
// result does not depend on the thread count); returns the pairs pushed, each seen from both sides
int applyMoves(Particles& p, ClothScratch& scratch, int count, const int* owner) {
  Vec3* x = p.xPred.data();
  const Vec3* delta = scratch.delta.data();
  parallelFor(count, [&](int64_t r) { x[owner ? owner[r] : r] += delta[r]; });
  int contacts = 0;
  for (int r = 0; r < count; ++r) contacts += scratch.contacts[r];
  return contacts;
}

}  // namespace

int clothSelfCollision(const Model& model, Particles& p, const NeighborLists& neighbors, ClothScratch& scratch) {
  const int n = model.numCloth;
  scratch.delta.assign(n, Vec3::Zero());
  scratch.contacts.assign(n, 0);
  if (n == 0) return 0;
  parallelForDynamic(n, kClothChunk, [&](int64_t ii) {  // folds have more neighbours
    const int i = static_cast<int>(ii);
    const float d = selfCollisionThickness(model, p, i);
    if (d <= 0.0f) return;
    Vec3 sum = Vec3::Zero();
    for (uint32_t s = neighbors.start[i], end = neighbors.clothEnd(i, static_cast<uint32_t>(n)); s < end; ++s) {
      const int j = static_cast<int>(neighbors.index[s]);
      float dist2 = 0.0f;
      if (j < n && isPair(model, p, i, j, d, d, dist2)) {
        sum += pushApart(p, i, j, d, std::sqrt(dist2));
        ++scratch.contacts[i];
      }
    }
    scratch.delta[i] = sum;
  });
  return applyMoves(p, scratch, n, nullptr);
}

void findSelfCollisionPairs(const Model& model, const Particles& p, const NeighborLists& neighbors, float h,
                            ClothScratch& scratch) {
  const int n = model.numCloth;
  scratch.pairCount.assign(static_cast<size_t>(n) + 1, 0);
  scratch.pairs.clear();
  scratch.pairOwners.clear();
  if (n == 0) return;
  scratch.speed.resize(static_cast<size_t>(n));
  parallelFor(n, [&](int64_t i) { scratch.speed[i] = p.v[i].norm(); });
  const float* speed = scratch.speed.data();
  // one pass over the lists: particle i's pairs at its own list's offset, then packed in order. Most
  // neighbours are farther than any reach with |v_i| + |v_j| for |v_i - v_j|: that bound goes first,
  // without a square root
  scratch.pairs.resize(neighbors.start[n]);
  parallelForDynamic(n, kClothChunk, [&](int64_t ii) {
    const int i = static_cast<int>(ii);
    int k = static_cast<int>(neighbors.start[i]);
    const float d = selfCollisionThickness(model, p, i);
    if (d > 0.0f) {
      const float base = (1.0f + kCandidateMargin) * d;
      for (uint32_t s = neighbors.start[i], end = neighbors.clothEnd(i, static_cast<uint32_t>(n)); s < end; ++s) {
        const int j = static_cast<int>(neighbors.index[s]);
        if (j >= n) continue;
        const float bound = base + (speed[i] + speed[j]) * h;
        if ((p.xPred[i] - p.xPred[j]).squaredNorm() >= bound * bound) continue;
        const float reach = base + (p.v[i] - p.v[j]).norm() * h;
        float dist2 = 0.0f;
        if (isPair(model, p, i, j, d, reach, dist2)) scratch.pairs[k++] = j;
      }
    }
    scratch.pairCount[i + 1] = k - static_cast<int>(neighbors.start[i]);
  });
  for (int i = 0; i < n; ++i) {  // packing moves entries towards the front only: serial, in order
    const int from = static_cast<int>(neighbors.start[i]), count = scratch.pairCount[i + 1];
    scratch.pairCount[i + 1] = scratch.pairCount[i] + count;
    if (count > 0) scratch.pairOwners.push_back(i);
    std::copy(scratch.pairs.begin() + from, scratch.pairs.begin() + from + count, scratch.pairs.begin() + scratch.pairCount[i]);
  }
  scratch.pairs.resize(static_cast<size_t>(scratch.pairCount[n]));
}

int collideSelfCollisionPairs(const Model& model, Particles& p, ClothScratch& scratch) {
  // only the particles with pairs: in each small step, a flat sheet has none
  const int owners = static_cast<int>(scratch.pairOwners.size());
  if (owners == 0) return 0;
  scratch.delta.resize(static_cast<size_t>(owners));
  scratch.contacts.assign(static_cast<size_t>(owners), 0);
  parallelForDynamic(owners, kClothChunk, [&](int64_t r) {
    const int i = scratch.pairOwners[r];
    const float d = selfCollisionThickness(model, p, i);
    Vec3 sum = Vec3::Zero();
    for (int k = scratch.pairCount[i]; k < scratch.pairCount[i + 1]; ++k) {
      const int j = scratch.pairs[k];
      const float dist2 = (p.xPred[i] - p.xPred[j]).squaredNorm();
      if (dist2 < d * d && dist2 >= 1e-24f) {
        sum += pushApart(p, i, j, d, std::sqrt(dist2));
        ++scratch.contacts[r];
      }
    }
    scratch.delta[r] = sum;
  });
  return applyMoves(p, scratch, owners, scratch.pairOwners.data());
}

}  // namespace soak
