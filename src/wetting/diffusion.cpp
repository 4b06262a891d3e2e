// water spreading inside the cloth, section 4.3 of Shao et al. 2017 (Eq. 12-17), as a rate in time
// with a capillary equilibrium (departure: docs/models.md, "Diffusion"). Held water moves between
// neighbouring particles i, j of the same piece at
//   q_{j->i} = T_ij (1 + eta^d cos) [(S_j - S_i) + lambda S_up (z_j - z_i)]   (kg/s),
//   T_ij = D nu V_i V_j lap W_ij / c,   lambda = ln 2 / H,
// the SPH form of dS/dt = div(D grad S) + d/dz(D lambda S): Eq. 12's Laplacian of S (kappa^d becomes
// the diffusivity D in m^2/s) plus a drift down of the upper particle's water (S_up: the saturation
// of the higher of the two). nu scales the kernel's Laplacian so that it is exact for a quadratic
// field on the sheet; (1 + eta^d cos) is the paper's gravity factor along the flow (cos > 0 going
// down). When nothing flows the saturation halves every H of height: a dipped cloth wicks as sqrt(t)
// (Lucas-Washburn) and levels off with its front (half the saturation at the water) H above the water.
// The flux is q_{j->i} = -q_{i->j} bit for bit, so the held total is conserved (NOTES.md). Explicit
// Euler in sub-steps short enough that no particle can give more than half its water
// (wetting.diffusion.iterations times more for accuracy); a particle takes no more than its room up to
// S^MAX: its inflows, and the neighbours' outflows with them, are scaled down.
#include "wetting/wetting.hpp"

#include "core/kernels.hpp"
#include "core/parallel.hpp"

#include <algorithm>
#include <cmath>

