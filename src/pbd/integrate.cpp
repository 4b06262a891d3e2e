#include "pbd/integrate.hpp"

#include <soak/step.hpp>

#include "core/parallel.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace soak {

void predictPositions(const Model& model, double /*time*/, Particles& p, float dt) {
  const Vec3 g = model.solver.gravity;
  const int64_t nc = model.numCloth;
  parallelFor(static_cast<int64_t>(p.size()), [&](int64_t i) {
    if (model.implicitCloth(i)) return;  // garmentSubstep predicts these (src/garment)
    if (i < nc && model.clothPinned[i]) {
      p.xPred[i] = model.clothRestPosition[i];
      p.v[i].setZero();
      return;
    }
    p.v[i] += dt * g;
    p.xPred[i] = p.x[i] + dt * p.v[i];
  });
}

void updateVelocities(const Model& model, Particles& p, float dt) {
  const int64_t nc = model.numCloth;
  const float inv = 1.0f / dt;
  parallelFor(static_cast<int64_t>(p.size()), [&](int64_t i) {
    if (model.implicitCloth(i)) return;  // v from the implicit solve (addCouplingVelocity)
    Vec3 v = (p.xPred[i] - p.x[i]) * inv;
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

void updateColliderPoses(const Model& model, double time, std::vector<ColliderPose>& poses) {
  poses.resize(model.colliders.size());
  for (size_t c = 0; c < model.colliders.size(); ++c) poses[c] = colliderPose(model.colliders[c], time);
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

float maxSpeed(const Particles& p) {
  float m = 0.0f;
  for (const Vec3& v : p.v) m = std::max(m, v.norm());
  return m;
}

float meanDensityRatio(const Model& model, const Particles& p, const FluidScratch& s) {
  const size_t nc = static_cast<size_t>(model.numCloth);
  if (p.size() <= nc || s.density.size() < p.size()) return 0.0f;
  double sum = 0.0;
  for (size_t i = nc; i < p.size(); ++i) sum += s.density[i];
  return static_cast<float>(sum / static_cast<double>(p.size() - nc) / model.water.restDensity);
}

std::string checkState(const Model& model, const State& state) {
  const Particles& p = state.particles;
  for (size_t i = 0; i < p.size(); ++i) {
    const char* kind = isWater(p.phase[i]) ? "water" : "cloth";
    if (!p.x[i].allFinite() || !p.v[i].allFinite())
      return fmt::format("{} particle {} (id {}) has a non-finite position or velocity", kind, i, p.id[i]);
    const float speed = p.v[i].norm();
    if (speed > model.solver.maxSpeed)
      return fmt::format("{} particle {} (id {}) moves at {:.3g} m/s, above solver.maxSpeed = {:.3g} m/s", kind, i,
                         p.id[i], speed, model.solver.maxSpeed);
  }
  return {};
}

namespace {
template <class T>
void hashBytes(uint64_t& h, const std::vector<T>& a) {
  const auto* b = reinterpret_cast<const unsigned char*>(a.data());
  for (size_t k = 0; k < a.size() * sizeof(T); ++k) {
    h ^= b[k];
    h *= 1099511628211ull;
  }
}
}  // namespace

uint64_t stateHash(const State& state) {
  uint64_t h = 1469598103934665603ull;
  const Particles& p = state.particles;
  hashBytes(h, p.x);
  hashBytes(h, p.v);
  hashBytes(h, p.mass);
  hashBytes(h, p.radius);
  hashBytes(h, p.id);
  return h;
}

}  // namespace soak
