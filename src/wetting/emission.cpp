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
  // one pass over the water: particles may be in any order (sorted by cell); ids are unique, so each
  // entry is written by one particle at most, whichever thread finds it
  const int64_t nc = model.numCloth;
  parallelFor(static_cast<int64_t>(p.size()) - nc, [&](int64_t w) {
    const size_t q = static_cast<size_t>(nc + w);
    const auto it = std::lower_bound(ids.begin(), ids.end(), p.id[q]);
    if (it != ids.end() && *it == p.id[q]) index[static_cast<size_t>(it - ids.begin())] = static_cast<int64_t>(q);
  });
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

// W(y - x_j) of a drip of radius hp at y and particle j, over the pair's mean radius; 0 outside it
float dripKernel(const Particles& p, const Vec3& y, float hp, size_t j) {
  const float hij = pairRadius(hp, p.radius[j]);
  const float r2 = (y - p.x[j]).squaredNorm();
  return r2 < hij * hij ? poly6(r2, hij) : 0.0f;
}

// SPH density a drip of mass m and radius hp would have at y, without the drips made in this stage
// (indices from gridSize on): itself, the water and the cloth as Akinci boundary particles (Psi_b =
// rho0 V_b). big: the particles wider than the grid's cells (NeighborLists::big), which its 27 cells
// may not reach. Stops once the sum passes limit and returns that partial sum: every term is >= 0
// and adding one never lowers a float sum, so the whole sum would be above limit too (a drip source
// under water tried its 30 places against every particle around each: 3.6 of Fig. 9(b)'s 7 ms)
float dripDensityBefore(const Model& model, const Particles& p, const NeighborGrid& grid, const std::vector<uint32_t>& big,
                        const WettingScratch& s, const Vec3& y, float m, float hp, float limit) {
  const int64_t nc = model.numCloth;
  const float rho0 = model.water.restDensity;
  float rho = m * poly6(0.0f, hp);
  // adds particle j's term; true once the sum has passed limit
  const auto add = [&](size_t j) {
    const float w = dripKernel(p, y, hp, j);
    if (w > 0.0f) rho += (static_cast<int64_t>(j) < nc ? rho0 * s.volume[j] : p.mass[j]) * w;
    return rho > limit;
  };
  const bool over = grid.forEachCandidate(y, [&](uint32_t j) {
    return !std::binary_search(big.begin(), big.end(), j) && add(j);  // each big one once, below
  });
  if (!over)
    for (const uint32_t j : big)
      if (add(j)) break;
  return rho;
}

// rho (dripDensityBefore at y) plus the drips made in this stage, in index order: the whole density
float addNewDrips(float rho, const Particles& p, size_t gridSize, const Vec3& y, float hp) {
  for (size_t j = gridSize; j < p.size(); ++j) {
    const float w = dripKernel(p, y, hp, j);
    if (w > 0.0f) rho += p.mass[j] * w;
  }
  return rho;
}

// where a drip may go below a cloth particle whose vertex normal is n: along gravity g first, then off
// the cloth's surface on either side (dirs), at 1/4 .. 6/4 h_p along each: placement t is
// dirs[t / 6] at (t % 6 + 1) / 4 h_p
constexpr int kDripTries = 30;
struct DripDirections {
  Vec3 dirs[5];
  explicit DripDirections(const Vec3& g, const Vec3& n) : dirs{g, (g + n).normalized(), (g - n).normalized(), n, -n} {}
  // placement t from x_i; false when its direction does not exist (no gravity, a degenerate normal) or
  // points more than 30 degrees above the horizontal: no drip on the top face of a sheet lying flat (on
  // a ball or a floor, where it was pushed into the sheet and flung), its excess runs down (Eq. 18)
  bool placement(const Vec3& xi, float hp, int t, Vec3& y) const {
    const Vec3& dir = dirs[t / 6];
    if (!dir.allFinite() || dir.squaredNorm() < 0.5f || dir.dot(dirs[0]) < -0.5f) return false;
    y = xi + (0.25f * static_cast<float>(t % 6 + 1) * hp) * dir;
    return true;
  }
};

