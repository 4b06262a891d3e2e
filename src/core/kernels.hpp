// SPH kernels of Müller et al. 2003, as used by PBF (Macklin & Müller 2013): poly6 for density,
// spiky gradient for pressure, viscosity Laplacian for diffusion. A pair of particles with different
// support radii uses the symmetric mean h_ij = (h_i + h_j) / 2, so W_ij = W_ji.
#pragma once
#include <soak/math.hpp>

namespace soak {

inline float pairRadius(float hi, float hj) { return 0.5f * (hi + hj); }

// W_poly6(r, h) = 315 / (64 pi h^9) (h^2 - r^2)^3 for r < h
inline float poly6(float r2, float h) {
  const float h2 = h * h;
  if (r2 >= h2) return 0.0f;
  const float d = h2 - r2;
  const float h9 = h2 * h2 * h2 * h2 * h;
  return 315.0f / (64.0f * kPi * h9) * d * d * d;
}

// grad W_spiky(r, h) = -45 / (pi h^6) (h - r)^2 r_hat, with r = x_i - x_j
inline Vec3 spikyGrad(const Vec3& r, float h) {
  const float len = r.norm();
  if (len >= h || len <= 1e-9f) return Vec3::Zero();
  const float h3 = h * h * h;
  const float d = h - len;
  return (-45.0f / (kPi * h3 * h3) * d * d / len) * r;
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
    poly6Coef = 315.0f / (64.0f * kPi * (h2 * h2 * h2 * h2 * h));
    spikyCoef = -45.0f / (kPi * h3 * h3);
  }
  float poly6(float r2) const {
    if (r2 >= h2) return 0.0f;
    const float d = h2 - r2;
    return poly6Coef * d * d * d;
  }
  Vec3 spikyGrad(const Vec3& r) const {
    const float len = r.norm();
    if (len >= h || len <= 1e-9f) return Vec3::Zero();
    const float d = h - len;
    return (spikyCoef * d * d / len) * r;
  }
};

// W_spiky(r, h) = 15 / (pi h^6) (h - r)^3, used where a kernel must be sharp (drip attraction)
inline float spiky(float r, float h) {
  if (r >= h) return 0.0f;
  const float h3 = h * h * h;
  const float d = h - r;
  return 15.0f / (kPi * h3 * h3) * d * d * d;
}

// Laplacian of the viscosity kernel: 45 / (pi h^6) (h - r), positive, for diffusion (Eq. 12)
inline float viscosityLaplacian(float r, float h) {
  if (r >= h) return 0.0f;
  const float h3 = h * h * h;
  return 45.0f / (kPi * h3 * h3) * (h - r);
}

}  // namespace soak
