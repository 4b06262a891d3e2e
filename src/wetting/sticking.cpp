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
  // gathered per particle; the pair's force is bit for bit opposite seen from the other side. Each
  // pair's force is computed in a vectorised loop (plain floats, selects, the arithmetic of the scalar
  // code: stickingCoefficient, poly6) into a per-thread buffer and summed in list order, so the result
  // is that of the scalar loop; a pair that does not stick adds a zero, which leaves the sum unchanged.
  const uint32_t* const indexAll = nb.index.data();
  const int32_t* const phaseAll = p.phase.data();
  const float* const xAll = p.x[0].data();
  const float* const radiusAll = p.radius.data();
  const float* const restAll = model.clothRestPosition[0].data();
  const float* const satAll = sat.data();
  parallelForDynamic(nc, kWetChunk, [&](int64_t i) {
    Vec3 f = Vec3::Zero();
    if (sat[i] > 0.0f) {
      const uint32_t begin = nb.start[i], count = nb.clothEnd(i, static_cast<uint32_t>(nc)) - begin;
      const uint32_t* const J = indexAll + begin;
      const int32_t* const P = phaseAll;
      const float* const X = xAll;
      const float* const H = radiusAll;
      const float* const R = restAll;
      const float* const S = satAll;
      float* const Tx = threadBuffer<float>(3 * static_cast<size_t>(count));
      float* const Ty = Tx + count;
      float* const Tz = Ty + count;
      const uint32_t clothL = static_cast<uint32_t>(nc);
      const float st = w.saturationSticky, strength = w.stickingStrength, rate = w.stickingRate;
      const int32_t phi = P[i];
      const float si = S[i], hi = H[i];
      const float xi = X[3 * i], yi = X[3 * i + 1], zi = X[3 * i + 2];
      const float rxi = R[3 * i], ryi = R[3 * i + 1], rzi = R[3 * i + 2];
      // the ramp factor of i, min(1, S_i / S^T) (st = 0: no ramp)
      const float rampI = st > 0.0f ? (si / st < 1.0f ? si / st : 1.0f) : 1.0f;
#pragma omp simd
      for (uint32_t k = 0; k < count; ++k) {
        const uint32_t j = J[k];
        const bool isCloth = j < clothL;
        const uint32_t jj = isCloth ? j : static_cast<uint32_t>(i);  // S and the rest shape hold cloth only
        const float sj = S[jj];
        const float hij = 0.5f * (hi + H[j]);  // pairRadius
        // neighbours on the rest shape are not "touching": the cloth holds them, not the water
        const float qx = rxi - R[3 * jj], qy = ryi - R[3 * jj + 1], qz = rzi - R[3 * jj + 2];
        const bool restNear = (P[j] == phi) & (qx * qx + (qy * qy + qz * qz) < 2.25f * hij * hij);
        // stickingCoefficient(w, S_i, S_j), S_i > 0
        const float fc = strength - rate * std::fabs((si - st) * (sj - st));
        const float rampJ = st > 0.0f ? (sj / st < 1.0f ? sj / st : 1.0f) : 1.0f;
        const float coef = fc * (rampI * rampJ);
        const float rx = X[3 * j] - xi, ry = X[3 * j + 1] - yi, rz = X[3 * j + 2] - zi;  // x_j - x_i
        const float r2 = rx * rx + (ry * ry + rz * rz);
        const float h2 = hij * hij;
        const bool sticks = isCloth & (sj > 0.0f) & !restNear & (fc > 0.0f) & (coef > 0.0f) & (r2 < h2) &
                            (r2 >= 1e-18f);
        // poly6(r2, h) / poly6(0, h) / |r|; the guards only keep the dropped lanes finite
        const float h9 = h2 * h2 * h2 * h2 * hij;
        const float c6 = 315.0f / (64.0f * kPi * h9);
        const float d = sticks ? h2 - r2 : 0.0f;
        const float len = std::sqrt(sticks ? r2 : 1.0f);
        const float scale = coef * (c6 * d * d * d) / (c6 * h2 * h2 * h2) / len;
        const float m = sticks ? 1.0f : 0.0f;
        Tx[k] = scale * rx * m;
        Ty[k] = scale * ry * m;
        Tz[k] = scale * rz * m;
      }
      for (uint32_t k = 0; k < count; ++k) f += Vec3(Tx[k], Ty[k], Tz[k]);
    }
    s.force[i] = f;
  });
  parallelFor(nc, [&](int64_t i) { p.v[i] += (h * p.invMass[i]) * s.force[i]; });
}

}  // namespace soak