// 1. water above S^EW goes into the buffer, then S_i (computeSaturation's) of what stays
void fillBuffers(const Model& model, State& state, const WettingScratch& s) {
  const WettingParams& w = model.wetting;
  const int64_t nc = model.numCloth;
  const double c = w.c;
  // EW_i = max(0, (S_i - S^EW) V_i) / c; then S_i as computeSaturation, in the same loop. A buffer
  // holding m^threshold (a drip that found no place, under water) takes no more, from its particle or
  // from above (moveBuffersDown), so a sheet under water does not pump the pool into its buffers
  // (departure: docs/models.md). m^threshold is per referenceArea of cloth (dripThreshold)
  std::vector<float>& sat = state.clothSaturation;
  sat.resize(static_cast<size_t>(nc));
  parallelFor(nc, [&](int64_t i) {
    const double keep = static_cast<double>(w.saturationEmit) * s.volume[i] / c;
    const double excess = state.clothWater[i] - keep;
    if (excess > 0.0 && state.clothBuffer[i] < dripThreshold(w, s.areaShare[i])) {  // a full buffer takes no more (below)
      state.clothWater[i] = keep;
      state.clothBuffer[i] += excess;
    }
    sat[i] = saturationOf(c, state.clothWater[i], s.volume[i]);
  });
}

// the neighbour loops' inputs: pointers into the lists, the particles, the saturation, volume and
// buffers, and the pairs' cos theta, poly6 and spiky gradient factor (pairGeometry): cos theta_ji is
// exactly -cos theta_ij and the kernels are symmetric, so the numbers are the same seen from either side.
// Each loop computes the pairs' terms in a vectorised loop (plain floats and doubles, selects, the
// arithmetic of the scalar expressions) into a per-thread buffer and sums them in list order, so every
// result is that of the scalar loop. A pair the scalar loop skipped contributes a zero, which leaves a
// sum started at +0 unchanged. Pointers are copied into the loops' own locals: the compiler does not
// vectorise loads through a lambda's captures.
struct FlowInputs {
  const uint32_t* indexAll;
  const int32_t* phaseAll;
  const float* xAll;
  const float* satAll;
  const float* volumeAll;
  const double* bufferAll;
  const float *cosG, *poly, *spikyF;
};

FlowInputs flowInputs(const Model& model, const State& state, const NeighborLists& nb, WettingScratch& s) {
  const Particles& p = state.particles;
  ensurePairGeometry(model, p, nb, s);
  return {nb.index.data(), p.phase.data(), p.x[0].data(), state.clothSaturation.data(), s.volume.data(),
          state.clothBuffer.data(), s.pairCos.data(), s.pairPoly6.data(), s.pairSpiky.data()};
}

// 2. Eq. 18: s.transfers[i] when gravity beats the pull of i's wet neighbours above
void markTransfers(const Model& model, const NeighborLists& nb, const FlowInputs& in, WettingScratch& s) {
  const int64_t nc = model.numCloth;
  const uint32_t cloth = static_cast<uint32_t>(nc);
  const uint32_t* const indexAll = in.indexAll;
  const int32_t* const phaseAll = in.phaseAll;
  const float* const xAll = in.xAll;
  const float* const satAll = in.satAll;
  const float* const volumeAll = in.volumeAll;
  const double* const bufferAll = in.bufferAll;
  const float* const cosG = in.cosG;
  const float* const spikyF = in.spikyF;
  s.transfers.assign(static_cast<size_t>(nc), 0);
  const float pullLimit = model.wetting.beta * model.solver.gravity.norm();
  parallelForDynamic(nc, kWetChunk, [&](int64_t i) {
    if (bufferAll[i] <= 0.0) return;
    const uint32_t begin = nb.start[i], count = nb.clothEnd(i, cloth) - begin;
    const uint32_t* const J = indexAll + begin;
    const float* const C = cosG + begin;
    const float* const F = spikyF + begin;
    const int32_t* const P = phaseAll;
    const float* const X = xAll;
    const float* const SL = satAll;
    const float* const VL = volumeAll;
    float* const Tx = s.pairFloat.get(3 * static_cast<size_t>(count));
    float* const Ty = Tx + count;
    float* const Tz = Ty + count;
    const uint32_t clothL = cloth;
    const int32_t phi = P[i];
    const float xi = X[3 * i], yi = X[3 * i + 1], zi = X[3 * i + 2];
#pragma omp simd
    for (uint32_t k = 0; k < count; ++k) {
      const uint32_t j = J[k];
      const bool same = (j < clothL) & (P[j] == phi);
      const uint32_t jj = same ? j : static_cast<uint32_t>(i);  // S and V hold cloth only
      const float cosIJ = C[k];                                 // cosGravity(x_i, x_j, g)
      const bool above = same & (cosIJ > 0.0f);                 // j is above i
      // (V_j S_j cos) spikyGrad(x_i - x_j, h_ij), spikyGrad = f (x_i - x_j)
      const float q = VL[jj] * SL[jj] * cosIJ, f = F[k];
      const float dx = xi - X[3 * j], dy = yi - X[3 * j + 1], dz = zi - X[3 * j + 2];
      // times 1 or 0, not a select: the compiler would make the gathers masked, which it cannot emulate
      const float m = above ? 1.0f : 0.0f;
      Tx[k] = q * (f * dx) * m;
      Ty[k] = q * (f * dy) * m;
      Tz[k] = q * (f * dz) * m;
    }
    Vec3 pull = Vec3::Zero();
    for (uint32_t k = 0; k < count; ++k) pull += Vec3(Tx[k], Ty[k], Tz[k]);
    s.transfers[i] = pull.norm() < pullLimit;
  });
}

