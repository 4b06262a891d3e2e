// water diffusion inside the cloth, section 4.3 of Shao et al. 2017 (Eq. 12-17). The saturation
// constraint of particle i,
//   C_i(S) = sum_j (kappa_i^d + kappa_j^d)/2 (S_j - S_i)/rho0 (1 + eta^d cos theta_ij) lap W_ij  (Eq. 12),
// is projected as in PBD: lambda_i = -C_i / (sum_k |grad_k C_i|^2 + epsilon) (Eq. 15) and
// S_i += kappa^s lambda_i grad_i C_i (Eq. 17). Eq. 17 as printed changes only S_i, so the held water
// drifts; soak writes the same projection as pairwise exchange (NOTES.md, docs/models.md): the water
// entering i from j is the water leaving j towards i,
//   dm_{j->i} = kappa^s min(sigma_i, sigma_j) w_ij (S_j - S_i) min(V_i, V_j) / c,
// with sigma_i = a_i / (a_i^2 + sum_j w_ij^2 + epsilon) the step of Eq. 15-17 (a_i = sum_j w_ij, the
// diagonal derivative of Eq. 16) and w_ij = (kappa_i^d + kappa_j^d)/2 (1 + eta^d cos) lap W_ij / rho0,
// where cos is taken along the flow: water going down is sped up, water going up slowed down. sigma_i
// uses the largest gravity factor (1 + eta^d |cos|), so no particle gives more than it holds.
#include "wetting/wetting.hpp"

#include "core/kernels.hpp"
#include "core/parallel.hpp"

#include <algorithm>
#include <cmath>

