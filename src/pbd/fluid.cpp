#include "pbd/fluid.hpp"

#include "pbd/boundary.hpp"

#include "core/kernels.hpp"
#include "core/parallel.hpp"

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

#include <algorithm>
#include <cmath>
#include <limits>

namespace soak {

void computeBoundaryPsi(const Model& model, const Particles& p, const NeighborLists& nb, FluidScratch& s) {
  const int nc = model.numCloth;
  s.psi.resize(static_cast<size_t>(nc));
  const float rho0 = model.water.restDensity;
  parallelForDynamic(nc, kClothChunk, [&](int64_t b) {  // folds and bunches have more neighbours
    // Psi_b is read only through water neighbours (the density of water near b, and b's reaction):
    // a cloth particle with none gets 0 and costs nothing (most of a sheet, most of the time)
    bool wet = false;
    for (uint32_t k = nb.waterBegin(b, static_cast<uint32_t>(nc)); k < nb.start[b + 1] && !wet; ++k) wet = nb.index[k] >= static_cast<uint32_t>(nc);
    if (!wet) {
      s.psi[b] = 0.0f;
      return;
    }
    const float hb = p.radius[b];
    float sum = poly6(0.0f, hb);  // k includes b itself (NOTES.md on Eq. 10)
    KernelCache kernel;
    for (uint32_t k = nb.start[b], end = nb.clothEnd(b, static_cast<uint32_t>(nc)); k < end; ++k) {
      const uint32_t j = nb.index[k];
      if (p.phase[j] != p.phase[b]) continue;
      kernel.set(pairRadius(hb, p.radius[j]));
      sum += kernel.poly6((p.xPred[b] - p.xPred[j]).squaredNorm());
    }
    s.psi[b] = rho0 / sum;  // Psi_b = rho0 V_b, V_b = 1 / sum_k W_bk (Akinci et al. 2012)
  });
}

namespace {

inline float poly6Of(float h2, float poly6Coef, float r2) {
  const float d = std::max(h2 - r2, 0.0f);
  return poly6Coef * d * d * d;
}
// the factor f of grad W_spiky = f r (r = x_i - x_j), 0 outside the support and at r = 0
inline float spikyFactorOf(float h, float spikyCoef, float r2) {
  const float len = std::sqrt(r2);
  const float d = h - len;
  return (len < h && len > 1e-9f) ? spikyCoef * d * d / std::max(len, 1e-9f) : 0.0f;
}

// artificial pressure s_corr = -k (W_ij / W(dq))^n (Macklin 2013 Eq. 13), in lambda units. With
// dq = c h, W_ij / W(dq) = ((h^2 - r^2) / (h^2 (1 - c^2)))^3; the power by squaring (n < 64, the
// scene's range), without a branch
inline float tensileCorrection(float k, float oneMinusDq2, int n, float r2, float h2) {
  const float q = std::max(h2 - r2, 0.0f) / (h2 * oneMinusDq2);
  float base = q * q * q, power = 1.0f;
  for (int bit = 0; bit < 6; ++bit) {
    power *= ((n >> bit) & 1) ? base : 1.0f;
    base *= base;
  }
  return -k * power;
}

// sum_k w_k |grad_k C|^2 of a water particle at rest in a full cubic lattice (for the s_corr scale)
float restGradientNorm(const WaterParams& w) {
  const float r0 = w.spacing, h = w.supportRadius, m = w.particleMass, rho0 = w.restDensity;
  Vec3 gi = Vec3::Zero();
  float sum = 0.0f;
  const int n = static_cast<int>(std::ceil(h / r0));
  for (int z = -n; z <= n; ++z)
    for (int y = -n; y <= n; ++y)
      for (int x = -n; x <= n; ++x) {
        const Vec3 r = Vec3(float(x), float(y), float(z)) * r0;
        if ((x | y | z) == 0 || r.norm() >= h) continue;
        const Vec3 g = (m / rho0) * spikyGrad(r, h);
        gi += g;
        sum += g.squaredNorm() / m;
      }
  return sum + gi.squaredNorm() / m;
}

// calls f with two compile-time flags (std::true_type / std::false_type) for the run-time ones, so a
// neighbour loop has no test of them per pair
template <class F>
void withFlags(bool a, bool b, F&& f) {
  if (a && b) f(std::true_type{}, std::true_type{});
  if (a && !b) f(std::true_type{}, std::false_type{});
  if (!a && b) f(std::false_type{}, std::true_type{});
  if (!a && !b) f(std::false_type{}, std::false_type{});
}

// true when every particle has the same support radius h (no partial absorption yet): then a pair's
// h and 1 / h are loop constants, the same numbers as 0.5 (h_i + h_j) and its reciprocal
bool commonRadius(const std::vector<float>& radius, float& h) {
  const auto [lo, hi] = std::minmax_element(radius.begin(), radius.end());
  h = hi == radius.end() ? 1.0f : *hi;
  return lo == radius.end() || *lo == *hi;
}

// Two flags per particle, set by the particles that differ from a pool's and their neighbours (the
// lists are symmetric: r < (h_i + h_j) / 2), not by a pass over every pair:
// - mixed (null: every radius is h0): a pair of the particle's list has a radius other than h0 (partial
//   absorption shrinks water, Eq. 11). Only these need the per-pair radius; the others take the
//   constant h0 (the same values: (h0 + h0) / 2 = h0).
// - plain (null: not wanted): a water particle of water.particleMass m0 and radius h0 whose neighbours
//   all are ("plain": most of a pool). Its density pass takes m_j = m0 and w_j = 1 / m0 as constants
//   instead of gathering them, the same numbers. A cloth neighbour
//   (Psi_b, its own w), a drip or a partly absorbed particle makes its neighbours not plain.
void markNeighbourhoods(const Particles& p, const NeighborLists& nb, int64_t nc, float m0, float h0,
                        std::vector<uint8_t>* mixed, std::vector<uint8_t>* plain) {
  const int64_t n = static_cast<int64_t>(p.size());
  const float w0 = m0 > 0.0f ? 1.0f / m0 : 0.0f;  // as Particles::add
  const auto odd = [&](int64_t i) { return p.radius[i] != h0; };
  const auto own = [&](int64_t i) {
    return i >= nc && p.mass[i] == m0 && p.invMass[i] == w0 && !odd(i) && p.phase[i] == kWaterPhase;
  };
  if (mixed) mixed->resize(static_cast<size_t>(n));
  if (plain) plain->resize(static_cast<size_t>(n));
  uint8_t* const mx = mixed ? mixed->data() : nullptr;
  uint8_t* const pl = plain ? plain->data() : nullptr;
  parallelFor(n, [&](int64_t i) {
    if (mx) mx[i] = odd(i);
    if (pl) pl[i] = own(i);
  });
  // relaxed stores: two particles may mark a common neighbour
  parallelFor(n, [&](int64_t i) {
    const bool marksMixed = mx && odd(i);
    if (!marksMixed && (!pl || own(i))) return;
    // another radius marks every neighbour mixed; a particle not plain unmarks its water neighbours
    // (cloth ones are not plain anyway): the cloth and the few drips, not every pair of the pool
    const uint32_t k0 = marksMixed ? nb.start[i] : nb.waterBegin(static_cast<size_t>(i), static_cast<uint32_t>(nc));
    for (uint32_t k = k0; k < nb.start[i + 1]; ++k) {
      const uint32_t j = nb.index[k];
      if (marksMixed) __atomic_store_n(mx + j, uint8_t{1}, __ATOMIC_RELAXED);
      if (pl && j >= static_cast<uint32_t>(nc)) __atomic_store_n(pl + j, uint8_t{0}, __ATOMIC_RELAXED);
    }
  });
}

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
  float hU, invU;          // the common radius and its reciprocal (uniform case)
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

#if defined(__AVX512F__)
// With AVX-512, the pair sums below take 16 neighbours at a time: j's data are gathered (positions
// loaded and transposed), every lane does the scalar loop's arithmetic for its pair (same operations,
// same order, no FMA), and the sums are kept per lane and added across lanes at the end. Lanes past
// the list's end have mass 0 and masked kernels: they add 0. Lists shorter than kSimdMinPairs (spray)
// take the scalar loop, which is then faster. The order of the sums depends on the list's length,
// never on the thread count; results differ from a build without AVX-512 in the last bits. Written by
// hand: the compiler's own vectorisation of these loops loads the gathered values one by one.
constexpr uint32_t kSimdMinPairs = 4;
namespace v16 {
inline __m512 set(float x) { return _mm512_set1_ps(x); }
inline __m512 add(__m512 a, __m512 b) { return _mm512_add_ps(a, b); }
inline __m512 sub(__m512 a, __m512 b) { return _mm512_sub_ps(a, b); }
inline __m512 mul(__m512 a, __m512 b) { return _mm512_mul_ps(a, b); }
inline __mmask16 lanes(uint32_t k, uint32_t end) {
  return end - k >= 16 ? __mmask16(0xFFFF) : __mmask16((1u << (end - k)) - 1u);
}
// the lanes' pairs of particle i: j = index[k .. min(k + 16, end)) (mask m) and r = x_i - x_j,
// r2 = |r|^2 as the scalar loop rounds it; past end, j = 0 and r of whatever neighbourPositions read
struct Pairs {
  __mmask16 m;
  __m512i j;
  __m512 rx, ry, rz, r2;
};
// x, y, z of the 16 particles idx[0 .. 16) from 3-float records: one 128-bit load a particle (its
// fourth float masked off, so the last record reads nothing past the array) and a 4 x 4 transpose in
// each 128-bit quarter, cheaper than three gathers; the values are the same
inline void positionsOf(const float* X, const uint32_t* idx, __m512& x, __m512& y, __m512& z) {
  const auto at = [&](int l) { return _mm_maskz_loadu_ps(__mmask8(0x7), X + 3 * static_cast<size_t>(idx[l])); };
  __m512 a = _mm512_castps128_ps512(at(0)), b = _mm512_castps128_ps512(at(1));
  __m512 c = _mm512_castps128_ps512(at(2)), d = _mm512_castps128_ps512(at(3));
  a = _mm512_insertf32x4(a, at(4), 1), b = _mm512_insertf32x4(b, at(5), 1);
  c = _mm512_insertf32x4(c, at(6), 1), d = _mm512_insertf32x4(d, at(7), 1);
  a = _mm512_insertf32x4(a, at(8), 2), b = _mm512_insertf32x4(b, at(9), 2);
  c = _mm512_insertf32x4(c, at(10), 2), d = _mm512_insertf32x4(d, at(11), 2);
  a = _mm512_insertf32x4(a, at(12), 3), b = _mm512_insertf32x4(b, at(13), 3);
  c = _mm512_insertf32x4(c, at(14), 3), d = _mm512_insertf32x4(d, at(15), 3);
  // per quarter: t0 = x0 x1 y0 y1, t1 = z0 z1 0 0, t2 = x2 x3 y2 y3, t3 = z2 z3 0 0
  // (the maskz forms with every lane: see sum below)
  constexpr __mmask16 all = 0xFFFF;
  const __m512 t0 = _mm512_maskz_unpacklo_ps(all, a, b), t1 = _mm512_maskz_unpackhi_ps(all, a, b);
  const __m512 t2 = _mm512_maskz_unpacklo_ps(all, c, d), t3 = _mm512_maskz_unpackhi_ps(all, c, d);
  x = _mm512_maskz_shuffle_ps(all, t0, t2, 0x44);
  y = _mm512_maskz_shuffle_ps(all, t0, t2, 0xEE);
  z = _mm512_maskz_shuffle_ps(all, t1, t3, 0x44);
}
// positionsOf the lanes' neighbours index[k ..), lanes m: past the list's end the lanes read the next
// lists' neighbours (valid particles, masked by the callers); at the end of the index array they read
// particle 0. (Not a copy of the lanes: its scalar loads would wait for the vector store)
inline void neighbourPositions(const PairInputs& in, uint32_t k, __mmask16 m, __m512i j, __m512& x, __m512& y, __m512& z) {
  if (k + 16 <= in.indexSize) return positionsOf(in.X, in.index + k, x, y, z);
  alignas(64) uint32_t copy[16];
  _mm512_store_si512(copy, _mm512_maskz_mov_epi32(m, j));
  positionsOf(in.X, copy, x, y, z);
}
inline Pairs pairsAt(const PairInputs& in, uint32_t k, uint32_t end, __m512 xi, __m512 yi, __m512 zi) {
  Pairs q;
  q.m = lanes(k, end);
  q.j = _mm512_maskz_loadu_epi32(q.m, in.index + k);
  __m512 xj, yj, zj;
  neighbourPositions(in, k, q.m, q.j, xj, yj, zj);
  q.rx = sub(xi, xj);
  q.ry = sub(yi, yj);
  q.rz = sub(zi, zj);
  q.r2 = add(add(mul(q.rx, q.rx), mul(q.ry, q.ry)), mul(q.rz, q.rz));
  return q;
}
// a[j] of the lanes' neighbours (0 past the list's end)
inline __m512 gatherOf(const Pairs& q, const float* a) { return _mm512_mask_i32gather_ps(_mm512_setzero_ps(), q.m, q.j, a, 4); }
// the kernel constants of the lanes' pairs: h, h^2, the poly6 and spiky coefficients (poly6CoefOf,
// spikyCoefOf); loop constants when every radius is equal
struct Kernel {
  __m512 h, h2, poly6, spiky;
};
template <bool U>
inline Kernel kernelOf(const PairInputs& in, __mmask16 m, __m512i j, float hi) {
  if (U) return {set(in.hU), set(in.hU * in.hU), set(poly6CoefOfInverse(in.invU)), set(spikyGradCoefOfInverse(in.invU))};
  const __m512 hj = _mm512_mask_i32gather_ps(set(hi), m, j, in.H, 4);
  const __m512 h = mul(set(0.5f), add(set(hi), hj));
  const __m512 inv = _mm512_div_ps(set(1.0f), h);
  const __m512 inv3 = mul(mul(inv, inv), inv), inv6 = mul(inv3, inv3);
  return {h, mul(h, h), mul(mul(set(kPoly6Norm), inv6), inv3), mul(set(kSpikyGradNorm), inv6)};
}
// spikyFactorOf per lane, 0 outside the support, at r = 0 and in masked lanes
inline __m512 spikyFactor(const Kernel& k, __m512 r2, __mmask16 m) {
  const __m512 len = _mm512_maskz_sqrt_ps(__mmask16(0xFFFF), r2), d = sub(k.h, len);
  const __mmask16 in = _mm512_mask_cmp_ps_mask(m, len, k.h, _CMP_LT_OQ) & _mm512_cmp_ps_mask(len, set(1e-9f), _CMP_GT_OQ);
  return _mm512_maskz_div_ps(in, mul(mul(k.spiky, d), d), len);
}
// the artificial pressure s_corr = sCorrK tensileCorrection(1, ...) of the lanes' pairs, 0 for a cloth
// neighbour and in masked lanes
inline __m512 sCorr(const PairInputs& in, const Kernel& kern, __m512 r2, __mmask16 m, __m512i j) {
  const __m512 zero = _mm512_setzero_ps();
  const __m512i ph = _mm512_mask_i32gather_epi32(_mm512_set1_epi32(-1), m, j, in.phase, 4);
  const __mmask16 water = _mm512_mask_cmpeq_epi32_mask(m, ph, _mm512_set1_epi32(kWaterPhase));
  const __m512 ratio = _mm512_div_ps(_mm512_maskz_max_ps(__mmask16(0xFFFF), sub(kern.h2, r2), zero),
                                     mul(kern.h2, set(in.oneMinusDq2)));
  __m512 base = mul(mul(ratio, ratio), ratio), power = set(1.0f);
  for (int bit = 0; bit < 6; ++bit) {
    if ((in.tensileN >> bit) & 1) power = mul(power, base);
    base = mul(base, base);
  }
  return _mm512_maskz_mul_ps(water, set(in.sCorrK), mul(set(-1.0f), power));
}
// the lanes' sum as a fixed tree (halves, quarters, pairs). The maskz forms here and in spikyFactor
// (all lanes): the plain ones draw a false -Wmaybe-uninitialized warning
inline float sum(__m512 a) {
  constexpr __mmask16 all = 0xFFFF;
  a = add(a, _mm512_maskz_shuffle_f32x4(all, a, a, 0x4E));
  a = add(a, _mm512_maskz_shuffle_f32x4(all, a, a, 0xB1));
  a = add(a, _mm512_maskz_permute_ps(all, a, 0x4E));
  a = add(a, _mm512_maskz_permute_ps(all, a, 0xB1));
  return _mm512_cvtss_f32(a);
}
}  // namespace v16
#endif

// entry k of a list in the scalar tails of the pair loops: the neighbour j, x_i - x_j, its square
// and the pair's support radius and inverse
struct ScalarPair {
  uint32_t j;
  float rx, ry, rz, r2, kh, kinv;
};
template <bool U>
inline ScalarPair scalarPair(const PairInputs& in, uint32_t k, float xi, float yi, float zi, float hi) {
  const uint32_t j = in.index[k];
  const float* X = in.X;
  const float rx = xi - X[3 * j], ry = yi - X[3 * j + 1], rz = zi - X[3 * j + 2];
  const float kh = U ? in.hU : 0.5f * (hi + in.H[j]);
  return {j, rx, ry, rz, rx * rx + ry * ry + rz * rz, kh, U ? in.invU : 1.0f / kh};
}

// lambda pass of water particle i over its neighbours [k0, k1): rho_i without itself, grad_i C_i
// without the walls (times rho0) and sum_j w_j |grad_j C_i|^2
template <bool U, bool Plain = false>
inline void densitySums(const PairInputs& in, size_t i, uint32_t k0, uint32_t k1, float& rho, Vec3& grad,
                        float& sumOthers) {
  const float* X = in.X;
  const float xi = X[3 * i], yi = X[3 * i + 1], zi = X[3 * i + 2], hi = in.H[i];
  float r = 0.0f, gx = 0.0f, gy = 0.0f, gz = 0.0f, so = 0.0f;
  uint32_t k = k0;
#if defined(__AVX512F__)
  if (k1 - k0 >= kSimdMinPairs) {
    using namespace v16;
    const __m512 vx = set(xi), vy = set(yi), vz = set(zi), zero = _mm512_setzero_ps();
    __m512 sRho = zero, sGx = zero, sGy = zero, sGz = zero, sOthers = zero;
    for (; k < k1; k += 16) {
      const Pairs q = pairsAt(in, k, k1, vx, vy, vz);
      const __mmask16 m = q.m;
      const __m512i j = q.j;
      const __m512 rx = q.rx, ry = q.ry, rz = q.rz, r2 = q.r2;
      // plain (markNeighbourhoods): every neighbour's m_j and w_j are the constants, 0 past the list's end as gathered
      const __m512 mj = Plain ? _mm512_maskz_mov_ps(m, set(in.plainM)) : gatherOf(q, in.M);
      const __m512 wj = Plain ? _mm512_maskz_mov_ps(m, set(in.plainW)) : gatherOf(q, in.W);
      const Kernel kern = kernelOf<U>(in, m, j, hi);
      const __m512 d = _mm512_maskz_max_ps(__mmask16(0xFFFF), sub(kern.h2, r2), zero);
      sRho = add(sRho, mul(mj, mul(mul(mul(kern.poly6, d), d), d)));
      const __m512 sf = spikyFactor(kern, r2, m), f = mul(mul(mj, set(in.invRho0)), sf);
      if (in.cacheGx) {  // m_j sf r for the correction pass
        const __m512 g = mul(mj, sf);
        const uint32_t at = k - in.cacheBase;
        _mm512_mask_storeu_ps(in.cacheGx + at, m, mul(g, rx));
        _mm512_mask_storeu_ps(in.cacheGy + at, m, mul(g, ry));
        _mm512_mask_storeu_ps(in.cacheGz + at, m, mul(g, rz));
        if (in.cacheR2) _mm512_mask_storeu_ps(in.cacheR2 + at, m, r2);
      }
      sGx = add(sGx, mul(f, rx));
      sGy = add(sGy, mul(f, ry));
      sGz = add(sGz, mul(f, rz));
      sOthers = add(sOthers, mul(mul(mul(wj, f), f), r2));
    }
    r = sum(sRho);
    gx = sum(sGx), gy = sum(sGy), gz = sum(sGz);
    so = sum(sOthers);
    k = k1;
  }
#endif
  for (; k < k1; ++k) {
    const auto [j, rx, ry, rz, r2, kh, kinv] = scalarPair<U>(in, k, xi, yi, zi, hi);
    const float mj = in.M[j];
    r += mj * poly6Of(kh * kh, poly6CoefOfInverse(kinv), r2);
    const float sf = spikyFactorOf(kh, spikyGradCoefOfInverse(kinv), r2), f = mj * in.invRho0 * sf;
    if (in.cacheGx) {
      const float g = mj * sf;
      const uint32_t at = k - in.cacheBase;
      in.cacheGx[at] = g * rx, in.cacheGy[at] = g * ry, in.cacheGz[at] = g * rz;
      if (in.cacheR2) in.cacheR2[at] = r2;
    }
    gx += f * rx;
    gy += f * ry;
    gz += f * rz;
    so += in.W[j] * f * f * r2;
  }
  rho = r;
  grad = Vec3(gx, gy, gz);
  sumOthers = so;
}

// the correction pass from the pair cache: sum_j (lambda_i + lambda_j + s_corr) (m_j sf_ij r_ij), the
// pairs' geometry as the lambda pass of this iteration left it (the positions have not moved since)
template <bool U, bool Tensile>
inline Vec3 cachedCorrectionSum(const PairInputs& in, size_t i, uint32_t k0, uint32_t k1) {
  const float hi = in.H[i], li = in.L[i];
  float dx = 0.0f, dy = 0.0f, dz = 0.0f;
  uint32_t k = k0;
#if defined(__AVX512F__)
  if (k1 - k0 >= kSimdMinPairs) {
    using namespace v16;
    const __m512 vli = set(li), zero = _mm512_setzero_ps();
    __m512 sx = zero, sy = zero, sz = zero;
    for (; k < k1; k += 16) {
      const __mmask16 m = lanes(k, k1);
      const uint32_t at = k - in.cacheBase;
      const __m512i j = _mm512_maskz_loadu_epi32(m, in.index + k);
      const __m512 lj = _mm512_mask_i32gather_ps(zero, m, j, in.L, 4);
      __m512 sc = zero;
      if (Tensile) sc = sCorr(in, kernelOf<U>(in, m, j, hi), _mm512_maskz_loadu_ps(m, in.cacheR2 + at), m, j);
      const __m512 lam = add(add(vli, lj), sc);
      sx = add(sx, mul(lam, _mm512_maskz_loadu_ps(m, in.cacheGx + at)));
      sy = add(sy, mul(lam, _mm512_maskz_loadu_ps(m, in.cacheGy + at)));
      sz = add(sz, mul(lam, _mm512_maskz_loadu_ps(m, in.cacheGz + at)));
    }
    dx = sum(sx), dy = sum(sy), dz = sum(sz);
    k = k1;
  }
#endif
  for (; k < k1; ++k) {
    const uint32_t j = in.index[k], at = k - in.cacheBase;
    const float kh = U ? in.hU : 0.5f * (hi + in.H[j]);
    const float sc = Tensile && in.phase[j] == kWaterPhase
                         ? in.sCorrK * tensileCorrection(1.0f, in.oneMinusDq2, in.tensileN, in.cacheR2[at], kh * kh)
                         : 0.0f;
    const float lam = li + in.L[j] + sc;
    dx += lam * in.cacheGx[at];
    dy += lam * in.cacheGy[at];
    dz += lam * in.cacheGz[at];
  }
  return Vec3(dx, dy, dz);
}

// correction pass of water particle i: sum_j m_j (lambda_i + lambda_j + s_corr) grad W_ij (a cloth
// neighbour has lambda 0 and no s_corr)
template <bool U, bool Tensile>
inline Vec3 correctionSum(const PairInputs& in, size_t i, uint32_t k0, uint32_t k1) {
  if (in.cacheGx) return cachedCorrectionSum<U, Tensile>(in, i, k0, k1);
  const float* X = in.X;
  const float xi = X[3 * i], yi = X[3 * i + 1], zi = X[3 * i + 2], hi = in.H[i], li = in.L[i];
  float dx = 0.0f, dy = 0.0f, dz = 0.0f;
  uint32_t k = k0;
#if defined(__AVX512F__)
  if (k1 - k0 >= kSimdMinPairs) {
    using namespace v16;
    const __m512 vx = set(xi), vy = set(yi), vz = set(zi), vli = set(li), zero = _mm512_setzero_ps();
    __m512 sx = zero, sy = zero, sz = zero;
    for (; k < k1; k += 16) {
      const Pairs q = pairsAt(in, k, k1, vx, vy, vz);
      const __mmask16 m = q.m;
      const __m512i j = q.j;
      const __m512 rx = q.rx, ry = q.ry, rz = q.rz, r2 = q.r2;
      const __m512 mj = gatherOf(q, in.M), lj = gatherOf(q, in.L);
      const Kernel kern = kernelOf<U>(in, m, j, hi);
      __m512 sc = zero;
      if (Tensile) sc = sCorr(in, kern, r2, m, j);
      const __m512 f = mul(mul(mj, add(add(vli, lj), sc)), spikyFactor(kern, r2, m));
      sx = add(sx, mul(f, rx));
      sy = add(sy, mul(f, ry));
      sz = add(sz, mul(f, rz));
    }
    dx = sum(sx), dy = sum(sy), dz = sum(sz);
    k = k1;
  }
#endif
  for (; k < k1; ++k) {
    const auto [j, rx, ry, rz, r2, kh, kinv] = scalarPair<U>(in, k, xi, yi, zi, hi);
    const float sc = Tensile && in.phase[j] == kWaterPhase
                         ? in.sCorrK * tensileCorrection(1.0f, in.oneMinusDq2, in.tensileN, r2, kh * kh)
                         : 0.0f;
    const float f = in.M[j] * (li + in.L[j] + sc) * spikyFactorOf(kh, spikyGradCoefOfInverse(kinv), r2);
    dx += f * rx;
    dy += f * ry;
    dz += f * rz;
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
  float dx = 0.0f, dy = 0.0f, dz = 0.0f;
  uint32_t k = k0;
#if defined(__AVX512F__)
  if (k1 - k0 >= kSimdMinPairs) {
    using namespace v16;
    const __m512 vx = set(xb), vy = set(yb), vz = set(zb), zero = _mm512_setzero_ps();
    __m512 sx = zero, sy = zero, sz = zero;
    for (; k < k1; k += 16) {
      const __mmask16 m = lanes(k, k1);
      const __m512i i = _mm512_maskz_loadu_epi32(m, in.index + k);
      const __m512 li = _mm512_mask_i32gather_ps(zero, m, i, in.L, 4);
      const __m512i ph = _mm512_mask_i32gather_epi32(_mm512_set1_epi32(-1), m, i, in.phase, 4);
      // only compressed water pushes
      const __mmask16 push = _mm512_mask_cmpeq_epi32_mask(m, ph, _mm512_set1_epi32(kWaterPhase)) &
                             _mm512_cmp_ps_mask(li, zero, _CMP_NEQ_UQ);
      if (!push) continue;
      __m512 xi, yi, zi;  // every lane's: those that do not push get mi = 0 and a masked kernel
      neighbourPositions(in, k, m, i, xi, yi, zi);
      const __m512 rx = sub(xi, vx), ry = sub(yi, vy), rz = sub(zi, vz);
      const __m512 mi = _mm512_mask_i32gather_ps(zero, push, i, in.mass, 4);
      const Kernel kern = kernelOf<U>(in, push, i, hb);
      const __m512 r2 = add(add(mul(rx, rx), mul(ry, ry)), mul(rz, rz));
      const __m512 f = mul(mul(mi, li), spikyFactor(kern, r2, push));
      sx = sub(sx, mul(f, rx));
      sy = sub(sy, mul(f, ry));
      sz = sub(sz, mul(f, rz));
      pushing += __builtin_popcount(push);
    }
    dx = sum(sx), dy = sum(sy), dz = sum(sz);
    k = k1;
  }
#endif
  for (; k < k1; ++k) {
    const uint32_t i = in.index[k];
    if (in.phase[i] != kWaterPhase || in.L[i] == 0.0f) continue;  // only compressed water pushes
    const float rx = X[3 * i] - xb, ry = X[3 * i + 1] - yb, rz = X[3 * i + 2] - zb;
    const float kh = U ? in.hU : 0.5f * (in.H[i] + hb), kinv = U ? in.invU : 1.0f / kh;
    const float f = in.mass[i] * in.L[i] * spikyFactorOf(kh, spikyGradCoefOfInverse(kinv), rx * rx + ry * ry + rz * rz);
    dx -= f * rx;
    dy -= f * ry;
    dz -= f * rz;
    ++pushing;
  }
  sumOut = Vec3(dx, dy, dz);
  return pushing;
}

}  // namespace

// water particles a chunk of the solver's dynamically scheduled passes (the water by the cloth, the
// smaller particles and the surface cost more a particle than the pool's: static halves are unequal)
constexpr int64_t kWaterPassChunk = 1024;

// The solver's neighbour loops are densitySums, correctionSum and reactionSum above (AVX-512 by hand
// where available); the velocity pass below is scalar (once a substep).
void solveFluid(const Model& model, const std::vector<ColliderPose>& poses, Particles& p, const NeighborLists& nb,
                FluidScratch& s, int iterations) {
  const WaterParams& wp = model.water;
  const size_t n = p.size();
  const int64_t nc = model.numCloth;
  const int64_t nw = static_cast<int64_t>(n) - nc;
  if (nw <= 0) return;
  const float rho0 = wp.restDensity, invRho0 = 1.0f / rho0;
  s.density.assign(n, 0.0f);  // cloth entries stay 0 (the velocity pass reads them as masked lanes)
  s.lambda.assign(n, 0.0f);  // cloth entries stay 0: a boundary particle has no constraint of its own
  s.delta.resize(n);
  s.massOrPsi.resize(n);
  if (s.sCorrScale == 0.0f) s.sCorrScale = 1.0f / (wp.particleMass * restGradientNorm(wp));
  const float sCorrK = wp.tensileK * s.sCorrScale, oneMinusDq2 = 1.0f - wp.tensileDq * wp.tensileDq;
  const int tensileN = wp.tensileN;
  boundaryParts(model, poses, s.parts);
  // each water particle's distance to the nearest collider part, once per substep; the iterations
  // query the parts again only once the particle may have come within h of one. Factor 2 on the
  // distance moved: a trilinear mesh distance can change faster than the point moves
  if (!s.parts.empty()) {
    s.wallClear.assign(static_cast<size_t>(nw), std::numeric_limits<float>::max());  // a lower bound is enough
    s.wallFrom.assign(p.xPred.begin() + nc, p.xPred.end());
    for (const BoundaryPart& part : s.parts)
      colliderDistanceBounds(part.shape, part.pose, p.xPred[static_cast<size_t>(nc)].data(), nw, s.wallClear.data());
  }
  // the mass a neighbour lends the density: its own for water, the boundary mass Psi_b for cloth
  parallelFor(static_cast<int64_t>(n), [&](int64_t j) { s.massOrPsi[j] = j < nc ? s.psi[j] : p.mass[j]; });
  const float* H = p.radius.data();
  const float* L = s.lambda.data();
  float hU = 0.0f;
  const bool uniform = commonRadius(p.radius, hU);
  // mixed radii: the particles whose pairs all have h0 still take the constant-radius loops
  if (!uniform) hU = wp.supportRadius;
  const WallKernel wallU(hU);  // the walls' kernel for the particles of radius hU
  markNeighbourhoods(p, nb, nc, wp.particleMass, hU, uniform ? nullptr : &s.mixedRadius, &s.plain);
  const uint8_t* const mixed = s.mixedRadius.data();
  const uint8_t* const plain = s.plain.data();
  PairInputs in{p.xPred[0].data(), H, s.massOrPsi.data(), p.invMass.data(), L, p.mass.data(), p.phase.data(),
                nb.index.data(), nb.index.size(), hU, 1.0f / hU, invRho0, sCorrK, oneMinusDq2, tensileN};
  in.plainM = wp.particleMass;
  in.plainW = wp.particleMass > 0.0f ? 1.0f / wp.particleMass : 0.0f;
  // the pair cache: 12 bytes a pair of the water's lists (16 with artificial pressure, whose s_corr
  // needs |r|^2), when that fits s.pairCacheLimit (not the 1M-particle block: its memory target). It
  // spares the correction pass four gathers, a square root and a division a pair
  const size_t waterPairs = nb.start[n] - nb.start[static_cast<size_t>(nc)];
  const bool tensile = sCorrK != 0.0f;  // s_corr is 0 without artificial pressure
  if (waterPairs * (tensile ? 4 : 3) * sizeof(float) <= s.pairCacheLimit) {
    for (std::vector<float>* v : {&s.pairGx, &s.pairGy, &s.pairGz}) v->resize(waterPairs);
    s.pairR2.resize(tensile ? waterPairs : 0);
    in.cacheGx = s.pairGx.data(), in.cacheGy = s.pairGy.data(), in.cacheGz = s.pairGz.data();
    in.cacheR2 = tensile ? s.pairR2.data() : nullptr;  // unread by the correction pass without s_corr
    in.cacheBase = nb.start[static_cast<size_t>(nc)];
  }
  const auto solve = [&](auto uniform, auto tensile) {
    constexpr bool U = decltype(uniform)::value, Tensile = decltype(tensile)::value;
    for (int it = 0; it < iterations; ++it) {
      // lambda of each water particle from the density constraint C_i = rho_i / rho0 - 1 (Eq. 6-7).
      // Chunks of kWaterPassChunk to whichever thread is free
      parallelForDynamic(nw, kWaterPassChunk, [&](int64_t w) {
        const size_t i = static_cast<size_t>(nc + w);
        const float hi = H[i], mi = p.mass[i];
        float rho = 0.0f, sumOthers = 0.0f;  // sumOthers: sum over neighbours of w_k |grad_k C|^2
        Vec3 gradI;
        if (plain[i])  // radius h0 too: the constant-radius loop
          densitySums<true, true>(in, i, nb.start[i], nb.start[i + 1], rho, gradI, sumOthers);
        else if (U || !mixed[i])
          densitySums<true>(in, i, nb.start[i], nb.start[i + 1], rho, gradI, sumOthers);
        else
          densitySums<false>(in, i, nb.start[i], nb.start[i + 1], rho, gradI, sumOthers);
        rho += mi * poly6(0.0f, hi);
        // colliders as a continuous wall of boundary particles, skipped while the particle cannot have
        // come within h of one (exact: a part beyond h adds nothing)
        Vec3 gradWall = -Vec3::Zero();
        if (!s.parts.empty() && s.wallClear[w] - 2.0f * (p.xPred[i] - s.wallFrom[w]).norm() < hi)
          rho += rho0 * boundaryFraction(s.parts, p.xPred[i], hi == hU ? wallU : WallKernel(hi), &gradWall);
        gradI += gradWall;
        s.delta[i] = gradWall;  // kept for the corrections below (same positions): one wall query per iteration
        s.density[i] = rho;
        // inequality: only compressed water pushes, so a free surface does not clump (departure from
        // Macklin 2013, which also pulls; see docs/models.md)
        const float C = std::max(rho / rho0 - 1.0f, 0.0f);
        const float denom = p.invMass[i] * gradI.squaredNorm() + sumOthers + wp.relaxation * p.invMass[i] / (hi * hi);
        s.lambda[i] = -C / (mi * denom);
      });
      // water corrections: dx_i = 1/rho0 sum_j m_j (lambda_i + lambda_j + s_corr) grad W_ij (+ boundaries);
      // a cloth neighbour has lambda 0 and no s_corr: Psi_b lambda_i grad W_ib
      parallelForDynamic(nw, kWaterPassChunk, [&](int64_t w) {
        const size_t i = static_cast<size_t>(nc + w);
        const Vec3 sumJ = U || !mixed[i] ? correctionSum<true, Tensile>(in, i, nb.start[i], nb.start[i + 1])
                                         : correctionSum<false, Tensile>(in, i, nb.start[i], nb.start[i + 1]);
        s.delta[i] = (sumJ + rho0 * L[i] * s.delta[i]) * invRho0;  // + the wall gradient of the lambda pass
      });
      // cloth reaction (two-way): dx_b = -(w_b Psi_b / rho0) sum_i m_i lambda_i grad W_ib
      parallelForDynamic(nc, kClothChunk, [&](int64_t b) {  // only the cloth under water has work
        s.delta[b].setZero();
        if (p.invMass[b] == 0.0f) return;
        Vec3 sumI;
        const uint32_t k0 = nb.waterBegin(b, static_cast<uint32_t>(nc)), k1 = nb.start[b + 1];
        const int pushing = U || !mixed[b] ? reactionSum<true>(in, static_cast<size_t>(b), k0, k1, sumI)
                                           : reactionSum<false>(in, static_cast<size_t>(b), k0, k1, sumI);
        // averaged over the water particles pushing it (Jacobi averaging, Macklin et al. 2014 4.2):
        // the plain sum of ~30 corrections overshoots and makes the cloth a trampoline
        if (pushing) s.delta[b] = (p.invMass[b] * s.psi[b] / (rho0 * static_cast<float>(pushing))) * sumI;
      });
      parallelFor(static_cast<int64_t>(n), [&](int64_t i) {
        if (i >= nc || p.invMass[i] != 0.0f) p.xPred[i] += s.delta[i];
      });
    }
  };
  withFlags(uniform, tensile, solve);
}

void fluidVelocityPass(const Model& model, Particles& p, const NeighborLists& nb, FluidScratch& s, float dt,
                       bool listsOfSolve) {
  const WaterParams& wp = model.water;
  const size_t n = p.size();
  const int64_t nc = model.numCloth;
  const int64_t nw = static_cast<int64_t>(n) - nc;
  if (nw <= 0 || (wp.viscosity <= 0.0f && wp.vorticity <= 0.0f)) return;
  std::vector<Vec3>& vNew = s.delta;  // the solver's corrections are spent: reuse their memory
  vNew.resize(n);
  s.vorticity.resize(n);
  const float* X = p.xPred[0].data();
  const float* V = p.v[0].data();
  const float* H = p.radius.data();
  const float* M = p.mass.data();
  const float* D = s.density.data();
  const int32_t* phase = p.phase.data();
  const uint32_t* index = nb.index.data();
  // omega_i = sum_j V_j v_ij x grad W_ij (Macklin 2013 Eq. 15), only for the confinement, and XSPH
  // (Eq. 17) weighted by V_ij. Compile-time flags: every radius equal (h and 1 / h are constants, as
  // in solveFluid), vorticity wanted
  float hU = 0.0f;
  const bool uniform = commonRadius(p.radius, hU);
  // as in solveFluid: only the particles with a pair of another radius take the per-pair radius
  // (the radii have not changed since solveFluid marked these lists: the wetting stages come after)
  if (!uniform) {
    hU = wp.supportRadius;
    if (!listsOfSolve) markNeighbourhoods(p, nb, nc, wp.particleMass, hU, &s.mixedRadius, nullptr);
  }
  const uint8_t* const mixed = s.mixedRadius.data();
  const float invU = 1.0f / hU;
  // one water particle's XSPH velocity (and vorticity)
  const auto xsphOf = [&](auto uniform, auto vortex, size_t i) {
    constexpr bool U = decltype(uniform)::value, Vort = decltype(vortex)::value;
    const float xi = X[3 * i], yi = X[3 * i + 1], zi = X[3 * i + 2], hi = H[i], di = D[i];
    const float vxi = V[3 * i], vyi = V[3 * i + 1], vzi = V[3 * i + 2];
    float bx = 0.0f, by = 0.0f, bz = 0.0f, ox = 0.0f, oy = 0.0f, oz = 0.0f;
    for (uint32_t k = nb.waterBegin(i, static_cast<uint32_t>(nc)); k < nb.start[i + 1]; ++k) {
      const uint32_t j = index[k];
      const float rx = xi - X[3 * j], ry = yi - X[3 * j + 1], rz = zi - X[3 * j + 2];
      const float r2 = rx * rx + ry * ry + rz * rz;
      const float kh = U ? hU : 0.5f * (hi + H[j]), kinv = U ? invU : 1.0f / kh;
      // m_j over the pair's mean density keeps sum m_i dv_i = 0 (momentum conserved)
      const float vol = phase[j] == kWaterPhase ? 2.0f * M[j] / std::max(di + D[j], 1e-3f) : 0.0f;
      const float vx = V[3 * j] - vxi, vy = V[3 * j + 1] - vyi, vz = V[3 * j + 2] - vzi;
      const float wgt = vol * poly6Of(kh * kh, poly6CoefOfInverse(kinv), r2);
      bx += wgt * vx;
      by += wgt * vy;
      bz += wgt * vz;
      if (Vort) {
        const float f = vol * spikyFactorOf(kh, spikyGradCoefOfInverse(kinv), r2);  // v_ij x (f r)
        ox += f * (vy * rz - vz * ry);
        oy += f * (vz * rx - vx * rz);
        oz += f * (vx * ry - vy * rx);
      }
    }
    if (Vort) s.vorticity[i] = Vec3(ox, oy, oz);
    vNew[i] = Vec3(vxi, vyi, vzi) + wp.viscosity * Vec3(bx, by, bz);
  };
  const auto xsph = [&](auto uniform, auto vortex) {
    parallelFor(nw, [&](int64_t w) {
      const size_t i = static_cast<size_t>(nc + w);
      if (decltype(uniform)::value || !mixed[i])
        xsphOf(std::true_type{}, vortex, i);
      else
        xsphOf(std::false_type{}, vortex, i);
    });
  };
  withFlags(uniform, wp.vorticity > 0.0f, xsph);
  if (wp.vorticity > 0.0f) {
    // f = epsilon (N x omega), N = eta / |eta|, eta = grad |omega| (Macklin 2013 Eq. 16)
    s.vorticityNorm.resize(n);
    parallelFor(static_cast<int64_t>(n), [&](int64_t j) { s.vorticityNorm[j] = j < nc ? 0.0f : s.vorticity[j].norm(); });
    const float* O = s.vorticityNorm.data();
    parallelFor(nw, [&](int64_t w) {
      const size_t i = static_cast<size_t>(nc + w);
      const float xi = X[3 * i], yi = X[3 * i + 1], zi = X[3 * i + 2], hi = H[i];
      float ex = 0.0f, ey = 0.0f, ez = 0.0f;

      for (uint32_t k = nb.waterBegin(i, static_cast<uint32_t>(nc)); k < nb.start[i + 1]; ++k) {
        const uint32_t j = index[k];
        const float rx = xi - X[3 * j], ry = yi - X[3 * j + 1], rz = zi - X[3 * j + 2];
        const float kh = 0.5f * (hi + H[j]), kinv = 1.0f / kh;
        const float vol = phase[j] == kWaterPhase ? M[j] / std::max(D[j], 1e-3f) : 0.0f;
        const float f = vol * O[j] * spikyFactorOf(kh, spikyGradCoefOfInverse(kinv), rx * rx + ry * ry + rz * rz);
        ex += f * rx;
        ey += f * ry;
        ez += f * rz;
      }
      const Vec3 eta(ex, ey, ez);
      const float len = eta.norm();
      if (len > 1e-9f) vNew[i] += dt * wp.vorticity * (eta / len).cross(s.vorticity[i]);
    });
  }
  parallelFor(nw, [&](int64_t w) { p.v[nc + w] = vNew[nc + w]; });
}

}  // namespace soak