// Eq. 18's transfer: the buffer of an upper particle u flows to a lower neighbour l at
// rate cos theta_lu V_u W_lu EW_u; cos theta_lu > 0 (l below u) and W_lu = poly6(|x_l - x_u|^2, h_lu)
// are the pair's numbers (pairGeometry), the same seen from u or l. rate = h / rateStep of one part (moveBuffersDown).

// s.outScale[u]: the share of each shedding particle's flows its buffer can pay (1 but where strongly
// compressed cloth asks for more than it holds; 0 where it does not shed)
void outflowScales(const Model& model, const NeighborLists& nb, const FlowInputs& in, double rate,
                   WettingScratch& s) {
  const WettingParams& w = model.wetting;
  const int64_t nc = model.numCloth;
  const uint32_t cloth = static_cast<uint32_t>(nc);
  const uint32_t* const indexAll = in.indexAll;
  const int32_t* const phaseAll = in.phaseAll;
  const float* const volumeAll = in.volumeAll;
  const double* const bufferAll = in.bufferAll;
  const float* const cosG = in.cosG;
  const float* const poly = in.poly;
  s.outScale.assign(static_cast<size_t>(nc), 0.0f);  // stays 0 exactly where transfers is 0
  parallelForDynamic(nc, kWetChunk, [&](int64_t u) {
    if (!s.transfers[u]) return;
    const uint32_t begin = nb.start[u], count = nb.clothEnd(u, cloth) - begin;
    const uint32_t* const J = indexAll + begin;
    const float* const C = cosG + begin;
    const float* const W = poly + begin;
    const int32_t* const P = phaseAll;
    double* const T = s.pairDouble.get(count);
    const uint32_t clothL = cloth;
    const int32_t phu = P[u];
    const float vu = volumeAll[u];
    const double* const B = bufferAll;
    const double bu = bufferAll[u], rateL = rate;
    const float* const A = s.areaShare.data();
    const float thr = w.massThreshold;  // a local: the loop below is vectorised
#pragma omp simd
    for (uint32_t k = 0; k < count; ++k) {
      const uint32_t l = J[k];
      const bool same = (l < clothL) & (P[l] == phu);
      const uint32_t ll = same ? l : static_cast<uint32_t>(u);  // buffers hold cloth only
      const float cosLU = -C[k];  // cosGravity(x_l, x_u, g)
      const bool below = same & (cosLU > 0.0f) & (B[ll] < dripThreshold(thr, A[ll]));  // and l's buffer takes water
      T[k] = bufferFlow(rateL, cosLU, vu, W[k], bu) * (below ? 1.0 : 0.0);  // +-0 where not below
    }
    double out = 0.0;
    for (uint32_t k = 0; k < count; ++k) out += T[k];
    // the fractions sum below one; this only guards strongly compressed cloth
    s.outScale[u] = out > bu ? static_cast<float>(bu / out) : 1.0f;
  });
}

