// porosity of the cloth particles, section 4.1 of Shao et al. 2017: each cloth particle is a small porous
// volume V_i that holds m^water_i of water, at saturation S_i = c m^water_i / V_i (Eq. 10)
#include "wetting/wetting.hpp"

#include "core/kernels.hpp"
#include "core/parallel.hpp"

#include <algorithm>

namespace soak {

void clothVolumes(const Model& model, const std::vector<Vec3>& x, const std::vector<float>& radius,
                  const std::vector<int32_t>& phase, const NeighborLists& nb, std::vector<float>& volume) {
  const int64_t nc = model.numCloth;
  volume.resize(static_cast<size_t>(nc));
  parallelFor(nc, [&](int64_t i) {
    const float hi = radius[i];
    float sum = poly6(0.0f, hi);  // k includes i itself (NOTES.md on Eq. 10)
    for (uint32_t k = nb.start[i], end = nb.clothEnd(i, static_cast<uint32_t>(nc)); k < end; ++k) {
      const uint32_t j = nb.index[k];
      if (static_cast<int64_t>(j) >= nc || phase[j] != phase[i]) continue;  // same piece only
      sum += poly6((x[i] - x[j]).squaredNorm(), pairRadius(hi, radius[j]));
    }
    volume[i] = 1.0f / sum;  // V_i = 1 / sum_k W_ik (Akinci et al. 2012)
  });
}

std::vector<float> restVolumes(const Model& model, const std::vector<float>& radius) {
  const size_t nc = static_cast<size_t>(model.numCloth);
  std::vector<int32_t> phase(nc);
  for (size_t k = 0; k < model.pieces.size(); ++k)
    for (int i = 0; i < model.pieces[k].particleCount; ++i)
      phase[static_cast<size_t>(model.pieces[k].firstParticle + i)] = static_cast<int32_t>(k + 1);
  const std::vector<float> r(radius.begin(), radius.begin() + static_cast<std::ptrdiff_t>(nc));
  NeighborGrid grid;
  NeighborLists nb;
  float cell = 1e-3f;
  for (float h : r) cell = std::max(cell, h);
  buildGrid(model.clothRestPosition, cell, grid);
  buildNeighborLists(model.clothRestPosition, r, grid, nb);
  std::vector<float> volume;
  clothVolumes(model, model.clothRestPosition, r, phase, nb, volume);
  return volume;
}

namespace {

// m_i = dry + held + buffer; pinned particles stay kinematic
void setWetMass(const Model& model, State& state, int64_t i) {
  Particles& p = state.particles;
  const float m = model.clothDryMass[i] + static_cast<float>(state.clothWater[i] + state.clothBuffer[i]);
  p.mass[i] = m;
  p.invMass[i] = model.clothPinned[i] ? 0.0f : 1.0f / m;
}

}  // namespace

void initWettingState(const Model& model, const std::vector<float>& volume, State& state) {
  const size_t nc = static_cast<size_t>(model.numCloth);
  const WettingParams& w = model.wetting;
  state.clothWater.assign(nc, 0.0);
  state.clothBuffer.assign(nc, 0.0);
  state.clothSaturation.assign(nc, 0.0f);
  state.dripId.clear();
  state.dripSource.clear();
  double held = 0.0;
  for (size_t i = 0; i < nc; ++i) {
    // m^water = S V / c (Eq. 10 solved for the mass)
    state.clothWater[i] = static_cast<double>(w.initialSaturation) * volume[i] / w.c;
    state.clothSaturation[i] = w.initialSaturation;
    held += state.clothWater[i];
    setWetMass(model, state, static_cast<int64_t>(i));
  }
  // water put in the cloth at load counts as emitted, so free + held + buffers + removed = emitted
  state.ledger.emitted += held;
  state.ledger.heldInCloth = held;
  state.ledger.inBuffers = 0.0;
}

void computeSaturation(const Model& model, const State& state, const WettingScratch& s, std::vector<float>& sat) {
  const int64_t nc = model.numCloth;
  const double c = model.wetting.c;
  sat.resize(static_cast<size_t>(nc));
  parallelFor(nc, [&](int64_t i) { sat[i] = static_cast<float>(c * state.clothWater[i] / s.volume[i]); });
}

void updatePorosity(const Model& model, State& state, const NeighborLists& nb, WettingScratch& s) {
  if (!model.wetting.enabled || model.numCloth == 0) return;
  const Particles& p = state.particles;
  clothVolumes(model, p.x, p.radius, p.phase, nb, s.volume);
  computeSaturation(model, state, s, state.clothSaturation);
  parallelFor(model.numCloth, [&](int64_t i) { setWetMass(model, state, i); });
}

}  // namespace soak