namespace soak {

namespace {

constexpr int kMaxDiffusionSubsteps = 4096;  // a guard: D or dt far beyond any scene's

// nu of each piece: 4 / sum_j V_j lap W_ij |x_ij|^2 on the rest shape at its particle with the most
// neighbours (an interior one: the sum a full neighbourhood gives for the field |x - x_i|^2, whose
// Laplacian on a sheet is 4; at an edge the neighbours' larger V_j would inflate it)
void diffusionNorms(const Model& model, const State& state, WettingScratch& s) {
  if (s.diffusionNorm.size() == model.pieces.size()) return;  // once a run: the rest shape is constant
  const int64_t nc = model.numCloth;
  const std::vector<float> radius(state.particles.radius.begin(), state.particles.radius.begin() + nc);
  const std::vector<float> volume = restVolumes(model, radius);
  NeighborGrid grid;
  NeighborLists nb;
  buildGrid(model.clothRestPosition, *std::max_element(radius.begin(), radius.end()), grid);
  buildNeighborLists(model.clothRestPosition, radius, grid, nb);
  std::vector<double> most(model.pieces.size(), 0.0);
  std::vector<int> mostCount(model.pieces.size(), -1);
  for (int64_t i = 0; i < nc; ++i) {
    const size_t k = clothPiece(state.particles.phase[i]);
    double sum = 0.0;
    int count = 0;
    for (uint32_t e = nb.start[i]; e < nb.start[i + 1]; ++e) {
      const uint32_t j = nb.index[e];
      if (static_cast<int64_t>(j) >= nc || state.particles.phase[j] != state.particles.phase[i]) continue;
      const float r2 = (model.clothRestPosition[i] - model.clothRestPosition[j]).squaredNorm();
      sum += static_cast<double>(volume[j]) * viscosityLaplacian(std::sqrt(r2), pairRadius(radius[i], radius[j])) * r2;
      ++count;
    }
    if (count > mostCount[k]) most[k] = sum, mostCount[k] = count;
  }
  s.diffusionNorm.resize(model.pieces.size());
  for (size_t k = 0; k < most.size(); ++k) s.diffusionNorm[k] = most[k] > 0.0 ? static_cast<float>(4.0 / most[k]) : 0.0f;
}

// the pass's constants: D nu / c of each piece, lambda, eta^d and c
struct DiffusionRates {
  std::vector<float> conductance;  // D nu / c of each piece
  float lambda, eta;
  double c;
};

// per entry e of i's cloth part (pairGeometry's), j = index[e]: s.pairConductance[e] = T_ij (0 for
// another piece), s.pairRise[e] = z_j - z_i; returns the largest rate max_i r_i (1/s) at which a
// particle can lose its water, r_i = c/V_i sum_j T_ij (1 + eta) (1 + lambda |z_j - z_i|)
float pairTerms(const Model& model, const State& state, const NeighborLists& nb, WettingScratch& s,
                const DiffusionRates& r) {
  const int64_t nc = model.numCloth;
  const uint32_t cloth = static_cast<uint32_t>(nc);
  const Particles& p = state.particles;
  const Vec3 g = gravityDirection(model);
  s.pairConductance.resize(nb.index.size());
  s.pairRise.resize(nb.index.size());
  s.lossRate.resize(static_cast<size_t>(nc));
  parallelFor(nc, [&](int64_t i) {
    const float k = r.conductance[clothPiece(p.phase[i])], vi = s.volume[i];
    double rate = 0.0;
    for (uint32_t e = nb.start[i], end = nb.clothEnd(i, cloth); e < end; ++e) {
      const uint32_t j = nb.index[e];
      const bool same = j < cloth && p.phase[j] == p.phase[i];
      const Vec3 d = p.x[i] - p.x[j];
      // (x_i - x_j) . g_dir = z_j - z_i, exactly minus the value seen from j
      s.pairRise[e] = d.x() * g.x() + (d.y() * g.y() + d.z() * g.z());
      s.pairConductance[e] = same ? (k * s.pairLap[e]) * (vi * s.volume[j]) : 0.0f;
      rate += static_cast<double>(s.pairConductance[e]) * (1.0 + r.eta) * (1.0 + r.lambda * std::fabs(s.pairRise[e]));
    }
    s.lossRate[i] = static_cast<float>(r.c * rate / vi);
  });
  float most = 0.0f;
  for (int64_t i = 0; i < nc; ++i) most = std::max(most, s.lossRate[i]);
  return most;
}

// one explicit sub-step of tau seconds: s.pairFlow[e] the water entering i from j (kg) and the share
// s.inScale[i] of i's inflow that fits below S^MAX; s.wetPair[i] whether i exchanges anything
void pairFlows(const Model& model, const State& state, const NeighborLists& nb, WettingScratch& s,
               const DiffusionRates& r, double tau) {
  const int64_t nc = model.numCloth;
  const uint32_t cloth = static_cast<uint32_t>(nc);
  const float* const S = state.clothSaturation.data();
  parallelForDynamic(nc, kWetChunk, [&](int64_t i) {
    // a dry particle among dry neighbours exchanges nothing (every push is 0): skip the dry cloth
    bool wet = S[i] > 0.0f;
    for (uint32_t e = nb.start[i], end = nb.clothEnd(i, cloth); e < end && !wet; ++e) wet = S[nb.index[e]] > 0.0f;
    s.wetPair[i] = wet;
    if (!wet) return;
    double inflow = 0.0;
    for (uint32_t e = nb.start[i], end = nb.clothEnd(i, cloth); e < end; ++e) {
      const uint32_t j = nb.index[e];
      const uint32_t jj = j < cloth ? j : static_cast<uint32_t>(i);  // T = 0 for water neighbours
      const double q = diffusionFlow(tau, s.pairConductance[e], r.eta, s.pairCos[e], S[i], S[jj], r.lambda, s.pairRise[e]);
      s.pairFlow[e] = q;
      inflow += q > 0.0 ? q : 0.0;
    }
    const double room = std::max(0.0, mostHeldWater(model.wetting, s.volume[i]) - state.clothWater[i]);
    s.inScale[i] = inflow > room ? room / inflow : 1.0;
  });
}

// the flows, each scaled by its receiver's share, into the held water and S_i
void applyFlows(const Model& model, State& state, const NeighborLists& nb, WettingScratch& s, double c) {
  const int64_t nc = model.numCloth;
  const uint32_t cloth = static_cast<uint32_t>(nc);
  parallelForDynamic(nc, kWetChunk, [&](int64_t i) {
    double dm = 0.0;
    if (!s.wetPair[i]) {  // pairFlows skipped it: no flow
      s.delta[i] = 0.0;
      return;
    }
    for (uint32_t e = nb.start[i], end = nb.clothEnd(i, cloth); e < end; ++e) {
      const uint32_t j = nb.index[e];
      const double q = s.pairFlow[e];
      if (q == 0.0 || j >= cloth) continue;
      dm += q * (q > 0.0 ? s.inScale[i] : s.inScale[j]);  // the same product seen from j, negated
    }
    s.delta[i] = dm;
  });
  parallelFor(nc, [&](int64_t i) {
    state.clothWater[i] = std::max(0.0, state.clothWater[i] + s.delta[i]);
    state.clothSaturation[i] = saturationOf(c, state.clothWater[i], s.volume[i]);
  });
}

}  // namespace

int diffusionSubsteps(float lossRate, float h, int iterations) {
  const double n = std::ceil(2.0 * static_cast<double>(lossRate) * h);  // tau r <= 1/2
  return std::clamp(static_cast<int>(std::min(n, 1e6)), 1, kMaxDiffusionSubsteps) * std::max(1, iterations);
}

int diffuseWater(const Model& model, State& state, const NeighborLists& nb, WettingScratch& s, float h) {
  const WettingParams& w = model.wetting;
  const int64_t nc = model.numCloth;
  if (!w.enabled || !w.diffusion || nc == 0 || w.diffusivity <= 0.0f) return 0;
  // nothing held, nothing to spread (the common case before the water arrives)
  bool any = false;
  for (int64_t i = 0; i < nc && !any; ++i) any = state.clothWater[i] > 0.0;
  if (!any) return 0;
  diffusionNorms(model, state, s);
  const bool gravity = w.diffusionGravity && gravityDirection(model).squaredNorm() > 0.0f;
  DiffusionRates r;
  for (const float nu : s.diffusionNorm) r.conductance.push_back(static_cast<float>(w.diffusivity * nu / w.c));
  r.lambda = gravity && w.wickingHeight > 0.0f ? std::log(2.0f) / w.wickingHeight : 0.0f;
  r.eta = gravity ? w.diffusionGravityFactor : 0.0f;
  r.c = w.c;
  ensurePairGeometry(model, state.particles, nb, s);
  computeSaturation(model, state, s, state.clothSaturation);  // absorption changed the held water
  const int n = diffusionSubsteps(pairTerms(model, state, nb, s, r), h, w.diffusionIterations);
  s.pairFlow.resize(nb.index.size());
  s.inScale.resize(static_cast<size_t>(nc));
  s.wetPair.resize(static_cast<size_t>(nc));
  s.delta.resize(static_cast<size_t>(nc));
  const double tau = static_cast<double>(h) / n;
  for (int k = 0; k < n; ++k) {
    pairFlows(model, state, nb, s, r, tau);
    applyFlows(model, state, nb, s, r.c);
  }
  updateWetMasses(model, state);  // the water moved: m = dry + held + buffer
  return n;
}

}  // namespace soak
