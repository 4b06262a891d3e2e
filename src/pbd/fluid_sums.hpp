// The neighbour sums of the PBF solver (pbd/fluid.cpp): for one particle, the sum over its list of a
// pair formula of pbd/fluid_pairs.hpp. Each sum has a vectorised loop of simd::kLanes pairs at a time
// and a scalar loop, which call the same pair formula: j's data are gathered (positions loaded and
// transposed), every lane does the scalar loop's arithmetic for its pair, the sums are kept per lane
// and added across lanes at the end (simd::sum). Lanes past the list's end have mass 0 and masked
// kernels: they add 0. Lists shorter than kSimdMinPairs (spray) take the scalar loop, which is then
// faster. The order of a sum depends on the list's length, never on the thread count; results differ
// from a build without the wide type in the last bits.
// Internal to pbd/fluid.cpp.
#pragma once
#include <soak/model.hpp>

#include "core/simd.hpp"
#include "pbd/fluid_pairs.hpp"

#include <cstdint>

namespace soak::pbf {

// what the pair loops of one solver pass read: the positions, radii, masses (Psi for cloth), inverse
// masses and lambdas of every particle, and the pass's constants
struct PairInputs {
  const float* X;          // xPred, 3 floats a particle
  const float* H;          // support radius
  const float* M;          // m_j for water, Psi_j for cloth (massOrPsi)
  const float* W;          // inverse mass
  const float* L;          // lambda (0 for cloth)
  const float* mass;       // the particle's own mass
  const int32_t* phase;
  const uint32_t* index;   // neighbour lists
  size_t indexSize;        // their entries (the lanes of the last one stop there)
  float hU;                // the common radius (uniform case) and its kernel constants
  PairKernel<float> kU;
  float invRho0;
  float sCorrK, oneMinusDq2;
  int tensileN;
  // the pair cache (FluidScratch::pairG*): the lambda pass writes m_j sf_ij r_ij and |r_ij|^2 (only
  // with artificial pressure; cacheR2 null without) of list entry k at [k - cacheBase], the correction
  // pass of the same iteration reads them; null when off
  float* cacheGx = nullptr;
  float* cacheGy = nullptr;
  float* cacheGz = nullptr;
  float* cacheR2 = nullptr;
  uint32_t cacheBase = 0;
  float plainM = 0.0f, plainW = 0.0f;  // m_j and w_j of a plain particle's neighbours (markNeighbourhoods)
};

// entry k of a list in the scalar loops: the neighbour j, x_i - x_j, its square and the pair's kernel
struct ScalarPair {
  uint32_t j;
  float rx, ry, rz, r2;
  PairKernel<float> kernel;
};
template <bool U>
inline ScalarPair scalarPair(const PairInputs& in, uint32_t k, float xi, float yi, float zi, float hi) {
  const uint32_t j = in.index[k];
  const float* X = in.X;
  const float rx = xi - X[3 * j], ry = yi - X[3 * j + 1], rz = zi - X[3 * j + 2];
  const float h = pairRadius(hi, in.H[j]);
  return {j, rx, ry, rz, rx * rx + ry * ry + rz * rz, U ? in.kU : pairKernel(h, 1.0f / h)};
}

// s_corr of the pair (i, j) for the correction pass: 0 without artificial pressure and for a cloth j
template <bool Tensile>
inline float sCorrOf(const PairInputs& in, uint32_t j, float r2, float h) {
  return Tensile && in.phase[j] == kWaterPhase ? artificialPressure(h * h, r2, in.sCorrK, in.oneMinusDq2, in.tensileN)
                                               : 0.0f;
}

#if SOAK_SIMD_WIDE
constexpr uint32_t kSimdMinPairs = 4;
using simd::FloatW;
using simd::MaskW;
using simd::UintW;

// the lanes' pairs of particle i: j = index[k .. min(k + kLanes, end)) (mask m) and r = x_i - x_j,
// r2 = |r|^2 as the scalar loop rounds it; past end, j = 0 and r of whatever neighbourPositions read
struct Pairs {
  MaskW m;
  UintW j;
  FloatW rx, ry, rz, r2;
};
// the positions of the lanes' neighbours index[k ..), lanes m: past the list's end the lanes read the
// next lists' neighbours (valid particles, masked by the callers); at the end of the index array they
// read particle 0. (Not a copy of the lanes: its scalar loads would wait for the vector store)
inline void neighbourPositions(const PairInputs& in, uint32_t k, MaskW m, UintW j, FloatW& x, FloatW& y, FloatW& z) {
  if (k + simd::kLanes <= in.indexSize) return simd::loadXyz(in.X, in.index + k, x, y, z);
  alignas(64) uint32_t copy[simd::kLanes];
  simd::store(copy, simd::select(m, j));
  simd::loadXyz(in.X, copy, x, y, z);
}
inline Pairs pairsAt(const PairInputs& in, uint32_t k, uint32_t end, FloatW xi, FloatW yi, FloatW zi) {
  Pairs q;
  q.m = simd::firstLanes(end - k);
  q.j = simd::load(in.index + k, q.m);
  FloatW xj, yj, zj;
  neighbourPositions(in, k, q.m, q.j, xj, yj, zj);
  q.rx = xi - xj;
  q.ry = yi - yj;
  q.rz = zi - zj;
  q.r2 = q.rx * q.rx + q.ry * q.ry + q.rz * q.rz;
  return q;
}
// the kernel constants of the lanes' pairs with particle i (radius hi); loop constants when every
// radius is equal
template <bool U>
inline PairKernel<FloatW> kernelOf(const PairInputs& in, MaskW m, UintW j, float hi) {
  if (U) return {in.kU.h, in.kU.h2, in.kU.poly6, in.kU.spiky};
  const FloatW h = pairRadius(FloatW(hi), simd::gather(in.H, j, m, hi));
  return pairKernel(h, FloatW(1.0f) / h);
}
// s_corr of the lanes' pairs, 0 for a cloth neighbour and in the lanes not in m
inline FloatW sCorrOf(const PairInputs& in, const PairKernel<FloatW>& k, FloatW r2, MaskW m, UintW j) {
  const UintW phase = simd::gather(in.phase, j, m, simd::splat(~0u));
  const MaskW water = m & (phase == simd::splat(static_cast<uint32_t>(kWaterPhase)));
  return simd::select(water, artificialPressure(k.h2, r2, in.sCorrK, in.oneMinusDq2, in.tensileN));
}
#endif

// lambda pass of water particle i over its neighbours [k0, k1): DensitySums. Plain: every neighbour
// has the mass and inverse mass in.plainM, in.plainW (markNeighbourhoods), taken as constants
template <bool U, bool Plain = false>
inline DensitySums<float> densitySums(const PairInputs& in, size_t i, uint32_t k0, uint32_t k1) {
  const float* X = in.X;
  const float xi = X[3 * i], yi = X[3 * i + 1], zi = X[3 * i + 2], hi = in.H[i];
#if SOAK_SIMD_WIDE
  if (k1 - k0 >= kSimdMinPairs) {
    const FloatW vx = xi, vy = yi, vz = zi;
    DensitySums<FloatW> s;
    for (uint32_t k = k0; k < k1; k += simd::kLanes) {
      const Pairs q = pairsAt(in, k, k1, vx, vy, vz);
      // 0 past the list's end, as gathered
      const FloatW mj = Plain ? simd::select(q.m, in.plainM) : simd::gather(in.M, q.j, q.m);
      const FloatW wj = Plain ? simd::select(q.m, in.plainW) : simd::gather(in.W, q.j, q.m);
      const FloatW g = addDensityPair(s, kernelOf<U>(in, q.m, q.j, hi), q.rx, q.ry, q.rz, q.r2, mj, wj, in.invRho0, q.m);
      if (in.cacheGx) {  // m_j sf r for the correction pass
        const uint32_t at = k - in.cacheBase;
        simd::store(in.cacheGx + at, q.m, g * q.rx);
        simd::store(in.cacheGy + at, q.m, g * q.ry);
        simd::store(in.cacheGz + at, q.m, g * q.rz);
        if (in.cacheR2) simd::store(in.cacheR2 + at, q.m, q.r2);
      }
    }
    return {simd::sum(s.rho), simd::sum(s.gx), simd::sum(s.gy), simd::sum(s.gz), simd::sum(s.others)};
  }
#endif
  DensitySums<float> s;
  for (uint32_t k = k0; k < k1; ++k) {
    const ScalarPair q = scalarPair<U>(in, k, xi, yi, zi, hi);
    const float g = addDensityPair(s, q.kernel, q.rx, q.ry, q.rz, q.r2, in.M[q.j], in.W[q.j], in.invRho0, true);
    if (in.cacheGx) {
      const uint32_t at = k - in.cacheBase;
      in.cacheGx[at] = g * q.rx, in.cacheGy[at] = g * q.ry, in.cacheGz[at] = g * q.rz;
      if (in.cacheR2) in.cacheR2[at] = q.r2;
    }
  }
  return s;
}

// the correction pass from the pair cache: sum_j (lambda_i + lambda_j + s_corr) (m_j sf_ij r_ij), the
// pairs' geometry as the lambda pass of this iteration left it (the positions have not moved since)
template <bool U, bool Tensile>
inline Vec3 cachedCorrectionSum(const PairInputs& in, size_t i, uint32_t k0, uint32_t k1) {
  const float hi = in.H[i], li = in.L[i];
#if SOAK_SIMD_WIDE
  if (k1 - k0 >= kSimdMinPairs) {
    const FloatW vli = li;
    FloatW sx = 0.0f, sy = 0.0f, sz = 0.0f;
    for (uint32_t k = k0; k < k1; k += simd::kLanes) {
      const MaskW m = simd::firstLanes(k1 - k);
      const uint32_t at = k - in.cacheBase;
      const UintW j = simd::load(in.index + k, m);
      const FloatW lj = simd::gather(in.L, j, m);
      const FloatW sc = Tensile ? sCorrOf(in, kernelOf<U>(in, m, j, hi), simd::load(in.cacheR2 + at, m), m, j) : 0.0f;
      const FloatW lambda = pairLambda(vli, lj, sc);
      sx += lambda * simd::load(in.cacheGx + at, m);
      sy += lambda * simd::load(in.cacheGy + at, m);
      sz += lambda * simd::load(in.cacheGz + at, m);
    }
    return Vec3(simd::sum(sx), simd::sum(sy), simd::sum(sz));
  }
#endif
  float dx = 0.0f, dy = 0.0f, dz = 0.0f;
  for (uint32_t k = k0; k < k1; ++k) {
    const uint32_t j = in.index[k], at = k - in.cacheBase;
    const float h = U ? in.hU : pairRadius(hi, in.H[j]);
    const float lambda = pairLambda(li, in.L[j], sCorrOf<Tensile>(in, j, Tensile ? in.cacheR2[at] : 0.0f, h));
    dx += lambda * in.cacheGx[at];
    dy += lambda * in.cacheGy[at];
    dz += lambda * in.cacheGz[at];
  }
  return Vec3(dx, dy, dz);
}

// correction pass of water particle i: sum_j m_j (lambda_i + lambda_j + s_corr) grad W_ij (PBF Eq. 12;
// a cloth neighbour has lambda 0 and no s_corr)
template <bool U, bool Tensile>
inline Vec3 correctionSum(const PairInputs& in, size_t i, uint32_t k0, uint32_t k1) {
  if (in.cacheGx) return cachedCorrectionSum<U, Tensile>(in, i, k0, k1);
  const float* X = in.X;
  const float xi = X[3 * i], yi = X[3 * i + 1], zi = X[3 * i + 2], hi = in.H[i], li = in.L[i];
#if SOAK_SIMD_WIDE
  if (k1 - k0 >= kSimdMinPairs) {
    const FloatW vx = xi, vy = yi, vz = zi, vli = li;
    FloatW sx = 0.0f, sy = 0.0f, sz = 0.0f;
    for (uint32_t k = k0; k < k1; k += simd::kLanes) {
      const Pairs q = pairsAt(in, k, k1, vx, vy, vz);
      const FloatW mj = simd::gather(in.M, q.j, q.m), lj = simd::gather(in.L, q.j, q.m);
      const PairKernel<FloatW> kernel = kernelOf<U>(in, q.m, q.j, hi);
      const FloatW sc = Tensile ? sCorrOf(in, kernel, q.r2, q.m, q.j) : 0.0f;
      const FloatW f = correctionFactor(mj, vli, lj, sc, spikyFactor(kernel, q.r2, q.m));
      sx += f * q.rx;
      sy += f * q.ry;
      sz += f * q.rz;
    }
    return Vec3(simd::sum(sx), simd::sum(sy), simd::sum(sz));
  }
#endif
  float dx = 0.0f, dy = 0.0f, dz = 0.0f;
  for (uint32_t k = k0; k < k1; ++k) {
    const ScalarPair q = scalarPair<U>(in, k, xi, yi, zi, hi);
    const float sc = sCorrOf<Tensile>(in, q.j, q.r2, q.kernel.h);
    const float f = correctionFactor(in.M[q.j], li, in.L[q.j], sc, spikyFactor(q.kernel, q.r2, true));
    dx += f * q.rx;
    dy += f * q.ry;
    dz += f * q.rz;
  }
  return Vec3(dx, dy, dz);
}

// cloth reaction of cloth particle b over its water neighbours [k0, k1): -sum_i m_i lambda_i grad W_ib
// over the water that pushes (lambda != 0); returns how many push
template <bool U>
inline int reactionSum(const PairInputs& in, size_t b, uint32_t k0, uint32_t k1, Vec3& sumOut) {
  const float* X = in.X;
  const float xb = X[3 * b], yb = X[3 * b + 1], zb = X[3 * b + 2], hb = in.H[b];
  int pushing = 0;
#if SOAK_SIMD_WIDE
  if (k1 - k0 >= kSimdMinPairs) {
    const FloatW vx = xb, vy = yb, vz = zb;
    FloatW sx = 0.0f, sy = 0.0f, sz = 0.0f;
    for (uint32_t k = k0; k < k1; k += simd::kLanes) {
      const MaskW m = simd::firstLanes(k1 - k);
      const UintW i = simd::load(in.index + k, m);
      const FloatW li = simd::gather(in.L, i, m);
      const UintW phase = simd::gather(in.phase, i, m, simd::splat(~0u));
      // only compressed water pushes
      const MaskW push = m & (phase == simd::splat(static_cast<uint32_t>(kWaterPhase))) & (li != 0.0f);
      if (!simd::any(push)) continue;
      FloatW xi, yi, zi;  // every lane's: those that do not push get mi = 0 and a masked kernel
      neighbourPositions(in, k, m, i, xi, yi, zi);
      const FloatW rx = xi - vx, ry = yi - vy, rz = zi - vz;
      const FloatW mi = simd::gather(in.mass, i, push);
      const FloatW r2 = rx * rx + ry * ry + rz * rz;
      const FloatW f = reactionFactor(mi, li, spikyFactor(kernelOf<U>(in, push, i, hb), r2, push));
      sx -= f * rx;
      sy -= f * ry;
      sz -= f * rz;
      pushing += simd::count(push);
    }
    sumOut = Vec3(simd::sum(sx), simd::sum(sy), simd::sum(sz));
    return pushing;
  }
#endif
  float dx = 0.0f, dy = 0.0f, dz = 0.0f;
  for (uint32_t k = k0; k < k1; ++k) {
    const uint32_t i = in.index[k];
    if (in.phase[i] != kWaterPhase || in.L[i] == 0.0f) continue;  // only compressed water pushes
    const float rx = X[3 * i] - xb, ry = X[3 * i + 1] - yb, rz = X[3 * i + 2] - zb;
    const float h = pairRadius(hb, in.H[i]);
    const PairKernel<float> kernel = U ? in.kU : pairKernel(h, 1.0f / h);
    const float f = reactionFactor(in.mass[i], in.L[i], spikyFactor(kernel, rx * rx + ry * ry + rz * rz, true));
    dx -= f * rx;
    dy -= f * ry;
    dz -= f * rz;
    ++pushing;
  }
  sumOut = Vec3(dx, dy, dz);
  return pushing;
}

}  // namespace soak::pbf
