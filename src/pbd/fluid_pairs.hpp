// The pair formulas of Position Based Fluids (Macklin & Müller 2013, "PBF" below) with the kernels of
// Müller et al. 2003, each written once as a template on the lane type: float, or simd::FloatW (16
// pairs at a time) where the build has it. The solver's vectorised loops, their scalar tails, the
// velocity pass and tests/pbd/fluid_pairs_test.cpp call these same functions. `active` is true for a
// scalar pair and the lanes that hold a pair for a vector (its other lanes get 0).
#pragma once
#include "core/kernels.hpp"
#include "core/simd.hpp"

namespace soak::pbf {

// a pair's kernel constants: h_ij, h_ij^2, the poly6 and the spiky-gradient factors, from h_ij and 1 / h_ij
template <class F>
struct PairKernel {
  F h, h2, poly6, spiky;
};
template <class F>
inline PairKernel<F> pairKernel(F h, F inv) {
  return {h, h * h, poly6CoefOfInverse(inv), spikyGradCoefOfInverse(inv)};
}

// W_poly6(r_ij, h_ij) from r^2, 0 outside the support
template <class F>
inline F poly6Value(const PairKernel<F>& k, F r2) {
  return poly6From(k.poly6, k.h2, r2);
}

// the factor f of grad W_spiky(r_ij, h_ij) = f r_ij (r_ij = x_i - x_j); 0 outside the support, at
// r = 0 and where not active
template <class F, class M>
inline F spikyFactor(const PairKernel<F>& k, F r2, M active) {
  return spikyGradFactorFrom(k.spiky, k.h, r2, active);
}

// artificial pressure s_corr = -k (W_ij / W(dq))^n (PBF Eq. 13), in lambda units. With dq = c h,
// W_ij / W(dq) = ((h^2 - r^2) / (h^2 (1 - c^2)))^3; the power by squaring (0 <= n < 64)
template <class F>
inline F artificialPressure(F h2, F r2, float k, float oneMinusDq2, int n) {
  const F q = simd::max(h2 - r2, F(0.0f)) / (h2 * F(oneMinusDq2));
  F base = q * q * q, power = 1.0f;
  for (int bit = 0; bit < 6; ++bit) {
    if ((n >> bit) & 1) power = power * base;
    base = base * base;
  }
  return F(k) * (F(-1.0f) * power);
}

// what the neighbours of water particle i add to its lambda (PBF Eqs. 2, 8, 9): rho_i without itself,
// grad_i C_i without the walls and sum_j w_j |grad_j C_i|^2
template <class F>
struct DensitySums {
  F rho = 0.0f, gx = 0.0f, gy = 0.0f, gz = 0.0f, others = 0.0f;
};
// neighbour j's part of them: rho_i += m_j W_ij, grad_i C_i += (m_j / rho0) grad W_ij and
// w_j |grad_j C_i|^2 = w_j |(m_j / rho0) grad W_ij|^2. Returns m_j f_ij (grad W_ij = f_ij r_ij),
// which the correction pass of the same iteration reuses
template <class F, class M>
inline F addDensityPair(DensitySums<F>& s, const PairKernel<F>& k, F rx, F ry, F rz, F r2, F mj, F wj,
                        float invRho0, M active) {
  s.rho += mj * poly6Value(k, r2);
  const F sf = spikyFactor(k, r2, active), f = mj * F(invRho0) * sf;
  s.gx += f * rx;
  s.gy += f * ry;
  s.gz += f * rz;
  s.others += wj * f * f * r2;
  return mj * sf;
}

// lambda_i + lambda_j + s_corr, the pair's weight in the position correction (PBF Eq. 12)
template <class F>
inline F pairLambda(F li, F lj, F sCorr) {
  return li + lj + sCorr;
}
// the factor of r_ij in dx_i (PBF Eq. 12): m_j (lambda_i + lambda_j + s_corr) f_ij
template <class F>
inline F correctionFactor(F mj, F li, F lj, F sCorr, F sf) {
  return mj * pairLambda(li, lj, sCorr) * sf;
}
// the factor of r_ib in the reaction on cloth particle b of water particle i: m_i lambda_i f_ib
template <class F>
inline F reactionFactor(F mi, F li, F sf) {
  return mi * li * sf;
}

}  // namespace soak::pbf
