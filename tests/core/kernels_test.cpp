#include "core/kernels.hpp"
#include "pbd/boundary.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

using namespace soak;

namespace {
// midpoint-rule integral of f over the cube [-h, h]^3
template <class F>
double integrate3(float h, int n, F&& f) {
  const double dx = 2.0 * h / n;
  double sum = 0.0;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const Vec3 r(float(-h + (i + 0.5) * dx), float(-h + (j + 0.5) * dx), float(-h + (k + 0.5) * dx));
        sum += f(r);
      }
  return sum * dx * dx * dx;
}
#if SOAK_SIMD_WIDE
// f(v[l]) in lane l
template <class F>
simd::FloatW FloatWOf(const float* v, simd::MaskW m, F&& f) {
  float out[16];
  for (int l = 0; l < 16; ++l) out[l] = f(v[l]);
  return simd::load(out, m);
}
#endif
}  // namespace

TEST(Kernels, Poly6AndSpikyIntegrateToOne) {
  for (float h : {0.04f, 0.1f, 1.0f}) {
    EXPECT_NEAR(integrate3(h, 120, [&](const Vec3& r) { return poly6(r.squaredNorm(), h); }), 1.0, 2e-3) << h;
    EXPECT_NEAR(integrate3(h, 120, [&](const Vec3& r) { return spiky(r.norm(), h); }), 1.0, 5e-3) << h;
  }
}

TEST(Kernels, ZeroOutsideSupport) {
  EXPECT_EQ(poly6(0.04f * 0.04f, 0.04f), 0.0f);
  EXPECT_EQ(spiky(0.05f, 0.04f), 0.0f);
  EXPECT_TRUE(spikyGrad(Vec3(0.05f, 0, 0), 0.04f).isZero());
  EXPECT_EQ(viscosityLaplacian(0.04f, 0.04f), 0.0f);
  EXPECT_GT(viscosityLaplacian(0.01f, 0.04f), 0.0f);
}

TEST(Kernels, SpikyGradientMatchesFiniteDifferences) {
  const float h = 0.04f;
  const Vec3 pts[] = {{0.01f, 0.002f, -0.005f}, {-0.02f, 0.01f, 0.015f}, {0.0f, 0.03f, 0.001f}};
  for (const Vec3& r : pts) {
    const Vec3 g = spikyGrad(r, h);
    for (int a = 0; a < 3; ++a) {
      const double e = 1e-4;
      Eigen::Vector3d rp = r.cast<double>(), rm = r.cast<double>();
      rp[a] += e;
      rm[a] -= e;
      auto w = [&](const Eigen::Vector3d& x) { const double d = h - x.norm(); return 15.0 / (M_PI * std::pow(h, 6)) * d * d * d; };
      const double fd = (w(rp) - w(rm)) / (2 * e);
      EXPECT_NEAR(g[a], fd, 1e-3 * std::abs(fd) + 1e-2) << a;
    }
  }
}

// one formula, several callers: the cached kernels, the factor form and (where the build has it) the
// vector lanes give the scalar kernels' values bit for bit
TEST(Kernels, EveryFormOfAKernelIsTheSameNumber) {
  const auto same = [](float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-0.05f, 0.05f), hr(0.02f, 0.06f);
  for (int k = 0; k < 200; ++k) {
    const Vec3 r(u(rng), u(rng), u(rng));
    const float h = hr(rng), r2 = r.squaredNorm();
    KernelCache cache;
    cache.set(h);
    EXPECT_TRUE(same(cache.poly6(r2), poly6(r2, h))) << k;
    const Vec3 g = spikyGrad(r, h), gc = cache.spikyGrad(r), gf = spikyGradFactor(r2, h) * r;
    for (int a = 0; a < 3; ++a) {
      EXPECT_TRUE(same(gc[a], g[a])) << k;
      if (r.norm() < h) EXPECT_TRUE(same(gf[a], g[a])) << k;
    }
    EXPECT_TRUE(same(viscosityLaplacian(r.norm(), h), r.norm() >= h ? 0.0f : viscosityLaplacianCoef(h * h * h) * (h - r.norm())));
  }
  EXPECT_EQ(spikyGradFactor(0.0f, 0.04f), 0.0f);  // no direction at r = 0
#if SOAK_SIMD_WIDE
  float hs[16], r2s[16];
  for (int l = 0; l < 16; ++l) hs[l] = hr(rng), r2s[l] = std::pow(u(rng) + 0.05f, 2.0f);
  const simd::MaskW all = simd::firstLanes(16);
  const simd::FloatW H = simd::load(hs, all), R2 = simd::load(r2s, all);
  const simd::FloatW p6 = poly6From(FloatWOf(hs, all, [](float h) { return poly6Coef(h, h * h); }), H * H, R2);
  const simd::FloatW sf = spikyGradFactorFrom(FloatWOf(hs, all, [](float h) { return spikyGradCoef(h * h * h); }), H, R2, all);
  for (int l = 0; l < 16; ++l) {
    EXPECT_TRUE(same(simd::lane(p6, l), poly6(r2s[l], hs[l]))) << l;
    EXPECT_TRUE(same(simd::lane(sf, l), spikyGradFactor(r2s[l], hs[l]))) << l;
  }
#endif
}

TEST(Kernels, WallFractionIsTheHalfSpaceIntegral) {
  const float h = 0.04f;
  float dphi = 0.0f;
  EXPECT_NEAR(wallKernelFraction(0.0f, h, &dphi), 0.5f, 1e-5f);
  EXPECT_NEAR(wallKernelFraction(h, h, nullptr), 0.0f, 1e-6f);
  EXPECT_NEAR(wallKernelFraction(-h, h, nullptr), 1.0f, 1e-6f);
  for (float d : {-0.03f, -0.01f, 0.005f, 0.02f, 0.035f}) {
    // direct midpoint integral of poly6 over the slab y in [d, h] (the half-space beyond the plane)
    const int n = 100;
    const double dxz = 2.0 * h / n, dy = (h - d) / n;
    double direct = 0.0;
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const Vec3 r(float(-h + (i + 0.5) * dxz), float(d + (j + 0.5) * dy), float(-h + (k + 0.5) * dxz));
          direct += poly6(r.squaredNorm(), h) * dxz * dxz * dy;
        }
    EXPECT_NEAR(wallKernelFraction(d, h, &dphi), direct, 3e-3) << d;
    const float e = 1e-4f;
    const float fd = (wallKernelFraction(d + e, h, nullptr) - wallKernelFraction(d - e, h, nullptr)) / (2 * e);
    EXPECT_NEAR(dphi, fd, 2e-2f * std::abs(fd) + 1e-2f) << d;
  }
}
