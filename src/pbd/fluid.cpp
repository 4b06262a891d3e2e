#include "pbd/fluid.hpp"

#include "pbd/boundary.hpp"

#include "core/kernels.hpp"
#include "core/parallel.hpp"

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

// the kernel constants of one pair from its support radius h, with one division and no h^9 divisions
inline float poly6CoefOf(float inv) {
  const float inv3 = inv * inv * inv, inv6 = inv3 * inv3;
  return (315.0f / (64.0f * kPi)) * inv6 * inv3;
}
inline float spikyCoefOf(float inv) {
  const float inv3 = inv * inv * inv, inv6 = inv3 * inv3;
  return (-45.0f / kPi) * inv6;
}
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

}  // namespace

// The neighbour loops are scalar: vectorised (omp simd), GCC 12 emulates the gathers of j's data
// with scalar loads on Zen 4 and the PBF passes took 19.5 ms per step at 1 thread against 17.2
// scalar; real gather instructions (-mtune-ctrl=use_gather) were no faster (docs/performance.md).
// (Until session 6 they carried omp simd pragmas that GCC silently did not honour: the PairKernel
// struct in the loop body became a per-lane array.)
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
    s.wallClear.resize(static_cast<size_t>(nw));
    s.wallFrom.resize(static_cast<size_t>(nw));
    parallelFor(nw, [&](int64_t w) {
      const Vec3& x = p.xPred[static_cast<size_t>(nc + w)];
      float clear = std::numeric_limits<float>::max();
      Vec3 normal;
      for (const BoundaryPart& part : s.parts) clear = std::min(clear, colliderDistance(part.shape, part.pose, x, &normal));
      s.wallClear[w] = clear;
      s.wallFrom[w] = x;
    });
  }
  // the mass a neighbour lends the density: its own for water, the boundary mass Psi_b for cloth
  parallelFor(static_cast<int64_t>(n), [&](int64_t j) { s.massOrPsi[j] = j < nc ? s.psi[j] : p.mass[j]; });
  const float* X = p.xPred[0].data();
  const float* H = p.radius.data();
  const float* M = s.massOrPsi.data();
  const float* W = p.invMass.data();
  const float* L = s.lambda.data();
  const int32_t* phase = p.phase.data();
  const uint32_t* index = nb.index.data();

  float hU = 0.0f;
  const bool uniform = commonRadius(p.radius, hU);
  const float invU = 1.0f / hU;
  const auto solve = [&](auto uniform, auto tensile) {
    constexpr bool U = decltype(uniform)::value, Tensile = decltype(tensile)::value;
    for (int it = 0; it < iterations; ++it) {
      // lambda of each water particle from the density constraint C_i = rho_i / rho0 - 1 (Eq. 6-7)
      parallelFor(nw, [&](int64_t w) {
        const size_t i = static_cast<size_t>(nc + w);
        const float xi = X[3 * i], yi = X[3 * i + 1], zi = X[3 * i + 2];
        const float hi = H[i], mi = p.mass[i];
        float rho = 0.0f, gx = 0.0f, gy = 0.0f, gz = 0.0f;
        float sumOthers = 0.0f;  // sum over neighbours of w_k |grad_k C|^2

        for (uint32_t k = nb.start[i]; k < nb.start[i + 1]; ++k) {
          const uint32_t j = index[k];
          const float rx = xi - X[3 * j], ry = yi - X[3 * j + 1], rz = zi - X[3 * j + 2];
          const float r2 = rx * rx + ry * ry + rz * rz;
          const float kh = U ? hU : 0.5f * (hi + H[j]), kinv = U ? invU : 1.0f / kh;
          const float mj = M[j];
          rho += mj * poly6Of(kh * kh, poly6CoefOf(kinv), r2);
          const float f = mj * invRho0 * spikyFactorOf(kh, spikyCoefOf(kinv), r2);
          gx += f * rx;
          gy += f * ry;
          gz += f * rz;
          sumOthers += W[j] * f * f * r2;
        }
        rho += mi * poly6(0.0f, hi);
        Vec3 gradI(gx, gy, gz);
        // colliders as a continuous wall of boundary particles, skipped while the particle cannot have
        // come within h of one (exact: a part beyond h adds nothing)
        Vec3 gradWall = -Vec3::Zero();
        if (!s.parts.empty() && s.wallClear[w] - 2.0f * (p.xPred[i] - s.wallFrom[w]).norm() < hi)
          rho += rho0 * boundaryFraction(s.parts, p.xPred[i], hi, &gradWall);
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
      parallelFor(nw, [&](int64_t w) {
        const size_t i = static_cast<size_t>(nc + w);
        const float xi = X[3 * i], yi = X[3 * i + 1], zi = X[3 * i + 2];
        const float hi = H[i], li = L[i];
        float dx = 0.0f, dy = 0.0f, dz = 0.0f;

        for (uint32_t k = nb.start[i]; k < nb.start[i + 1]; ++k) {
          const uint32_t j = index[k];
          const float rx = xi - X[3 * j], ry = yi - X[3 * j + 1], rz = zi - X[3 * j + 2];
          const float r2 = rx * rx + ry * ry + rz * rz;
          const float kh = U ? hU : 0.5f * (hi + H[j]), kinv = U ? invU : 1.0f / kh;
          const float sc = Tensile && phase[j] == kWaterPhase ? sCorrK * tensileCorrection(1.0f, oneMinusDq2, tensileN, r2, kh * kh) : 0.0f;
          const float f = M[j] * (li + L[j] + sc) * spikyFactorOf(kh, spikyCoefOf(kinv), r2);
          dx += f * rx;
          dy += f * ry;
          dz += f * rz;
        }
        s.delta[i] = (Vec3(dx, dy, dz) + rho0 * li * s.delta[i]) * invRho0;  // + the wall gradient of the lambda pass
      });
      // cloth reaction (two-way): dx_b = -(w_b Psi_b / rho0) sum_i m_i lambda_i grad W_ib
      parallelForDynamic(nc, kClothChunk, [&](int64_t b) {  // only the cloth under water has work
        s.delta[b].setZero();
        if (p.invMass[b] == 0.0f) return;
        const float xb = X[3 * b], yb = X[3 * b + 1], zb = X[3 * b + 2], hb = H[b];
        float dx = 0.0f, dy = 0.0f, dz = 0.0f;
        int pushing = 0;

        for (uint32_t k = nb.waterBegin(b, static_cast<uint32_t>(nc)); k < nb.start[b + 1]; ++k) {
          const uint32_t i = index[k];
          if (phase[i] != kWaterPhase || L[i] == 0.0f) continue;  // only compressed water pushes
          const float rx = X[3 * i] - xb, ry = X[3 * i + 1] - yb, rz = X[3 * i + 2] - zb;
          const float kh = U ? hU : 0.5f * (H[i] + hb), kinv = U ? invU : 1.0f / kh;
          const float f = p.mass[i] * L[i] * spikyFactorOf(kh, spikyCoefOf(kinv), rx * rx + ry * ry + rz * rz);
          dx -= f * rx;
          dy -= f * ry;
          dz -= f * rz;
          ++pushing;
        }
        // averaged over the water particles pushing it (Jacobi averaging, Macklin et al. 2014 4.2):
        // the plain sum of ~30 corrections overshoots and makes the cloth a trampoline
        if (pushing) s.delta[b] = (p.invMass[b] * s.psi[b] / (rho0 * static_cast<float>(pushing))) * Vec3(dx, dy, dz);
      });
      parallelFor(static_cast<int64_t>(n), [&](int64_t i) {
        if (i >= nc || p.invMass[i] != 0.0f) p.xPred[i] += s.delta[i];
      });
    }
  };
  withFlags(uniform, sCorrK != 0.0f, solve);  // s_corr is 0 without artificial pressure
}

void fluidVelocityPass(const Model& model, Particles& p, const NeighborLists& nb, FluidScratch& s, float dt) {
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
  const float invU = 1.0f / hU;
  const auto xsph = [&](auto uniform, auto vortex) {
    constexpr bool U = decltype(uniform)::value, Vort = decltype(vortex)::value;
    parallelFor(nw, [&](int64_t w) {
      const size_t i = static_cast<size_t>(nc + w);
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
        const float wgt = vol * poly6Of(kh * kh, poly6CoefOf(kinv), r2);
        bx += wgt * vx;
        by += wgt * vy;
        bz += wgt * vz;
        if (Vort) {
          const float f = vol * spikyFactorOf(kh, spikyCoefOf(kinv), r2);  // v_ij x (f r)
          ox += f * (vy * rz - vz * ry);
          oy += f * (vz * rx - vx * rz);
          oz += f * (vx * ry - vy * rx);
        }
      }
      if (Vort) s.vorticity[i] = Vec3(ox, oy, oz);
      vNew[i] = Vec3(vxi, vyi, vzi) + wp.viscosity * Vec3(bx, by, bz);
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
        const float f = vol * O[j] * spikyFactorOf(kh, spikyCoefOf(kinv), rx * rx + ry * ry + rz * rz);
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
