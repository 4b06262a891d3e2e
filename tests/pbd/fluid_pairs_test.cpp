// The PBF pair formulas (pbd/fluid_pairs.hpp) against the kernels of core/kernels.hpp and the closed
// forms of Macklin & Müller 2013, and their vector lanes against the scalar call, bit for bit.
#include "pbd/fluid_pairs.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

using namespace soak;
using pbf::PairKernel;

namespace {
PairKernel<float> kernelOf(float h) { return pbf::pairKernel(h, 1.0f / h); }
bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }
}  // namespace

TEST(FluidPairs, Poly6AndSpikyFactorAreTheKernels) {
  for (float h : {0.01f, 0.04f, 0.1f}) {
    const PairKernel<float> k = kernelOf(h);
    EXPECT_EQ(k.h, h);
    EXPECT_EQ(k.h2, h * h);
    for (float q : {0.0f, 0.1f, 0.37f, 0.5f, 0.81f, 0.999f}) {
      const Vec3 r = Vec3(0.3f, -0.5f, 0.8124f).normalized() * (q * h);
      const float r2 = r.squaredNorm();
      EXPECT_NEAR(pbf::poly6Value(k, r2), poly6(r2, h), 2e-6f * poly6(0.0f, h)) << h << " " << q;
      const Vec3 g = pbf::spikyFactor(k, r2, true) * r, ref = spikyGrad(r, h);
      EXPECT_NEAR((g - ref).norm(), 0.0f, 2e-6f * spikyGrad(Vec3(0.01f * h, 0, 0), h).norm()) << h << " " << q;
    }
    // outside the support, at r = 0 (no direction) and when not active: 0
    EXPECT_EQ(pbf::poly6Value(k, 1.0001f * h * h), 0.0f);
    EXPECT_EQ(pbf::spikyFactor(k, 1.0001f * h * h, true), 0.0f);
    EXPECT_EQ(pbf::spikyFactor(k, 0.0f, true), 0.0f);
    EXPECT_EQ(pbf::spikyFactor(k, 0.25f * h * h, false), 0.0f);
    EXPECT_LT(pbf::spikyFactor(k, 0.25f * h * h, true), 0.0f);  // grad W points from i to j: repulsion is -grad
  }
}

// s_corr = -k (W(r) / W(dq h))^n: -k at r = dq h, the closed form between, 0 beyond h
TEST(FluidPairs, ArtificialPressureIsTheClosedForm) {
  const float h = 0.04f, k = 0.1f, dq = 0.2f;
  for (int n : {1, 2, 4, 7}) {
    const float r = dq * h;
    EXPECT_NEAR(pbf::artificialPressure(h * h, r * r, k, 1.0f - dq * dq, n), -k, 1e-6f) << n;
    for (float q : {0.0f, 0.5f, 0.9f}) {
      const float rq = q * h;
      const double ratio = poly6(rq * rq, h) / double(poly6(r * r, h));
      EXPECT_NEAR(pbf::artificialPressure(h * h, rq * rq, k, 1.0f - dq * dq, n), -k * std::pow(ratio, n),
                  2e-6 * k * std::pow(ratio, n))
          << n << " " << q;
    }
    EXPECT_EQ(pbf::artificialPressure(h * h, 1.01f * h * h, k, 1.0f - dq * dq, n), 0.0f);
  }
}

// one pair's terms of the lambda (Eqs. 2, 8, 9) summed over a lattice neighbourhood equal the kernels'
// sums: rho = sum m W, grad C = sum (m / rho0) grad W, sum_j w |grad_j C|^2 = sum w |(m / rho0) grad W|^2
TEST(FluidPairs, DensityPairTermsSumToTheDensityAndItsGradient) {
  const float h = 0.04f, spacing = 0.018f, m = 0.006f, w = 1.0f / m, rho0 = 1000.0f;
  const Vec3 xi(0.003f, -0.002f, 0.001f);  // off the lattice: the gradient is not 0
  pbf::DensitySums<float> s;
  double rho = 0.0, others = 0.0;
  Vec3d grad = Vec3d::Zero();
  float gLast = 0.0f;
  Vec3 rLast = Vec3::Zero();
  for (int z = -3; z <= 3; ++z)
    for (int y = -3; y <= 3; ++y)
      for (int x = -3; x <= 3; ++x) {
        const Vec3 r = xi - Vec3(float(x), float(y), float(z)) * spacing;
        const float g = pbf::addDensityPair(s, kernelOf(h), r.x(), r.y(), r.z(), r.squaredNorm(), m, w, 1.0f / rho0, true);
        rho += m * poly6(r.squaredNorm(), h);
        const Vec3d gj = (m / rho0) * spikyGrad(r, h).cast<double>();
        grad += gj;
        others += w * gj.squaredNorm();
        if (g != 0.0f) gLast = g, rLast = r;
      }
  EXPECT_GT(rho, 0.5 * rho0);
  EXPECT_NEAR(s.rho, rho, 1e-5 * rho);
  EXPECT_GT(grad.norm(), 0.0);
  EXPECT_NEAR((Vec3d(s.gx, s.gy, s.gz) - grad).norm(), 0.0, 1e-5 * grad.norm());
  EXPECT_NEAR(s.others, others, 1e-5 * others);
  // the returned factor is m_j f_ij: m_j grad W_ij = g r_ij
  EXPECT_NEAR((gLast * rLast - m * spikyGrad(rLast, h)).norm(), 0.0f, 1e-5f * (m * spikyGrad(rLast, h)).norm());
}

