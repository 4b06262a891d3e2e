// SPH kernels of Müller et al. 2003, as used by PBF (Macklin & Müller 2013): poly6 for density,
// spiky gradient for pressure, viscosity Laplacian for diffusion. A pair of particles with different
// support radii uses the symmetric mean h_ij = (h_i + h_j) / 2, so W_ij = W_ji.
#pragma once
#include <soak/math.hpp>

#include "core/simd.hpp"

#include <cmath>

namespace soak {

// (a template on the lane type: float or simd::FloatW, core/simd.hpp)
template <class F>
inline F pairRadius(F hi, F hj) {
  return 0.5f * (hi + hj);
}

// The kernels' normalisations, the only place their constants are written. The loops that vectorise
// (pbd/fluid.cpp, wetting/) call these small functions with the same arithmetic as the kernels below,
// so their results are the kernels' bit for bit.
constexpr float kPoly6Norm = 315.0f / (64.0f * kPi);  // W_poly6 h^9 / (h^2 - r^2)^3
constexpr float kSpikyGradNorm = -45.0f / kPi;        // |grad W_spiky| h^6 / (h - r)^2, negative
// 315 / (64 pi h^9), h2 = h^2
inline float poly6Coef(float h, float h2) { return 315.0f / (64.0f * kPi * (h2 * h2 * h2 * h2 * h)); }
// -45 / (pi h^6), h3 = h^3: the factor of (h - r)^2 r_hat in grad W_spiky
inline float spikyGradCoef(float h3) { return -45.0f / (kPi * h3 * h3); }
// 45 / (pi h^6), h3 = h^3: the factor of (h - r) in the viscosity kernel's Laplacian
inline float viscosityLaplacianCoef(float h3) { return 45.0f / (kPi * h3 * h3); }
// the same factors from 1 / h, with one division a pair instead of one per factor (templates on the
// lane type, for the vectorised loops)
template <class F>
inline F poly6CoefOfInverse(F inv) {
  const F inv3 = inv * inv * inv, inv6 = inv3 * inv3;
  return kPoly6Norm * inv6 * inv3;
}
template <class F>
inline F spikyGradCoefOfInverse(F inv) {
  const F inv3 = inv * inv * inv, inv6 = inv3 * inv3;
  return kSpikyGradNorm * inv6;
}

// The kernels' formulas, each written once, from a factor computed above (or cached, or per lane):
// templates on the lane type (float, or simd::FloatW where the build has it), with selects only, so
// that `omp simd` loops and the hand-vectorised ones (pbd/fluid_pairs.hpp) run the same arithmetic.
// W_poly6 = coef (h^2 - r^2)^3, 0 outside the support; coef = poly6Coef(h, h^2)
template <class F>
inline F poly6From(F coef, F h2, F r2) {
  const F d = simd::max(h2 - r2, F(0.0f));
  return coef * d * d * d;
}
// the factor f of grad W_spiky = f r (r = x_i - x_j, |r|^2 = r2): coef (h - |r|)^2 / |r|; 0 outside
// the support, at r = 0 and where not active. coef = spikyGradCoef(h^3)
template <class F, class M>
inline F spikyGradFactorFrom(F coef, F h, F r2, M active) {
  const F len = simd::sqrt(r2), d = h - len;
  return simd::divideOrZero(active & (len < h) & (len > F(1e-9f)), coef * d * d, len);
}

// W_poly6(r, h) = 315 / (64 pi h^9) (h^2 - r^2)^3 for r < h
inline float poly6(float r2, float h) {
  const float h2 = h * h;
  return poly6From(poly6Coef(h, h2), h2, r2);
}

// the factor f of grad W_spiky(r, h) = f r, from |r|^2
inline float spikyGradFactor(float r2, float h) { return spikyGradFactorFrom(spikyGradCoef(h * h * h), h, r2, true); }

// grad W_spiky(r, h) = -45 / (pi h^6) (h - r)^2 r_hat, with r = x_i - x_j
inline Vec3 spikyGrad(const Vec3& r, float h) {
  const float len = r.norm();
  if (len >= h || len <= 1e-9f) return Vec3::Zero();
  return spikyGradFactor(r.squaredNorm(), h) * r;
}

// poly6 and the spiky gradient for one support radius, with its constants computed once: loops over
// many pairs of equal radii (the common case) call set(h) per pair and pay the divisions only when h
// changes. Same arithmetic, same results as poly6() and spikyGrad().
struct KernelCache {
  float h = -1.0f, h2 = 0.0f, poly6Coef = 0.0f, spikyCoef = 0.0f;
  void set(float hNew) {
    if (hNew == h) return;
    h = hNew;
    h2 = h * h;
    const float h3 = h2 * h;
    poly6Coef = soak::poly6Coef(h, h2);
    spikyCoef = spikyGradCoef(h3);
  }
  float poly6(float r2) const { return poly6From(poly6Coef, h2, r2); }
  Vec3 spikyGrad(const Vec3& r) const {
    const float len = r.norm();
    if (len >= h || len <= 1e-9f) return Vec3::Zero();
    return spikyGradFactorFrom(spikyCoef, h, r.squaredNorm(), true) * r;
  }
};

// W_spiky(r, h) = 15 / (pi h^6) (h - r)^3, used where a kernel must be sharp (drip attraction)
inline float spiky(float r, float h) {
  if (r >= h) return 0.0f;
  const float h3 = h * h * h;
  const float d = h - r;
  return 15.0f / (kPi * h3 * h3) * d * d * d;
}

// Laplacian of the viscosity kernel: 45 / (pi h^6) (h - r), positive, for diffusion (Eq. 12); a
// select, for `omp simd` loops
inline float viscosityLaplacian(float r, float h) {
  return r >= h ? 0.0f : viscosityLaplacianCoef(h * h * h) * (h - r);
}

// a poly6 kernel of support h cut by a plane wall (pbd/boundary.cpp), with its factor
// K pi / 4 = 315 / (256 h^9) computed once: loops over particles of one radius build it once
struct WallKernel {
  float h;
  double quarterPiK;
  explicit WallKernel(float support) : h(support), quarterPiK(315.0 / (256.0 * std::pow(double(support), 9))) {}
};

// fraction of the poly6 kernel's mass beyond a plane at signed distance d (m):
// (K pi / 4) int_d^h (h^2 - z^2)^4 dz; dFraction receives its derivative wrt d
inline float wallKernelFraction(float d, const WallKernel& kernel, float* dFraction) {
  const float h = kernel.h;
  const float ad = std::fabs(d);
  if (ad >= h) {
    if (dFraction) *dFraction = 0.0f;
    return d > 0.0f ? 0.0f : 1.0f;
  }
  const double hh = h, z = ad, h2 = hh * hh;
  auto antiderivative = [&](double t) {
    const double t2 = t * t;
    return h2 * h2 * h2 * h2 * t - 4.0 / 3.0 * h2 * h2 * h2 * t2 * t + 6.0 / 5.0 * h2 * h2 * t2 * t2 * t -
           4.0 / 7.0 * h2 * t2 * t2 * t2 * t + t2 * t2 * t2 * t2 * t / 9.0;
  };
  const double k = kernel.quarterPiK;
  const double beyond = k * (antiderivative(hh) - antiderivative(z));
  const double q = h2 - z * z;
  if (dFraction) *dFraction = static_cast<float>(-k * q * q * q * q);  // the same on both sides
  return static_cast<float>(d >= 0.0f ? beyond : 1.0 - beyond);
}
inline float wallKernelFraction(float d, float h, float* dFraction) {
  return wallKernelFraction(d, WallKernel(h), dFraction);
}

}  // namespace soak
