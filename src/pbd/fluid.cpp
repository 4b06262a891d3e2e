#include "pbd/fluid.hpp"

#include "pbd/boundary.hpp"

#include "core/kernels.hpp"
#include "core/parallel.hpp"

#include <algorithm>
#include <cmath>

namespace soak {

void computeBoundaryPsi(const Model& model, const Particles& p, const NeighborLists& nb, FluidScratch& s) {
  const int nc = model.numCloth;
  s.psi.resize(static_cast<size_t>(nc));
  const float rho0 = model.water.restDensity;
  parallelFor(nc, [&](int64_t b) {
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

// artificial pressure s_corr = -k (W_ij / W(dq))^n (Macklin 2013 Eq. 13), in lambda units. With
// dq = c h, W_ij / W(dq) = ((h^2 - r^2) / (h^2 (1 - c^2)))^3: one division, no h^9
float tensileCorrection(const WaterParams& w, float r2, float h, float scale) {
  if (w.tensileK <= 0.0f) return 0.0f;
  const float h2 = h * h;
  if (r2 >= h2) return 0.0f;
  const float q = (h2 - r2) / (h2 * (1.0f - w.tensileDq * w.tensileDq));
  const float ratio = q * q * q;
  float power = 1.0f;
  for (int k = 0; k < w.tensileN; ++k) power *= ratio;
  return -w.tensileK * power * scale;
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

}  // namespace

void solveFluid(const Model& model, const std::vector<ColliderPose>& poses, Particles& p, const NeighborLists& nb,
                FluidScratch& s, int iterations) {
  const WaterParams& wp = model.water;
  const size_t n = p.size();
  const int64_t nc = model.numCloth;
  const int64_t nw = static_cast<int64_t>(n) - nc;
  if (nw <= 0) return;
  const float rho0 = wp.restDensity, invRho0 = 1.0f / rho0;
  s.density.resize(n);
  s.lambda.resize(n);
  s.delta.resize(n);
  if (s.sCorrScale == 0.0f) s.sCorrScale = 1.0f / (wp.particleMass * restGradientNorm(wp));
  const float sCorrScale = s.sCorrScale;
  boundaryParts(model, poses, s.parts);

  for (int it = 0; it < iterations; ++it) {
    // lambda of each water particle from the density constraint C_i = rho_i / rho0 - 1 (Eq. 6-7)
    parallelFor(nw, [&](int64_t w) {
      const size_t i = static_cast<size_t>(nc + w);
      const Vec3 xi = p.xPred[i];
      const float hi = p.radius[i], mi = p.mass[i];
      float rho = mi * poly6(0.0f, hi);
      Vec3 gradI = Vec3::Zero();
      float sumOthers = 0.0f;  // sum over neighbours of w_k |grad_k C|^2
      KernelCache kernel;
      for (uint32_t k = nb.start[i]; k < nb.start[i + 1]; ++k) {
        const uint32_t j = nb.index[k];
        const Vec3 r = xi - p.xPred[j];
        kernel.set(pairRadius(hi, p.radius[j]));
        const float mj = isWater(p.phase[j]) ? p.mass[j] : s.psi[j];  // cloth: boundary mass Psi_b
        rho += mj * kernel.poly6(r.squaredNorm());
        const Vec3 g = (mj * invRho0) * kernel.spikyGrad(r);
        gradI += g;
        sumOthers += p.invMass[j] * g.squaredNorm();
      }
      // colliders as a continuous wall of boundary particles
      Vec3 gradWall;
      rho += rho0 * boundaryFraction(s.parts, xi, hi, &gradWall);
      gradI += gradWall;
      s.delta[i] = gradWall;  // kept for the corrections below (same positions): one wall query per iteration
      s.density[i] = rho;
      // inequality: only compressed water pushes, so a free surface does not clump (departure from
      // Macklin 2013, which also pulls; see docs/models.md)
      const float C = std::max(rho / rho0 - 1.0f, 0.0f);
      const float denom = p.invMass[i] * gradI.squaredNorm() + sumOthers + wp.relaxation * p.invMass[i] / (hi * hi);
      s.lambda[i] = -C / (mi * denom);
    });
    // water corrections: dx_i = 1/rho0 sum_j m_j (lambda_i + lambda_j + s_corr) grad W_ij (+ boundaries)
    parallelFor(nw, [&](int64_t w) {
      const size_t i = static_cast<size_t>(nc + w);
      const Vec3 xi = p.xPred[i];
      const float hi = p.radius[i], li = s.lambda[i];
      Vec3 dx = Vec3::Zero();
      KernelCache kernel;
      for (uint32_t k = nb.start[i]; k < nb.start[i + 1]; ++k) {
        const uint32_t j = nb.index[k];
        const Vec3 r = xi - p.xPred[j];
        const float h = pairRadius(hi, p.radius[j]);
        kernel.set(h);
        if (isWater(p.phase[j])) {
          const float sc = tensileCorrection(wp, r.squaredNorm(), h, sCorrScale);
          dx += p.mass[j] * (li + s.lambda[j] + sc) * kernel.spikyGrad(r);
        } else {
          dx += s.psi[j] * li * kernel.spikyGrad(r);
        }
      }
      dx += rho0 * li * s.delta[i];  // the wall gradient of the lambda pass (zero away from walls)
      s.delta[i] = dx / rho0;
    });
    // cloth reaction (two-way): dx_b = -(w_b Psi_b / rho0) sum_i m_i lambda_i grad W_ib
    parallelFor(nc, [&](int64_t b) {
      s.delta[b].setZero();
      if (p.invMass[b] == 0.0f) return;
      Vec3 dx = Vec3::Zero();
      int pushing = 0;
      KernelCache kernel;
      for (uint32_t k = nb.waterBegin(b, static_cast<uint32_t>(nc)); k < nb.start[b + 1]; ++k) {
        const uint32_t i = nb.index[k];
        if (!isWater(p.phase[i]) || s.lambda[i] == 0.0f) continue;
        const Vec3 r = p.xPred[i] - p.xPred[b];
        kernel.set(pairRadius(p.radius[i], p.radius[b]));
        dx -= p.mass[i] * s.lambda[i] * kernel.spikyGrad(r);
        ++pushing;
      }
      // averaged over the water particles pushing it (Jacobi averaging, Macklin et al. 2014 4.2):
      // the plain sum of ~30 corrections overshoots and makes the cloth a trampoline
      if (pushing) s.delta[b] = (p.invMass[b] * s.psi[b] / (rho0 * static_cast<float>(pushing))) * dx;
    });
    parallelFor(static_cast<int64_t>(n), [&](int64_t i) {
      if (i >= nc || p.invMass[i] != 0.0f) p.xPred[i] += s.delta[i];
    });
  }
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
  // omega_i = sum_j V_j v_ij x grad W_ij (Macklin 2013 Eq. 15), and XSPH (Eq. 17) weighted by V_ij
  parallelFor(nw, [&](int64_t w) {
    const size_t i = static_cast<size_t>(nc + w);
    const Vec3 vi = p.v[i];
    Vec3 omega = Vec3::Zero(), blend = Vec3::Zero();
    KernelCache kernel;
    for (uint32_t k = nb.waterBegin(i, static_cast<uint32_t>(nc)); k < nb.start[i + 1]; ++k) {
      const uint32_t j = nb.index[k];
      if (!isWater(p.phase[j])) continue;
      const Vec3 r = p.xPred[i] - p.xPred[j];
      kernel.set(pairRadius(p.radius[i], p.radius[j]));
      // m_j over the pair's mean density keeps sum m_i dv_i = 0 (momentum conserved)
      const float vol = 2.0f * p.mass[j] / std::max(s.density[i] + s.density[j], 1e-3f);
      const Vec3 vij = p.v[j] - vi;
      blend += vol * kernel.poly6(r.squaredNorm()) * vij;
      omega += vol * vij.cross(kernel.spikyGrad(r));
    }
    s.vorticity[i] = omega;
    vNew[i] = vi + wp.viscosity * blend;
  });
  if (wp.vorticity > 0.0f) {
    // f = epsilon (N x omega), N = eta / |eta|, eta = grad |omega| (Macklin 2013 Eq. 16)
    parallelFor(nw, [&](int64_t w) {
      const size_t i = static_cast<size_t>(nc + w);
      Vec3 eta = Vec3::Zero();
      KernelCache kernel;
      for (uint32_t k = nb.waterBegin(i, static_cast<uint32_t>(nc)); k < nb.start[i + 1]; ++k) {
        const uint32_t j = nb.index[k];
        if (!isWater(p.phase[j])) continue;
        const float vol = p.mass[j] / std::max(s.density[j], 1e-3f);
        kernel.set(pairRadius(p.radius[i], p.radius[j]));
        eta += vol * s.vorticity[j].norm() * kernel.spikyGrad(p.xPred[i] - p.xPred[j]);
      }
      const float len = eta.norm();
      if (len > 1e-9f) vNew[i] += dt * wp.vorticity * (eta / len).cross(s.vorticity[i]);
    });
  }
  parallelFor(nw, [&](int64_t w) { p.v[nc + w] = vNew[nc + w]; });
}

}  // namespace soak
