// water emission, section 4.4 of Shao et al. 2017 (after Patkar et al. 2013). Water held above S^EW
// moves into the particle's buffer, EW_i = max(0, (S_i - S^EW) V_i) / c (kg). A buffer passes down to
// the neighbours k below i, cos theta_ki EW_i V_i W_ki each, when gravity beats the pull of the wet
// neighbours above (Eq. 18):
//   EW_i > 0  and  | sum_{j above i} V_j S_j cos theta_ij grad W_ij | < |beta g|.
// (V_i W_ki makes the printed cos theta_ki EW_i W_ki a fraction of the buffer; the fractions sum to
// less than one.) A buffer that reaches m^threshold forms a drip particle of that mass, placed below
// the cloth where its density is not above rest (the aim of Lin 2015's placement), which the cloth
// holds by Eq. 19 and which the buffer keeps feeding until it is heavy enough to fall.
#include "wetting/wetting.hpp"

#include "core/kernels.hpp"
#include "core/parallel.hpp"

#include <algorithm>
#include <cmath>

namespace soak {

void findDrips(const Model& model, const State& state, std::vector<int64_t>& index) {
  const Particles& p = state.particles;
  const std::vector<uint32_t>& ids = state.dripId;  // ascending
  index.assign(ids.size(), -1);
  if (ids.empty()) return;
  // one pass over the water: particles may be in any order (sorted by cell), ids are unique
  for (size_t q = static_cast<size_t>(model.numCloth); q < p.size(); ++q) {
    const auto it = std::lower_bound(ids.begin(), ids.end(), p.id[q]);
    if (it != ids.end() && *it == p.id[q]) index[static_cast<size_t>(it - ids.begin())] = static_cast<int64_t>(q);
  }
}

namespace {

// area-weighted normal of cloth particle i at positions x (zero when degenerate)
Vec3 vertexNormal(const Model& model, const std::vector<Vec3>& x, int64_t i) {
  Vec3 n = Vec3::Zero();
  for (int e = model.vertexTriangleStart[i]; e < model.vertexTriangleStart[i + 1]; ++e) {
    const auto& f = model.triangles[static_cast<size_t>(model.vertexTriangles[e])];
    n += (x[f[1]] - x[f[0]]).cross(x[f[2]] - x[f[0]]);
  }
  const float len = n.norm();
  return len > 1e-20f ? Vec3(n / len) : Vec3::Zero();
}

// SPH density a drip of mass m and radius hp would have at y: itself, the water and the cloth as
// Akinci boundary particles (Psi_b = rho0 V_b), the drips made in this stage included
float dripDensity(const Model& model, const Particles& p, const NeighborGrid& grid, size_t gridSize,
                  const WettingScratch& s, const Vec3& y, float m, float hp) {
  const int64_t nc = model.numCloth;
  const float rho0 = model.water.restDensity;
  float rho = m * poly6(0.0f, hp);
  const auto add = [&](size_t j) {
    const float hij = pairRadius(hp, p.radius[j]);
    const float r2 = (y - p.x[j]).squaredNorm();
    if (r2 >= hij * hij) return;
    const float mj = static_cast<int64_t>(j) < nc ? rho0 * s.volume[j] : p.mass[j];
    rho += mj * poly6(r2, hij);
  };
  grid.forEachCandidate(y, [&](uint32_t j) { add(j); });
  for (size_t j = gridSize; j < p.size(); ++j) add(j);
  return rho;
}

}  // namespace

size_t emitExcessWater(const Model& model, State& state, const NeighborLists& nb, const NeighborGrid& grid,
                       WettingScratch& s, float h) {
  const WettingParams& w = model.wetting;
  const int64_t nc = model.numCloth;
  if (!w.enabled || !w.emission || nc == 0) return 0;
  Particles& p = state.particles;
  const Vec3 g = gravityDirection(model);
  const float gMag = model.solver.gravity.norm();
  const double c = w.c;

  // 1. water above S^EW goes into the buffer: EW_i = max(0, (S_i - S^EW) V_i) / c
  parallelFor(nc, [&](int64_t i) {
    const double keep = static_cast<double>(w.saturationEmit) * s.volume[i] / c;
    const double excess = state.clothWater[i] - keep;
    if (excess > 0.0) {
      state.clothWater[i] = keep;
      state.clothBuffer[i] += excess;
    }
  });
  std::vector<float>& sat = state.clothSaturation;
  computeSaturation(model, state, s, sat);
  const auto samePiece = [&](int64_t i, int64_t j) { return j < nc && p.phase[j] == p.phase[i]; };
  const uint32_t cloth = static_cast<uint32_t>(nc);  // loops below read the cloth part of the lists

  // the pairs' cos theta, poly6 and spiky gradient factor (pairGeometry): cos theta_ji is exactly
  // -cos theta_ij and the kernels are symmetric, so the numbers are the same seen from either side
  ensurePairGeometry(model, p, nb, s);
  const float* cosG = s.pairCos.data();
  const float* poly = s.pairPoly6.data();
  const float* spikyF = s.pairSpiky.data();

  // 2. Eq. 18: does gravity beat the pull of the wet neighbours above?
  s.transfers.assign(static_cast<size_t>(nc), 0);
  parallelForDynamic(nc, kWetChunk, [&](int64_t i) {
    if (state.clothBuffer[i] <= 0.0) return;
    Vec3 pull = Vec3::Zero();
    for (uint32_t e = nb.start[i], end = nb.clothEnd(i, cloth); e < end; ++e) {
      const int64_t j = nb.index[e];
      if (!samePiece(i, j)) continue;
      const float cosIJ = cosG[e];  // cosGravity(x_i, x_j, g)
      if (cosIJ <= 0.0f) continue;  // j is not above i
      // spikyGrad(x_i - x_j, h_ij) = f (x_i - x_j)
      pull += (s.volume[j] * sat[j] * cosIJ) * Vec3(spikyF[e] * Vec3(p.x[i] - p.x[j]));
    }
    s.transfers[i] = pull.norm() < w.beta * gMag;
  });
  // 3. the buffer of an upper particle u flowing to a lower neighbour l, before and after scaling;
  // cosLU = cos theta_lu > 0 (l below u) and r2 = |x_l - x_u|^2 are the same numbers seen from u or l
  const double rate = std::min(1.0, static_cast<double>(h) / w.rateStep);
  // (poly6(r2, h_lu) is the pair's poly6, the same from u's or l's list)
  const auto rawFlow = [&](int64_t u, float cosLU, float poly6LU) -> double {
    const float vw = s.volume[u] * poly6LU;
    return rate * static_cast<double>(cosLU * vw) * state.clothBuffer[u];
  };
  int anyTransfer = 0;
  for (int64_t i = 0; i < nc && !anyTransfer; ++i) anyTransfer = s.transfers[i];
  if (anyTransfer) {
    s.outScale.assign(static_cast<size_t>(nc), 0.0f);
    parallelForDynamic(nc, kWetChunk, [&](int64_t u) {
      if (!s.transfers[u]) return;
      double out = 0.0;
      for (uint32_t e = nb.start[u], end = nb.clothEnd(u, cloth); e < end; ++e) {
        const int64_t l = nb.index[e];
        if (!samePiece(u, l)) continue;
        const float cosLU = -cosG[e];  // cosGravity(x_l, x_u, g)
        if (cosLU > 0.0f) out += rawFlow(u, cosLU, poly[e]);
      }
      // the fractions sum below one; this only guards strongly compressed cloth
      s.outScale[u] = out > state.clothBuffer[u] ? static_cast<float>(state.clothBuffer[u] / out) : 1.0f;
    });
    // gathered per particle: what arrives from above minus what leaves below, the same numbers both ways
    s.delta.resize(static_cast<size_t>(nc));
    parallelForDynamic(nc, kWetChunk, [&](int64_t k) {
      double d = 0.0;
      for (uint32_t e = nb.start[k], end = nb.clothEnd(k, cloth); e < end; ++e) {
        const int64_t j = nb.index[e];
        if (!samePiece(k, j)) continue;
        if (!s.transfers[j] && !s.transfers[k]) continue;  // neither sheds water: no flow either way
        const float cosKJ = cosG[e];  // > 0: k below j; cos theta_jk is exactly -cosKJ
        if (cosKJ > 0.0f && s.transfers[j])
          d += static_cast<double>(s.outScale[j]) * rawFlow(j, cosKJ, poly[e]);
        else if (cosKJ < 0.0f && s.transfers[k])
          d -= static_cast<double>(s.outScale[k]) * rawFlow(k, -cosKJ, poly[e]);
      }
      s.delta[k] = d;
    });
  } else {
    s.delta.assign(static_cast<size_t>(nc), 0.0);
  }
  parallelFor(nc, [&](int64_t i) { state.clothBuffer[i] = std::max(0.0, state.clothBuffer[i] + s.delta[i]); });

  // 4. drips, serially in cloth order (few; new ids in a fixed order). Drips that are gone or have
  // fallen out of their source's reach are let go; a source keeps feeding its hanging drip.
  const float m0 = model.water.particleMass, h0 = model.water.supportRadius, rho0 = model.water.restDensity;
  std::vector<int64_t>& dripOf = s.dripOf;
  dripOf.assign(static_cast<size_t>(nc), -1);
  size_t kept = 0;
  std::vector<int64_t> dripIndex;
  findDrips(model, state, dripIndex);
  for (size_t d = 0; d < state.dripId.size(); ++d) {
    const int64_t q = dripIndex[d];
    const int32_t src = state.dripSource[d];
    if (q < 0 || p.mass[q] <= 0.0f || (p.x[q] - p.x[src]).norm() >= p.radius[q]) continue;
    state.dripId[kept] = state.dripId[d];
    state.dripSource[kept++] = src;
    dripOf[src] = q;
  }
  state.dripId.resize(kept);
  state.dripSource.resize(kept);
  for (int64_t i = 0; i < nc; ++i) {
    const int64_t q = dripOf[i];
    if (q < 0 || state.clothBuffer[i] <= 0.0) continue;
    const float before = p.mass[q];
    const float after = before + static_cast<float>(state.clothBuffer[i]);
    state.clothBuffer[i] -= static_cast<double>(after) - static_cast<double>(before);  // exact: both floats
    p.mass[q] = after;
    p.invMass[q] = 1.0f / after;
    p.radius[q] = std::cbrt(after / m0) * h0;
  }
  const size_t gridSize = grid.cellEntries.size();
  const float mDrip = w.massThreshold;
  const float hDrip = std::cbrt(mDrip / m0) * h0;  // h_p = (m_p / m0)^(1/3) h0
  size_t made = 0;
  for (int64_t i = 0; i < nc; ++i) {
    if (dripOf[i] >= 0 || state.clothBuffer[i] < static_cast<double>(mDrip)) continue;
    if (p.size() >= static_cast<size_t>(model.solver.maxParticles)) break;
    // below along gravity first, then off the cloth's surface on either side
    const Vec3 n = vertexNormal(model, p.x, i);
    const Vec3 dirs[5] = {g, (g + n).normalized(), (g - n).normalized(), n, -n};
    bool placed = false;
    Vec3 y = p.x[i];
    for (const Vec3& dir : dirs) {
      if (placed || !dir.allFinite() || dir.squaredNorm() < 0.5f) continue;
      for (int k = 1; k <= 6 && !placed; ++k) {
        y = p.x[i] + (0.25f * static_cast<float>(k) * hDrip) * dir;
        placed = dripDensity(model, p, grid, gridSize, s, y, mDrip, hDrip) <= rho0;
      }
    }
    if (!placed) continue;  // crowded: try again next substep
    const uint32_t id = state.nextId++;
    p.add(kWaterPhase, id, mDrip, hDrip, y, p.v[i]);
    state.clothBuffer[i] -= static_cast<double>(mDrip);
    state.dripId.push_back(id);  // the newest id is the largest: the list stays ascending
    state.dripSource.push_back(static_cast<int32_t>(i));
    ++made;
  }
  state.ledger.dripsEmitted += made;
  return made;
}

// f_p = sum_i kappa^e (m_i + eta^e S_i) (Psi_i / rho0) W(x_ip, h_p) along x_i - x_p (Eq. 19), Psi_i =
// rho0 V_i (NOTES.md); kappa^e in m/s^2 and eta^e in kg make it newtons. The kernel's support h_p grows
// with the drip, so its peak falls as 1/m_p while the drip's weight rises: a heavy drip falls.
void applyDripAttraction(const Model& model, State& state, const NeighborLists& nb, const WettingScratch& s, float h) {
  const WettingParams& w = model.wetting;
  const int64_t nc = model.numCloth;
  if (!w.enabled || !w.emission || nc == 0 || state.dripId.empty()) return;
  Particles& p = state.particles;
  const size_t covered = nb.start.size() - 1;  // particles the neighbour lists cover
  std::vector<int64_t> dripIndex;
  findDrips(model, state, dripIndex);
  for (size_t d = 0; d < state.dripId.size(); ++d) {
    const int64_t q = dripIndex[d];
    const int64_t src = state.dripSource[d];
    if (q < 0 || p.mass[q] <= 0.0f || static_cast<size_t>(src) >= covered) continue;
    const float hq = p.radius[q];
    Vec3 total = Vec3::Zero();
    const auto pull = [&](int64_t i) {
      const Vec3 r = p.x[i] - p.x[q];
      const float r2 = r.squaredNorm();
      if (r2 >= hq * hq || r2 < 1e-18f) return;
      // (Psi_i / rho0) W = V_i W(x_ip, h_p)
      const float mag = w.attraction * (p.mass[i] + w.attractionSaturation * state.clothSaturation[i]) *
                        s.volume[i] * poly6(r2, hq);
      const Vec3 f = (mag / std::sqrt(r2)) * r;
      total += f;
      p.v[i] -= (h * p.invMass[i]) * f;  // the cloth carries the drip: equal and opposite
    };
    pull(src);
    for (uint32_t e = nb.start[src]; e < nb.start[src + 1]; ++e)
      if (static_cast<int64_t>(nb.index[e]) < nc) pull(nb.index[e]);
    p.v[q] += (h * p.invMass[q]) * total;
  }
}

}  // namespace soak