// Eq. 12's correction of i by j and of j by i are opposite (equal masses): the pair conserves momentum
TEST(FluidPairs, CorrectionsOfAPairAreOpposite) {
  const PairKernel<float> k = kernelOf(0.04f);
  const Vec3 rij(0.011f, -0.004f, 0.02f);
  const float r2 = rij.squaredNorm(), m = 0.006f, li = -2e-6f, lj = -5e-6f, sc = -1e-7f;
  const Vec3 di = pbf::correctionFactor(m, li, lj, sc, pbf::spikyFactor(k, r2, true)) * rij;
  const Vec3 dj = pbf::correctionFactor(m, lj, li, sc, pbf::spikyFactor(k, r2, true)) * (-rij);
  EXPECT_GT(di.norm(), 0.0f);
  EXPECT_TRUE((di + dj).isZero(0.0f));
  // compressed water (lambda < 0) pushes the pair apart: dx_i along r_ij
  EXPECT_GT(di.dot(rij), 0.0f);
  // the reaction on a boundary particle b from water i is -m_i lambda_i grad W_ib: away from i
  const Vec3 rib = rij;  // x_i - x_b
  const Vec3 db = -pbf::reactionFactor(m, li, pbf::spikyFactor(k, r2, true)) * rib;
  EXPECT_LT(db.dot(rib), 0.0f);
}

#if SOAK_SIMD_WIDE
// a lane of the vector call is the scalar call on that lane's pair, bit for bit; lanes outside the
// mask add nothing
TEST(FluidPairs, VectorLanesAreTheScalarFormulasBitForBit) {
  using simd::FloatW;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-0.03f, 0.03f), hr(0.03f, 0.05f);
  float rx[16], ry[16], rz[16], r2[16], h[16], mj[16], wj[16];
  for (int l = 0; l < 16; ++l) {
    rx[l] = u(rng), ry[l] = u(rng), rz[l] = u(rng), h[l] = hr(rng), mj[l] = 0.004f + 0.001f * float(l % 4);
    wj[l] = 1.0f / mj[l];
    r2[l] = rx[l] * rx[l] + ry[l] * ry[l] + rz[l] * rz[l];
  }
  r2[5] = 0.0f, rx[5] = ry[5] = rz[5] = 0.0f;  // r = 0: no direction
  const auto W = [](const float* v) { return simd::load(v, simd::firstLanes(16)); };
  const simd::MaskW m = simd::firstLanes(13);  // lanes 13 .. 15 past a list's end
  const FloatW H = W(h);
  const PairKernel<FloatW> kw = pbf::pairKernel(H, FloatW(1.0f) / H);
  pbf::DensitySums<FloatW> sw;
  const FloatW mw = simd::select(m, W(mj));  // the loops gather 0 past the end
  const FloatW gw = pbf::addDensityPair(sw, kw, W(rx), W(ry), W(rz), W(r2), mw, W(wj), 1e-3f, m);
  const FloatW sc = pbf::artificialPressure(kw.h2, W(r2), 0.1f, 0.96f, 4);
  for (int l = 0; l < 16; ++l) {
    SCOPED_TRACE(l);
    const bool in = l < 13;
    pbf::DensitySums<float> s;
    const PairKernel<float> k = pbf::pairKernel(h[l], 1.0f / h[l]);
    const float g = pbf::addDensityPair(s, k, rx[l], ry[l], rz[l], r2[l], in ? mj[l] : 0.0f, wj[l], 1e-3f, in);
    EXPECT_TRUE(sameBits(simd::lane(gw, l), g));
    EXPECT_TRUE(sameBits(simd::lane(sw.rho, l), s.rho));
    EXPECT_TRUE(sameBits(simd::lane(sw.gx, l), s.gx));
    EXPECT_TRUE(sameBits(simd::lane(sw.others, l), s.others));
    EXPECT_TRUE(sameBits(simd::lane(sc, l), pbf::artificialPressure(k.h2, r2[l], 0.1f, 0.96f, 4)));
    if (!in) EXPECT_EQ(simd::lane(sw.rho, l), 0.0f);
  }
}
#endif
