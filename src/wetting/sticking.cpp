// sticking of wet cloth, section 4.5 of Shao et al. 2017 (Eq. 20): touching wet cloth particles attract,
//   f_i = sum_j (eta^ad - kappa^ad |(S_i - S^T)(S_j - S^T)|) W(x_j - x_i, h) along x_j - x_i,
// largest at S^T and gone when the cloth is too wet. As NOTES.md asks, the force is kept non-negative;
// soak adds a wetness ramp min(1, S/S^T) per particle so dry cloth does not stick (the printed force
// is eta^ad - kappa^ad (S^T)^2 > 0 at S = 0), and normalises W by W(0, h) so eta^ad and kappa^ad are
// newtons (docs/models.md). "Touching" means close in space but not on the rest shape: mesh
// neighbours are held by the cloth constraints, not by water.
#include "wetting/wetting.hpp"

#include "core/kernels.hpp"
#include "core/parallel.hpp"

#include <algorithm>
#include <cmath>

namespace soak {

float stickingCoefficient(const WettingParams& w, float si, float sj) {
  if (!(si > 0.0f) || !(sj > 0.0f)) return 0.0f;
  const float st = w.saturationSticky;
  const float f = w.stickingStrength - w.stickingRate * std::fabs((si - st) * (sj - st));
  if (f <= 0.0f) return 0.0f;
  const float ramp = st > 0.0f ? std::min(1.0f, si / st) * std::min(1.0f, sj / st) : 1.0f;
  return f * ramp;
}

void applySticking(const Model& model, State& state, const NeighborLists& nb, WettingScratch& s, float h) {
  const WettingParams& w = model.wetting;
  const int64_t nc = model.numCloth;
  if (!w.enabled || !w.sticking || nc == 0) return;
  Particles& p = state.particles;
  const std::vector<float>& sat = state.clothSaturation;
  s.force.resize(static_cast<size_t>(nc));
  // gathered per particle; the pair's force is bit for bit opposite seen from the other side
  parallelForDynamic(nc, kWetChunk, [&](int64_t i) {
    Vec3 f = Vec3::Zero();
    if (sat[i] > 0.0f) {
      for (uint32_t e = nb.start[i], end = nb.clothEnd(i, static_cast<uint32_t>(nc)); e < end; ++e) {
        const int64_t j = nb.index[e];
        if (j >= nc || !(sat[j] > 0.0f)) continue;
        const float hij = pairRadius(p.radius[i], p.radius[j]);
        // neighbours on the rest shape are not "touching": the cloth holds them, not the water
        if (p.phase[j] == p.phase[i] &&
            (model.clothRestPosition[i] - model.clothRestPosition[j]).squaredNorm() < 2.25f * hij * hij)
          continue;
        const float coef = stickingCoefficient(w, sat[i], sat[j]);
        if (coef <= 0.0f) continue;
        const Vec3 r = p.x[j] - p.x[i];
        const float r2 = r.squaredNorm();
        if (r2 >= hij * hij || r2 < 1e-18f) continue;
        f += (coef * poly6(r2, hij) / poly6(0.0f, hij) / std::sqrt(r2)) * r;
      }
    }
    s.force[i] = f;
  });
  parallelFor(nc, [&](int64_t i) { p.v[i] += (h * p.invMass[i]) * s.force[i]; });
}

}  // namespace soak