// s.delta[k]: what arrives at k from above minus what leaves it below, gathered per particle, the same
// numbers both ways. outScale > 0 stands for transfers (a shedding particle's scale is positive; were
// it 0 its flows would be zeros anyway)
void netFlows(const Model& model, const NeighborLists& nb, const FlowInputs& in, double rate, WettingScratch& s) {
  const WettingParams& w = model.wetting;
  const int64_t nc = model.numCloth;
  const uint32_t cloth = static_cast<uint32_t>(nc);
  const uint32_t* const indexAll = in.indexAll;
  const int32_t* const phaseAll = in.phaseAll;
  const float* const volumeAll = in.volumeAll;
  const double* const bufferAll = in.bufferAll;
  const float* const cosG = in.cosG;
  const float* const poly = in.poly;
  const float* const outScaleAll = s.outScale.data();
  s.delta.resize(static_cast<size_t>(nc));
  parallelForDynamic(nc, kWetChunk, [&](int64_t k) {
    // no flow either way unless k or a neighbour sheds (most of a cloth): d stays +0
    bool sheds = s.transfers[k];
    for (uint32_t e = nb.start[k], end = nb.clothEnd(k, cloth); e < end && !sheds; ++e)
      sheds = nb.index[e] < cloth && s.transfers[nb.index[e]];
    if (!sheds) {
      s.delta[k] = 0.0;
      return;
    }
    const uint32_t begin = nb.start[k], count = nb.clothEnd(k, cloth) - begin;
    const uint32_t* const J = indexAll + begin;
    const float* const C = cosG + begin;
    const float* const W = poly + begin;
    const int32_t* const P = phaseAll;
    const float* const VL = volumeAll;
    const float* const OS = outScaleAll;
    const double* const B = bufferAll;
    double* const T = s.pairDouble.get(count);
    const uint32_t clothL = cloth;
    const int32_t phk = P[k];
    const float vk = VL[k], osk = OS[k];
    const double bk = B[k], rateL = rate, fullK = dripThreshold(w, s.areaShare[k]);
    const float* const A = s.areaShare.data();
    const float thr = w.massThreshold;  // a local: the loop below is vectorised
#pragma omp simd
    for (uint32_t e = 0; e < count; ++e) {
      const uint32_t j = J[e];
      const bool same = (j < clothL) & (P[j] == phk);
      const uint32_t jj = same ? j : static_cast<uint32_t>(k);
      const float cosKJ = C[e];  // > 0: k below j; cos theta_jk is exactly -cosKJ
      const float osj = OS[jj];
      const bool fromJ = same & (cosKJ > 0.0f) & (osj > 0.0f) & (bk < fullK);     // j sheds into k
      const bool toJ = same & (cosKJ < 0.0f) & (osk > 0.0f) & (B[jj] < dripThreshold(thr, A[jj]));   // k sheds into j
      // outScale_u bufferFlow(u -> l)
      const double in = static_cast<double>(osj) * bufferFlow(rateL, cosKJ, VL[jj], W[e], B[jj]);
      const double out = static_cast<double>(osk) * bufferFlow(rateL, -cosKJ, vk, W[e], bk);
      T[e] = in * (fromJ ? 1.0 : 0.0) - out * (toJ ? 1.0 : 0.0);  // in, -out or +-0
    }
    double d = 0.0;
    for (uint32_t e = 0; e < count; ++e) d += T[e];
    s.delta[k] = d;
  });
}

// 3. the buffers flow down to the neighbours below, over a wetting pass of h: Eq. 18's transfer is a
// share per rateStep, so a pass is cut into equal parts of at most rateStep, each moving h / parts /
// rateStep of it (a rate in time for any dt; a pass up to rateStep is one part)
void moveBuffersDown(const Model& model, State& state, const NeighborLists& nb, const FlowInputs& in,
                     WettingScratch& s, float h) {
  const int64_t nc = model.numCloth;
  const double steps = static_cast<double>(h) / model.wetting.rateStep;
  const int parts = std::max(1, static_cast<int>(std::ceil(steps - 1e-6)));
  const double rate = steps / parts;
  for (int part = 0; part < parts; ++part) {
    if (part > 0) markTransfers(model, nb, in, s);  // the buffers changed
    int anyTransfer = 0;
    for (int64_t i = 0; i < nc && !anyTransfer; ++i) anyTransfer = s.transfers[i];
    if (!anyTransfer) return;
    outflowScales(model, nb, in, rate, s);
    netFlows(model, nb, in, rate, s);
    parallelFor(nc, [&](int64_t i) { state.clothBuffer[i] = std::max(0.0, state.clothBuffer[i] + s.delta[i]); });
  }
}

