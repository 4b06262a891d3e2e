// water passing through wet cloth, section 4.5 of Shao et al. 2017: the stiffness of the water-cloth
// coupling constraint (Eq. 21) falls as its triangle gets wetter (Eq. 22). pbd/coupling.cpp turns the
// stiffness into a per-iteration factor by Eq. 5. soak's cloth is also a boundary in the water's
// density (Akinci et al. 2012), a wall of its own: the same factor, per particle, thins that wall, or
// a soaked cloth would still hold the water up.
#include "wetting/wetting.hpp"

#include "core/parallel.hpp"

#include <algorithm>

namespace soak {

// kappa^couple = 1 - (S~a + S~b + S~c) / (3 (S^MAX - S^T)), S~ = max(0, S - S^T) (Eq. 22), clamped to
// [0, 1] (NOTES.md)
float couplingStiffness(const WettingParams& w, float sa, float sb, float sc) {
  const float st = w.saturationSticky;
  const float wet = std::max(0.0f, sa - st) + std::max(0.0f, sb - st) + std::max(0.0f, sc - st);
  const float range = 3.0f * (w.saturationMax - st);
  if (range <= 0.0f) return wet > 0.0f ? 0.0f : 1.0f;
  return std::clamp(1.0f - wet / range, 0.0f, 1.0f);
}

void updateCouplingStiffness(const Model& model, const State& state, std::vector<float>& triangleStiffness) {
  const WettingParams& w = model.wetting;
  const int64_t nt = static_cast<int64_t>(model.triangles.size());
  const bool wet = w.enabled && w.permeability && state.clothSaturation.size() == static_cast<size_t>(model.numCloth);
  triangleStiffness.resize(static_cast<size_t>(nt));
  if (!wet) {
    std::fill(triangleStiffness.begin(), triangleStiffness.end(), 1.0f);
    return;
  }
  const std::vector<float>& s = state.clothSaturation;
  parallelFor(nt, [&](int64_t t) {
    const auto& f = model.triangles[t];
    triangleStiffness[t] = couplingStiffness(w, s[f[0]], s[f[1]], s[f[2]]);
  });
}

void scaleBoundaryByPermeability(const Model& model, const State& state, std::vector<float>& psi) {
  const WettingParams& w = model.wetting;
  const int64_t nc = std::min<int64_t>(model.numCloth, static_cast<int64_t>(psi.size()));
  if (!w.enabled || !w.permeability || state.clothSaturation.size() != static_cast<size_t>(model.numCloth)) return;
  const std::vector<float>& s = state.clothSaturation;
  parallelFor(nc, [&](int64_t i) { psi[i] *= couplingStiffness(w, s[i], s[i], s[i]); });
}

}  // namespace soak
