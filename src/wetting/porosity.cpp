// porosity of the cloth particles, section 4.1 of Shao et al. 2017: each cloth particle is a small porous
// volume V_i that holds m^water_i of water, at saturation S_i = c m^water_i / V_i (Eq. 10)
#include "wetting/wetting.hpp"

#include "core/kernels.hpp"
#include "core/parallel.hpp"

#include <algorithm>
#include <cmath>

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

void setWetMass(const Model& model, State& state, int64_t i) {
  Particles& p = state.particles;
  const float m = model.clothDryMass[i] + static_cast<float>(state.clothWater[i] + state.clothBuffer[i]);
  p.setMass(static_cast<size_t>(i), m, model.clothPinned[i]);
}

void updateWetMasses(const Model& model, State& state) {
  parallelFor(model.numCloth, [&](int64_t i) { setWetMass(model, state, i); });
}

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
  parallelFor(nc, [&](int64_t i) { sat[i] = saturationOf(c, state.clothWater[i], s.volume[i]); });
}

// The pair loop is written for `omp simd` (plain floats, gathers of j's position and radius) and calls
// the select-only kernels poly6(), viscosityLaplacian(), spikyGradFactor() and cosGravityOf() with
// x_i - x_j summed as Eigen sums a Vec3 (x + (y + z)): the stored values are those of poly6(),
// spikyGrad() and cosGravity() at (x_i - x_j, pairRadius(h_i, h_j)), bit for bit. Only values are
// stored, no sums, so the vector width changes nothing.
namespace {

// pairGeometry, then after(i) for each cloth particle i in the same parallel loop (one fork and join)
template <class After>
void pairGeometryThen(const Model& model, const Particles& p, const NeighborLists& nb, WettingScratch& s,
                      After&& after) {
  const int64_t nc = model.numCloth;
  const uint32_t cloth = static_cast<uint32_t>(nc);
  const size_t entries = nb.index.size();
  s.pairPoly6.resize(entries);
  s.pairLap.resize(entries);
  s.pairCos.resize(entries);
  s.pairSpiky.resize(entries);
  const Vec3 g = gravityDirection(model);
  const float gx = g.x(), gy = g.y(), gz = g.z();
  const float* const x = p.x[0].data();
  const float* const radius = p.radius.data();
  const uint32_t* const list = nb.index.data();
  float* const poly6s = s.pairPoly6.data();
  float* const laps = s.pairLap.data();
  float* const coss = s.pairCos.data();
  float* const spikys = s.pairSpiky.data();
  parallelFor(nc, [&](int64_t i) {
    // local copies: the compiler does not vectorise loads through the closure's references
    const float* const X = x;
    const float* const H = radius;
    const uint32_t* const index = list;
    float* const P6 = poly6s;
    float* const L = laps;
    float* const C = coss;
    float* const F = spikys;
    const float xi = X[3 * i], yi = X[3 * i + 1], zi = X[3 * i + 2], hi = H[i];
    const uint32_t begin = nb.start[i], end = nb.clothEnd(i, cloth);
#pragma omp simd
    for (uint32_t e = begin; e < end; ++e) {
      const uint32_t j = index[e];
      const float dx = xi - X[3 * j], dy = yi - X[3 * j + 1], dz = zi - X[3 * j + 2];
      const float r2 = dx * dx + (dy * dy + dz * dz), r = std::sqrt(r2);
      const float h = pairRadius(hi, H[j]);
      P6[e] = poly6(r2, h);
      C[e] = cosGravityOf(dx * gx + (dy * gy + dz * gz), r);
      L[e] = viscosityLaplacian(r, h);
      F[e] = spikyGradFactor(r2, h);
    }
    after(i);
  });
  s.pairsList = nb.index.data();
  s.pairsSize = entries;
  s.pairsValid = true;
}

}  // namespace

void pairGeometry(const Model& model, const Particles& p, const NeighborLists& nb, WettingScratch& s) {
  pairGeometryThen(model, p, nb, s, [](int64_t) {});
}

void ensurePairGeometry(const Model& model, const Particles& p, const NeighborLists& nb, WettingScratch& s) {
  if (s.pairsValid && s.pairsList == nb.index.data() && s.pairsSize == nb.index.size()) return;
  pairGeometry(model, p, nb, s);
}

void updatePorosity(const Model& model, State& state, const NeighborLists& nb, WettingScratch& s) {
  if (!model.wetting.enabled || model.numCloth == 0) return;
  const Particles& p = state.particles;
  const int64_t nc = model.numCloth;
  const uint32_t cloth = static_cast<uint32_t>(nc);
  const double c = model.wetting.c;
  s.volume.resize(static_cast<size_t>(nc));
  state.clothSaturation.resize(static_cast<size_t>(nc));
  s.areaShare.resize(static_cast<size_t>(nc));
  for (int64_t i = 0; i < nc; ++i) s.areaShare[i] = areaShare(model.wetting.referenceArea, model.clothRestArea[i]);
  // in the loop of the pair geometry, once i's pairs are done: V_i = 1 / sum_k W_ik (Eq. 10) as
  // clothVolumes (the same terms in the same order), S_i as computeSaturation, and the wet mass
  pairGeometryThen(model, p, nb, s, [&](int64_t i) {
    float sum = poly6(0.0f, p.radius[i]);  // k includes i itself
    for (uint32_t e = nb.start[i], end = nb.clothEnd(i, cloth); e < end; ++e) {
      const uint32_t j = nb.index[e];
      if (static_cast<int64_t>(j) >= nc || p.phase[j] != p.phase[i]) continue;  // same piece only
      sum += s.pairPoly6[e];
    }
    s.volume[i] = 1.0f / sum;
    // S <= S^MAX: what a squeezed particle (V_i shrank) cannot hold goes to its buffer (docs/models.md)
    const double most = mostHeldWater(model.wetting, s.volume[i]);
    if (state.clothWater[i] > most) {
      state.clothBuffer[i] += state.clothWater[i] - most;
      state.clothWater[i] = most;
    }
    state.clothSaturation[i] = saturationOf(c, state.clothWater[i], s.volume[i]);
    setWetMass(model, state, i);
  });
}

}  // namespace soak
