#include "pbd/integrate.hpp"

#include "core/parallel.hpp"

#include <algorithm>
#include <cmath>

namespace soak {

void pbdParticles(const Model& model, size_t n, std::vector<IndexRange>& ranges) {
  ranges.clear();
  const auto add = [&](int64_t begin, int64_t end) {
    if (begin >= end) return;
    if (!ranges.empty() && ranges.back().end == begin)
      ranges.back().end = end;  // consecutive: one range, one parallel loop
    else
      ranges.push_back({begin, end});
  };
  for (const ClothPiece& piece : model.pieces)
    if (piece.solver == ClothSolver::Pbd) add(piece.firstParticle, piece.firstParticle + piece.particleCount);
  add(model.numCloth, static_cast<int64_t>(n));
}

void predictPositions(const Model& model, const std::vector<IndexRange>& moved, Particles& p, float dt) {
  const Vec3 g = model.solver.gravity;
  const int64_t nc = model.numCloth;
  parallelForRanges(moved, [&](int64_t i) {
    if (i < nc && model.clothPinned[i]) {  // stays where it is: where the scene put it, or a caller moved it
      p.xPred[i] = p.x[i];
      p.v[i].setZero();
      return;
    }
    p.v[i] += dt * g;
    p.xPred[i] = p.x[i] + dt * p.v[i];
  });
}

void updateVelocities(const Model& model, const std::vector<IndexRange>& moved, Particles& p, float dt,
                      std::span<const Vec3> clothVelocityOffset) {
  const int64_t nc = model.numCloth;
  const int64_t offsets = static_cast<int64_t>(clothVelocityOffset.size());
  const float inv = 1.0f / dt;
  parallelForRanges(moved, [&](int64_t i) {
    Vec3 v = (p.xPred[i] - p.x[i]) * inv;
    if (i < offsets) v += clothVelocityOffset[i];
    if (i < nc) v *= std::max(0.0f, 1.0f - dt * model.pieces[clothPiece(p.phase[i])].material.damping);
    p.v[i] = v;
  });
}

void commitPositions(Particles& p) {
  parallelFor(static_cast<int64_t>(p.size()), [&](int64_t i) { p.x[i] = p.xPred[i]; });
}

size_t removeOutsideDomain(const Model& model, State& state, std::vector<uint8_t>& keep) {
  Particles& p = state.particles;
  const Vec3 lo = model.solver.domainMin, hi = model.solver.domainMax;
  const size_t n = p.size();
  keep.assign(n, 1);
  size_t removed = 0;
  for (size_t i = static_cast<size_t>(model.numCloth); i < n; ++i) {
    const Vec3& x = p.x[i];
    if ((x.array() >= lo.array()).all() && (x.array() <= hi.array()).all()) continue;
    keep[i] = 0;
    ++removed;
    state.ledger.removedAtBounds += p.mass[i];
  }
  state.ledger.particlesRemovedAtBounds += removed;
  if (removed) p.compact(keep);
  return removed;
}

void updateColliderPoses(const Model& model, double time, std::span<const std::vector<Keyframe>> colliderKeys,
                         std::vector<ColliderPose>& poses) {
  poses.resize(model.colliders.size());
  for (size_t c = 0; c < model.colliders.size(); ++c) {
    const bool given = c < colliderKeys.size() && !colliderKeys[c].empty();
    const std::span<const Keyframe> keys = given ? colliderKeys[c] : model.colliders[c].keys;
    poses[c] = colliderPose(model.colliders[c], keys, time);
  }
}

float maxSupportRadius(const Particles& p) {
  float h = 1e-3f;
  for (float r : p.radius) h = std::max(h, r);
  return h;
}

float neighborCellSize(const Model& model, const Particles& p) {
  const size_t nc = std::min(static_cast<size_t>(std::max(model.numCloth, 0)), p.size());
  float h = std::max(1e-3f, model.water.supportRadius), hMax = h;
  for (size_t i = 0; i < nc; ++i) h = std::max(h, p.radius[i]);
  size_t above = 0;
  for (size_t i = nc; i < p.size(); ++i)
    if (p.radius[i] > h) ++above, hMax = std::max(hMax, p.radius[i]);
  return above * 8 > p.size() ? hMax : h;
}

float meanDensityRatio(const Model& model, const Particles& p, const FluidScratch& s) {
  const size_t nc = static_cast<size_t>(model.numCloth);
  if (p.size() <= nc || s.density.size() < p.size()) return 0.0f;
  double sum = 0.0;
  for (size_t i = nc; i < p.size(); ++i) sum += s.density[i];
  return static_cast<float>(sum / static_cast<double>(p.size() - nc) / model.water.restDensity);
}

}  // namespace soak