namespace soak {

namespace {

// the pass's rates, the same for every pair: kappa^s of one iteration (Eq. 17), kappa^d (isotropic
// cloth: (kappa_i^d + kappa_j^d) / 2 = kappa^d), eta^d (0 without gravity) and c
struct DiffusionRates {
  float kappaS, kd, eta;
  double c;
};

// Both neighbour loops below compute each pair's term in a vectorised loop (plain floats and
// doubles, selects, the arithmetic of the scalar expression) into a per-thread buffer and sum the
// terms in list order, so every result is that of the scalar loop. A pair that is skipped (another
// piece, equal saturations) contributes a zero, which leaves a sum started at +0 unchanged. They read
// the pair's geometry (pairGeometry), the same numbers seen from i or j (up to the sign of cos):
// w_ij / (1 + eta cos) = (kappa_i^d + kappa_j^d)/2 lap W_ij / rho0 (Eq. 12), and cos theta_ij.

// rho0 of cloth particle i's piece
float restDensity(const Model& model, const Particles& p, int64_t i) {
  return model.pieces[clothPiece(p.phase[i])].material.restDensity;
}

// s.sigma[i]: the PBD step of i's constraint (Eq. 15-17) with the gradients of Eq. 16
void constraintSteps(const Model& model, const State& state, const NeighborLists& nb, WettingScratch& s,
                     const DiffusionRates& r) {
  const WettingParams& w = model.wetting;
  const int64_t nc = model.numCloth;
  const Particles& p = state.particles;
  const std::vector<float>& sat = state.clothSaturation;
  const float* lap = s.pairLap.data();
  const float* cosG = s.pairCos.data();
  const auto samePiece = [&](int64_t i, int64_t j) { return j < nc && p.phase[j] == p.phase[i]; };
  const uint32_t cloth = static_cast<uint32_t>(nc);
  const uint32_t* const index = nb.index.data();
  float* const sigma = s.sigma.data();
  const float kd = r.kd, eta = r.eta;
  parallelForDynamic(nc, kWetChunk, [&](int64_t i) {
    // sigma_i is read only by exchanges with a neighbour of another saturation: skip it otherwise
    bool exchanges = false;
    for (uint32_t e = nb.start[i], end = nb.clothEnd(i, cloth); e < end && !exchanges; ++e)
      exchanges = samePiece(i, nb.index[e]) && sat[nb.index[e]] != sat[i];
    if (!exchanges) {
      sigma[i] = 0.0f;
      return;
    }
    const uint32_t begin = nb.start[i], count = nb.clothEnd(i, cloth) - begin;
    const float* const L = lap + begin;
    const float* const C = cosG + begin;
    float* const W = s.pairFloat.get(count);
    const float rho0 = restDensity(model, p, i), kdL = kd, etaL = eta;  // locals: the compiler does not
#pragma omp simd                                                         // vectorise loads through the closure
    for (uint32_t k = 0; k < count; ++k) W[k] = diffusionWeight(kdL, L[k], rho0, etaL, std::fabs(C[k]));
    float a = 0.0f, sq = 0.0f;
    for (uint32_t k = 0; k < count; ++k) {  // cloth neighbours only
      if (!samePiece(i, index[begin + k])) continue;
      const float wij = W[k];
      a += wij;
      sq += wij * wij;
    }
    sigma[i] = a > 0.0f ? a / (a * a + sq + w.epsilon) : 0.0f;
  });
}

// s.delta[i]: the pairwise exchange, gathered per particle: the flow j -> i is bit for bit minus the
// flow i -> j
void exchangeFlows(const Model& model, const State& state, const NeighborLists& nb, WettingScratch& s,
                   const DiffusionRates& r) {
  const int64_t nc = model.numCloth;
  const Particles& p = state.particles;
  const float* lap = s.pairLap.data();
  const float* cosG = s.pairCos.data();
  const uint32_t cloth = static_cast<uint32_t>(nc);
  const uint32_t* const index = nb.index.data();
  const int32_t* const phase = p.phase.data();
  const float* const S = state.clothSaturation.data();
  const float* const V = s.volume.data();
  const float* const sigma = s.sigma.data();
  const float kappaS = r.kappaS, kd = r.kd, eta = r.eta;
  const double c = r.c;
  parallelForDynamic(nc, kWetChunk, [&](int64_t i) {
    // sigma_i = 0 makes every coefficient min(sigma_i, sigma_j) ... zero: nothing moves
    if (sigma[i] == 0.0f) {
      s.delta[i] = 0.0;
      return;
    }
    const uint32_t begin = nb.start[i], count = nb.clothEnd(i, cloth) - begin;
    const uint32_t* const J = index + begin;
    const float* const L = lap + begin;
    const float* const C = cosG + begin;
    double* const T = s.pairDouble.get(count);
    // locals: the compiler does not vectorise loads through the closure
    const int32_t* const P = phase;
    const float* const SL = S;
    const float* const SG = sigma;
    const float* const VL = V;
    const float rho0 = restDensity(model, p, i), kdL = kd, etaL = eta, kappaL = kappaS;
    const double cL = c;
    const uint32_t clothL = cloth;
    const int32_t phi = P[i];
    const float si = SL[i], sgi = SG[i], vi = VL[i];
#pragma omp simd
    for (uint32_t k = 0; k < count; ++k) {  // cloth neighbours only
      const uint32_t j = J[k];
      const bool same = (j < clothL) & (P[j] == phi);
      const uint32_t jj = same ? j : static_cast<uint32_t>(i);  // S, sigma and V hold cloth only
      const double diff = static_cast<double>(SL[jj]) - static_cast<double>(si);
      // cos of the flow direction with gravity: from j to i when S_j > S_i, else from i to j
      const float cosFlow = diff > 0.0 ? C[k] : -C[k];
      const float wij = diffusionWeight(kdL, L[k], rho0, etaL, cosFlow);
      T[k] = diffusionExchange(kappaL, sgi, SG[jj], wij, vi, VL[jj], cL, diff);  // +-0 for another piece (jj = i)
    }
    double dm = 0.0;
    for (uint32_t k = 0; k < count; ++k) dm += T[k];
    s.delta[i] = dm;
  });
}

}  // namespace

void diffuseWater(const Model& model, State& state, const NeighborLists& nb, WettingScratch& s, float h) {
  s.pairFloat.prepare();  // the per-thread pair buffers of the loops below
  s.pairDouble.prepare();
  const WettingParams& w = model.wetting;
  const int64_t nc = model.numCloth;
  if (!w.enabled || !w.diffusion || nc == 0) return;
  const int iterations = std::max(1, w.diffusionIterations);
  DiffusionRates r;
  r.kappaS = rateForStep(w.smoothing, h / static_cast<float>(iterations), w.rateStep);
  r.kd = w.diffusionRate;
  r.eta = w.diffusionGravity ? w.diffusionGravityFactor : 0.0f;
  r.c = w.c;
  std::vector<float>& sat = state.clothSaturation;
  s.sigma.resize(static_cast<size_t>(nc));
  s.delta.resize(static_cast<size_t>(nc));

  // nothing held, nothing to spread (the common case before the water arrives)
  bool any = false;
  for (int64_t i = 0; i < nc && !any; ++i) any = state.clothWater[i] > 0.0;
  if (!any) return;

  ensurePairGeometry(model, state.particles, nb, s);
  computeSaturation(model, state, s, sat);  // absorption changed the held water
  for (int it = 0; it < iterations; ++it) {
    constraintSteps(model, state, nb, s, r);
    exchangeFlows(model, state, nb, s, r);
    // the exchange, and S_i for the next iteration or stage (computeSaturation, in the same loop)
    parallelFor(nc, [&](int64_t i) {
      state.clothWater[i] = std::max(0.0, state.clothWater[i] + s.delta[i]);
      sat[i] = saturationOf(r.c, state.clothWater[i], s.volume[i]);
    });
  }
}

}  // namespace soak