// 4a. the drips still hanging: kept in state.dripId / dripSource and in s.dripOf (the drip of each
// source, -1: none), each fed from its source's buffer up to maxDrip (at least the source's m^threshold)
void feedHangingDrips(const Model& model, State& state, WettingScratch& s, float maxDrip) {
  const auto largest = [&](int64_t src) { return std::max(maxDrip, dripThreshold(model.wetting, s.areaShare[src])); };
  const int64_t nc = model.numCloth;
  Particles& p = state.particles;
  const float m0 = model.water.particleMass, h0 = model.water.supportRadius;
  // 4. drips, serially in cloth order (few; new ids in a fixed order). Drips that are gone, have
  // fallen out of their source's reach or have grown to the largest drip mass are let go; a source
  // keeps feeding its hanging drip up to that mass (departure: docs/models.md)
  std::vector<int64_t>& dripOf = s.dripOf;
  dripOf.assign(static_cast<size_t>(nc), -1);
  size_t kept = 0;
  std::vector<int64_t> dripIndex;
  findDrips(model, state, dripIndex);
  for (size_t d = 0; d < state.dripId.size(); ++d) {
    const int64_t q = dripIndex[d];
    const int32_t src = state.dripSource[d];
    if (q < 0 || p.mass[q] <= 0.0f || p.mass[q] >= largest(src) || (p.x[q] - p.x[src]).norm() >= p.radius[q]) continue;
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
    const float after = std::min(before + static_cast<float>(state.clothBuffer[i]), largest(i));
    if (!(after > before)) continue;
    state.clothBuffer[i] -= static_cast<double>(after) - static_cast<double>(before);  // exact: both floats
    p.setMass(static_cast<size_t>(q), after, false);
    p.radius[q] = std::cbrt(after / m0) * h0;
  }
}

