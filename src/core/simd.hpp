// A small lane type for the vectorised neighbour loops, after Box2D v3's b2FloatW: FloatW holds
// kLanes floats, UintW kLanes 32-bit unsigned integers (particle indices, phases), MaskW says which
// lanes take part. A pair formula is written once, as a template on float or FloatW with the operators
// and free functions below: the vectorised loops, their scalar tails and the tests call the same
// function. Lane arithmetic is IEEE single precision, one lane at a time, in the order written (the
// build has -ffp-contract=off, so nothing is fused): a lane's result is the scalar call's bit for bit.
//
// With AVX-512 (SOAK_SIMD_WIDE is 1) FloatW is one 512-bit register of 16 lanes; without it only the
// scalar overloads exist and the loops take their scalar paths.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#if defined(__AVX512F__)
#include <immintrin.h>
#define SOAK_SIMD_WIDE 1
#else
#define SOAK_SIMD_WIDE 0
#endif

namespace soak::simd {

// --- scalar lanes: float values, bool masks ---
// max and min as the vector instructions define them: the second operand when equal or unordered
inline float max(float a, float b) { return a > b ? a : b; }
inline float min(float a, float b) { return a < b ? a : b; }
inline float sqrt(float a) { return std::sqrt(a); }
// x limited to [lo, hi] as std::min(std::max(x, lo), hi): a NaN x stays NaN
inline float clamp(float x, float lo, float hi) { return std::min(std::max(x, lo), hi); }
inline float select(bool m, float a) { return m ? a : 0.0f; }  // a where m, else 0
// a / b where m, else 0; b is replaced where not m, so the division can be done in every lane of an
// `omp simd` loop without a fault
inline float divideOrZero(bool m, float a, float b) {
  const float safe = m ? b : 1.0f;
  return m ? a / safe : 0.0f;
}

#if SOAK_SIMD_WIDE
constexpr uint32_t kLanes = 16;

struct MaskW {
  __mmask16 bits;
};
struct FloatW {
  __m512 v;
  FloatW() = default;
  FloatW(float x) : v(_mm512_set1_ps(x)) {}  // every lane x
  explicit FloatW(__m512 x) : v(x) {}
};
struct UintW {
  __m512i v;
};

constexpr __mmask16 kAll = 0xFFFF;

// the first min(count, kLanes) lanes
inline MaskW firstLanes(uint32_t count) {
  return {count >= kLanes ? kAll : __mmask16((1u << count) - 1u)};
}
inline MaskW operator&(MaskW a, MaskW b) { return {__mmask16(a.bits & b.bits)}; }
inline MaskW operator|(MaskW a, MaskW b) { return {__mmask16(a.bits | b.bits)}; }
inline MaskW& operator|=(MaskW& a, MaskW b) { return a = a | b; }
inline bool any(MaskW m) { return m.bits != 0; }
inline uint32_t bits(MaskW m) { return m.bits; }  // lane l is bit l
inline int count(MaskW m) { return __builtin_popcount(m.bits); }

inline FloatW operator+(FloatW a, FloatW b) { return FloatW(_mm512_add_ps(a.v, b.v)); }
inline FloatW operator-(FloatW a, FloatW b) { return FloatW(_mm512_sub_ps(a.v, b.v)); }
inline FloatW operator*(FloatW a, FloatW b) { return FloatW(_mm512_mul_ps(a.v, b.v)); }
inline FloatW operator/(FloatW a, FloatW b) { return FloatW(_mm512_div_ps(a.v, b.v)); }
inline FloatW& operator+=(FloatW& a, FloatW b) { return a = a + b; }
inline FloatW& operator-=(FloatW& a, FloatW b) { return a = a - b; }
// the maskz forms with every lane here: the plain ones draw a false -Wmaybe-uninitialized warning
inline FloatW max(FloatW a, FloatW b) { return FloatW(_mm512_maskz_max_ps(kAll, a.v, b.v)); }
inline FloatW min(FloatW a, FloatW b) { return FloatW(_mm512_maskz_min_ps(kAll, a.v, b.v)); }
inline FloatW clamp(FloatW x, FloatW lo, FloatW hi) {
  const __m512 up = _mm512_mask_blend_ps(_mm512_cmp_ps_mask(x.v, lo.v, _CMP_LT_OQ), x.v, lo.v);
  return FloatW(_mm512_mask_blend_ps(_mm512_cmp_ps_mask(hi.v, up, _CMP_LT_OQ), up, hi.v));
}
inline FloatW sqrt(FloatW a) { return FloatW(_mm512_maskz_sqrt_ps(kAll, a.v)); }
inline FloatW select(MaskW m, FloatW a) { return FloatW(_mm512_maskz_mov_ps(m.bits, a.v)); }
// a / b in the lanes of m (the others are not divided), 0 elsewhere
inline FloatW divideOrZero(MaskW m, FloatW a, FloatW b) { return FloatW(_mm512_maskz_div_ps(m.bits, a.v, b.v)); }

// ordered comparisons (false with a NaN); != is true with a NaN, as in C++
inline MaskW operator<(FloatW a, FloatW b) { return {_mm512_cmp_ps_mask(a.v, b.v, _CMP_LT_OQ)}; }
inline MaskW operator<=(FloatW a, FloatW b) { return {_mm512_cmp_ps_mask(a.v, b.v, _CMP_LE_OQ)}; }
inline MaskW operator>(FloatW a, FloatW b) { return {_mm512_cmp_ps_mask(a.v, b.v, _CMP_GT_OQ)}; }
inline MaskW operator!=(FloatW a, FloatW b) { return {_mm512_cmp_ps_mask(a.v, b.v, _CMP_NEQ_UQ)}; }

inline UintW splat(uint32_t x) { return {_mm512_set1_epi32(static_cast<int>(x))}; }
inline MaskW operator==(UintW a, UintW b) { return {_mm512_cmpeq_epi32_mask(a.v, b.v)}; }
inline MaskW operator!=(UintW a, UintW b) { return {_mm512_cmpneq_epi32_mask(a.v, b.v)}; }
inline MaskW operator<(UintW a, UintW b) { return {_mm512_cmplt_epu32_mask(a.v, b.v)}; }  // unsigned

// the lanes of m from p[0 .. kLanes), 0 in the others (which are not read)
inline FloatW load(const float* p, MaskW m) { return FloatW(_mm512_maskz_loadu_ps(m.bits, p)); }
inline UintW load(const uint32_t* p, MaskW m) { return {_mm512_maskz_loadu_epi32(m.bits, p)}; }
inline void store(float* p, MaskW m, FloatW a) { _mm512_mask_storeu_ps(p, m.bits, a.v); }
inline void store(uint32_t* p, UintW a) { _mm512_storeu_si512(p, a.v); }
// the lanes of m packed to the front, zeros after; stores all kLanes slots of p. Packed in a register
// and stored whole: a compressing store to memory is microcoded on some processors
inline void storeCompressed(uint32_t* p, MaskW m, UintW a) { _mm512_storeu_si512(p, _mm512_maskz_compress_epi32(m.bits, a.v)); }
inline UintW select(MaskW m, UintW a) { return {_mm512_maskz_mov_epi32(m.bits, a.v)}; }

// a[j] in the lanes of m, `otherwise` in the others (which read nothing)
inline FloatW gather(const float* a, UintW j, MaskW m, FloatW otherwise = 0.0f) {
  return FloatW(_mm512_mask_i32gather_ps(otherwise.v, m.bits, j.v, a, 4));
}
inline UintW gather(const int32_t* a, UintW j, MaskW m, UintW otherwise) {
  return {_mm512_mask_i32gather_epi32(otherwise.v, m.bits, j.v, a, 4)};
}

// x, y, z of the kLanes 3-float records X[3 idx[l] ..]: one 128-bit load a record (its fourth float
// masked off, so the last record reads nothing past the array) and a 4 x 4 transpose in each 128-bit
// quarter, cheaper than three gathers; the values are the same
inline void loadXyz(const float* X, const uint32_t* idx, FloatW& x, FloatW& y, FloatW& z) {
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
  const __m512 t0 = _mm512_maskz_unpacklo_ps(kAll, a, b), t1 = _mm512_maskz_unpackhi_ps(kAll, a, b);
  const __m512 t2 = _mm512_maskz_unpacklo_ps(kAll, c, d), t3 = _mm512_maskz_unpackhi_ps(kAll, c, d);
  x = FloatW(_mm512_maskz_shuffle_ps(kAll, t0, t2, 0x44));
  y = FloatW(_mm512_maskz_shuffle_ps(kAll, t0, t2, 0xEE));
  z = FloatW(_mm512_maskz_shuffle_ps(kAll, t1, t3, 0x44));
}

// the sum of the lanes as a fixed tree (halves, quarters, pairs): the same for every call
inline float sum(FloatW w) {
  __m512 a = w.v;
  a = _mm512_add_ps(a, _mm512_maskz_shuffle_f32x4(kAll, a, a, 0x4E));
  a = _mm512_add_ps(a, _mm512_maskz_shuffle_f32x4(kAll, a, a, 0xB1));
  a = _mm512_add_ps(a, _mm512_maskz_permute_ps(kAll, a, 0x4E));
  a = _mm512_add_ps(a, _mm512_maskz_permute_ps(kAll, a, 0xB1));
  return _mm512_cvtss_f32(a);
}
// lane l of a (for tests)
inline float lane(FloatW a, int l) {
  alignas(64) float v[kLanes];
  _mm512_store_ps(v, a.v);
  return v[l];
}
#endif

}  // namespace soak::simd