// 4b. a new drip below every source whose buffer holds its m^threshold (times its areaShare) and that
// has none hanging, at the first place with room (Eq. 18's emission; the places: DripDirections);
// returns how many
size_t placeNewDrips(const Model& model, State& state, const NeighborLists& nb, const NeighborGrid& grid,
                     const std::vector<ColliderPose>& poses, WettingScratch& s) {
  const WettingParams& w = model.wetting;
  const int64_t nc = model.numCloth;
  Particles& p = state.particles;
  const Vec3 g = gravityDirection(model);
  const float m0 = model.water.particleMass, h0 = model.water.supportRadius, rho0 = model.water.restDensity;
  const std::vector<int64_t>& dripOf = s.dripOf;
  const size_t gridSize = grid.cellEntries.size();
  const auto dripMass = [&](int32_t i) { return dripThreshold(w, s.areaShare[static_cast<size_t>(i)]); };
  const auto dripRadius = [&](int32_t i) { return std::cbrt(dripMass(i) / m0) * h0; };  // h_p = (m_p / m0)^(1/3) h0
  // a place inside a collider (below a sheet lying on the floor or on a ball) would be pushed out at
  // the next substep, through the far side of a thin floor or flung off the ball (departure: docs/models.md)
  const float clearance = contactMargin(model, kWaterPhase);
  const size_t numColliders = std::min(model.colliders.size(), poses.size());
  const auto clearOfColliders = [&](const Vec3& y) {
    for (size_t c = 0; c < numColliders; ++c)
      if (colliderDistance(model.colliders[c], poses[c], y, nullptr) < clearance) return false;
    return true;
  };
  const auto place = [&](const DripDirections& along, const Vec3& xi, float hDrip, int t, Vec3& y) {
    return along.placement(xi, hDrip, t, y) && clearOfColliders(y);
  };
  // the sources, in cloth order; then, in parallel, each one's first placement that the density
  // before this stage's drips allows (a placement it crowds stays crowded: the drips made below only
  // add density); then, serially in cloth order, the drips made before it are added, and a placement
  // they crowd moves on to the next ones. The same drips, places and sums as trying every placement
  // serially, with the density's terms added in the same order
  std::vector<int32_t>& sources = s.dripSources;
  sources.clear();
  for (int64_t i = 0; i < nc; ++i)
    if (dripOf[i] < 0 && state.clothBuffer[i] >= static_cast<double>(dripMass(static_cast<int32_t>(i))))
      sources.push_back(static_cast<int32_t>(i));
  const int64_t nSources = static_cast<int64_t>(sources.size());
  s.dripTry.assign(sources.size(), -1);
  s.dripBase.assign(sources.size(), 0.0f);
  s.dripNormal.resize(sources.size());
#pragma omp parallel for schedule(dynamic, 4) if (nSources > 8)
  for (int64_t c = 0; c < nSources; ++c) {
    const int32_t i = sources[static_cast<size_t>(c)];
    const float mDrip = dripMass(i), hDrip = dripRadius(i);
    s.dripNormal[static_cast<size_t>(c)] = vertexNormal(model, p.x, i);
    const DripDirections along(g, s.dripNormal[static_cast<size_t>(c)]);
    for (int t = 0; t < kDripTries; ++t) {
      Vec3 y;
      if (!place(along, p.x[i], hDrip, t, y)) continue;
      const float rho = dripDensityBefore(model, p, grid, nb.big, s, y, mDrip, hDrip, rho0);
      if (rho <= rho0) {
        s.dripTry[static_cast<size_t>(c)] = t;
        s.dripBase[static_cast<size_t>(c)] = rho;
        break;
      }
    }
  }
  size_t made = 0;
  for (int64_t c = 0; c < nSources; ++c) {
    if (p.size() >= static_cast<size_t>(model.solver.maxParticles)) break;
    const int32_t i = sources[static_cast<size_t>(c)];
    int t = s.dripTry[static_cast<size_t>(c)];
    if (t < 0) continue;  // crowded: try again at the next wetting pass
    const float mDrip = dripMass(i), hDrip = dripRadius(i);
    const DripDirections along(g, s.dripNormal[static_cast<size_t>(c)]);
    Vec3 y;
    place(along, p.x[i], hDrip, t, y);
    bool placed = addNewDrips(s.dripBase[static_cast<size_t>(c)], p, gridSize, y, hDrip) <= rho0;
    while (!placed && ++t < kDripTries)
      if (place(along, p.x[i], hDrip, t, y))
        placed = addNewDrips(dripDensityBefore(model, p, grid, nb.big, s, y, mDrip, hDrip, rho0), p, gridSize, y, hDrip) <= rho0;
    if (!placed) continue;
    const uint32_t id = state.nextId++;
    p.add(kWaterPhase, id, mDrip, hDrip, y, p.v[i]);
    state.clothBuffer[i] -= static_cast<double>(mDrip);
    state.dripId.push_back(id);  // the newest id is the largest: the list stays ascending
    state.dripSource.push_back(i);
    ++made;
  }
  state.ledger.dripsEmitted += made;
  return made;
}

}  // namespace

size_t emitExcessWater(const Model& model, State& state, const NeighborLists& nb, const NeighborGrid& grid,
                       const std::vector<ColliderPose>& poses, WettingScratch& s, float h) {
  s.pairFloat.prepare();  // the per-thread pair buffers of the loops below
  s.pairDouble.prepare();
  const WettingParams& w = model.wetting;
  if (!w.enabled || !w.emission || model.numCloth == 0) return 0;
  fillBuffers(model, state, s);                                    // S > S^EW: into the buffer
  const FlowInputs in = flowInputs(model, state, nb, s);
  markTransfers(model, nb, in, s);                                 // Eq. 18: gravity beats the pull above
  moveBuffersDown(model, state, nb, in, s, h);                     // the buffers flow down
  const float maxDrip = w.maxDripMass > 0.0f ? w.maxDripMass : 4.0f * model.water.particleMass;
  feedHangingDrips(model, state, s, maxDrip);                      // hanging drips grow, or let go
  const size_t made = placeNewDrips(model, state, nb, grid, poses, s);  // new drips where there is room
  updateWetMasses(model, state);                                   // the buffers moved: m = dry + held + buffer
  return made;
}

// f_p = sum_i kappa^e (m_i + eta^e S_i) (Psi_i / rho0) W(x_ip, h_p) along x_i - x_p (Eq. 19), Psi_i =
// rho0 V_i (NOTES.md); kappa^e in m/s^2 and eta^e in kg make it newtons (eta^e per referenceArea of
// cloth: times the particle's areaShare). The kernel's support h_p grows
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
      const float mag = w.attraction * (p.mass[i] + w.attractionSaturation * s.areaShare[i] * state.clothSaturation[i]) *
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
