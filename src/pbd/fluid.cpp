#include "pbd/fluid.hpp"

#include "pbd/boundary.hpp"
#include "pbd/fluid_sums.hpp"

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

// water particles a chunk of the solver's dynamically scheduled passes (the water by the cloth, the
// smaller particles and the surface cost more a particle than the pool's: static halves are unequal)
constexpr int64_t kWaterPassChunk = 1024;

// what the passes of one solve share
struct Solve {
  const Model& model;
  Particles& p;
  const NeighborLists& nb;
  FluidScratch& s;
  const pbf::PairInputs& in;
  const uint8_t* mixed;  // markNeighbourhoods' flags
  const uint8_t* plain;
  float hU;              // the common radius and the walls' kernel for it
  WallKernel wallU;
  int64_t nc, nw;
};

// sets the solver's scratch for this substep: densities and lambdas 0, the boundary masses of cloth
// neighbours, the collider parts and each water particle's distance to them
void prepareSolve(const Model& model, const std::vector<ColliderPose>& poses, const Particles& p, FluidScratch& s) {
  const size_t n = p.size();
  const int64_t nc = model.numCloth, nw = static_cast<int64_t>(n) - nc;
  s.density.assign(n, 0.0f);  // cloth entries stay 0 (the velocity pass reads them as masked lanes)
  s.lambda.assign(n, 0.0f);  // cloth entries stay 0: a boundary particle has no constraint of its own
  s.delta.resize(n);
  s.massOrPsi.resize(n);
  if (s.sCorrScale == 0.0f) s.sCorrScale = 1.0f / (model.water.particleMass * restGradientNorm(model.water));
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
}

// the pair cache: 12 bytes a pair of the water's lists (16 with artificial pressure, whose s_corr
// needs |r|^2), when that fits s.pairCacheLimit (not the 1M-particle block: its memory target). It
// spares the correction pass four gathers, a square root and a division a pair
void attachPairCache(const NeighborLists& nb, size_t nc, bool tensile, FluidScratch& s, pbf::PairInputs& in) {
  const size_t waterPairs = nb.start.back() - nb.start[nc];
  if (waterPairs * (tensile ? 4 : 3) * sizeof(float) > s.pairCacheLimit) return;
  for (std::vector<float>* v : {&s.pairGx, &s.pairGy, &s.pairGz}) v->resize(waterPairs);
  s.pairR2.resize(tensile ? waterPairs : 0);
  in.cacheGx = s.pairGx.data(), in.cacheGy = s.pairGy.data(), in.cacheGz = s.pairGz.data();
  in.cacheR2 = tensile ? s.pairR2.data() : nullptr;  // unread by the correction pass without s_corr
  in.cacheBase = nb.start[nc];
}

// lambda of each water particle from the density constraint C_i = rho_i / rho0 - 1 (Eq. 6-7); the
// wall gradient to s.delta for the correction pass. Chunks of kWaterPassChunk to whichever thread is free
template <bool U>
void lambdaPass(const Solve& c) {
  const WaterParams& wp = c.model.water;
  const float rho0 = wp.restDensity;
  Particles& p = c.p;
  FluidScratch& s = c.s;
  parallelForDynamic(c.nw, kWaterPassChunk, [&](int64_t w) {
    const size_t i = static_cast<size_t>(c.nc + w);
    const uint32_t k0 = c.nb.start[i], k1 = c.nb.start[i + 1];
    const float hi = p.radius[i], mi = p.mass[i];
    const pbf::DensitySums<float> sums = c.plain[i]           ? pbf::densitySums<true, true>(c.in, i, k0, k1)  // radius h0 too
                                         : U || !c.mixed[i] ? pbf::densitySums<true>(c.in, i, k0, k1)
                                                            : pbf::densitySums<false>(c.in, i, k0, k1);
    float rho = sums.rho + mi * poly6(0.0f, hi);
    // colliders as a continuous wall of boundary particles, skipped while the particle cannot have
    // come within h of one (exact: a part beyond h adds nothing)
    Vec3 gradWall = -Vec3::Zero();
    if (!s.parts.empty() && s.wallClear[w] - 2.0f * (p.xPred[i] - s.wallFrom[w]).norm() < hi)
      rho += rho0 * boundaryFraction(s.parts, p.xPred[i], hi == c.hU ? c.wallU : WallKernel(hi), &gradWall);
    const Vec3 gradI = Vec3(sums.gx, sums.gy, sums.gz) + gradWall;
    s.delta[i] = gradWall;  // kept for the corrections (same positions): one wall query per iteration
    s.density[i] = rho;
    // inequality: only compressed water pushes, so a free surface does not clump (departure from
    // Macklin 2013, which also pulls; see docs/models.md)
    const float C = std::max(rho / rho0 - 1.0f, 0.0f);
    const float denom = p.invMass[i] * gradI.squaredNorm() + sums.others + wp.relaxation * p.invMass[i] / (hi * hi);
    s.lambda[i] = -C / (mi * denom);
  });
}

// water corrections: dx_i = 1/rho0 sum_j m_j (lambda_i + lambda_j + s_corr) grad W_ij (+ boundaries);
// a cloth neighbour has lambda 0 and no s_corr: Psi_b lambda_i grad W_ib
template <bool U, bool Tensile>
void correctionPass(const Solve& c) {
  const float rho0 = c.model.water.restDensity, invRho0 = 1.0f / rho0;
  FluidScratch& s = c.s;
  parallelForDynamic(c.nw, kWaterPassChunk, [&](int64_t w) {
    const size_t i = static_cast<size_t>(c.nc + w);
    const uint32_t k0 = c.nb.start[i], k1 = c.nb.start[i + 1];
    const Vec3 sumJ = U || !c.mixed[i] ? pbf::correctionSum<true, Tensile>(c.in, i, k0, k1)
                                       : pbf::correctionSum<false, Tensile>(c.in, i, k0, k1);
    s.delta[i] = (sumJ + rho0 * s.lambda[i] * s.delta[i]) * invRho0;  // + the wall gradient of the lambda pass
  });
}

// cloth reaction (two-way): dx_b = -(w_b Psi_b / rho0) sum_i m_i lambda_i grad W_ib
template <bool U>
void reactionPass(const Solve& c) {
  const float rho0 = c.model.water.restDensity;
  const Particles& p = c.p;
  FluidScratch& s = c.s;
  parallelForDynamic(c.nc, kClothChunk, [&](int64_t b) {  // only the cloth under water has work
    s.delta[b].setZero();
    if (p.invMass[b] == 0.0f) return;
    Vec3 sumI;
    const uint32_t k0 = c.nb.waterBegin(b, static_cast<uint32_t>(c.nc)), k1 = c.nb.start[b + 1];
    const size_t bb = static_cast<size_t>(b);
    const int pushing = U || !c.mixed[b] ? pbf::reactionSum<true>(c.in, bb, k0, k1, sumI)
                                         : pbf::reactionSum<false>(c.in, bb, k0, k1, sumI);
    // averaged over the water particles pushing it (Jacobi averaging, Macklin et al. 2014 4.2):
    // the plain sum of ~30 corrections overshoots and makes the cloth a trampoline
    if (pushing) s.delta[b] = (p.invMass[b] * s.psi[b] / (rho0 * static_cast<float>(pushing))) * sumI;
  });
}

}  // namespace

// The solver's neighbour sums are in pbd/fluid_sums.hpp (vectorised where the build has the wide lane
// type); the velocity pass below is scalar (once a substep).
double meanCompression(const Model& model, const FluidScratch& s) {
  const size_t nc = static_cast<size_t>(model.numCloth), n = s.density.size();
  if (n <= nc) return 0.0;
  const float rho0 = model.water.restDensity;
  double sum = 0.0;
  for (size_t i = nc; i < n; ++i) sum += std::max(s.density[i] / rho0 - 1.0f, 0.0f);
  return sum / static_cast<double>(n - nc);
}

int solveFluid(const Model& model, const std::vector<ColliderPose>& poses, Particles& p, const NeighborLists& nb,
               FluidScratch& s, int iterations, int maxIterations, int last) {
  const WaterParams& wp = model.water;
  const size_t n = p.size();
  const int64_t nc = model.numCloth;
  const int64_t nw = static_cast<int64_t>(n) - nc;
  if (nw <= 0) return 0;
  prepareSolve(model, poses, p, s);
  const float sCorrK = wp.tensileK * s.sCorrScale;
  float hU = 0.0f;
  const bool uniform = commonRadius(p.radius, hU);
  // mixed radii: the particles whose pairs all have h0 still take the constant-radius loops
  if (!uniform) hU = wp.supportRadius;
  markNeighbourhoods(p, nb, nc, wp.particleMass, hU, uniform ? nullptr : &s.mixedRadius, &s.plain);
  pbf::PairInputs in{p.xPred[0].data(), p.radius.data(), s.massOrPsi.data(), p.invMass.data(), s.lambda.data(),
                     p.mass.data(), p.phase.data(), nb.index.data(), nb.index.size(), hU,
                     pbf::pairKernel(hU, 1.0f / hU), 1.0f / wp.restDensity, sCorrK,
                     1.0f - wp.tensileDq * wp.tensileDq, wp.tensileN};
  in.plainM = wp.particleMass;
  in.plainW = wp.particleMass > 0.0f ? 1.0f / wp.particleMass : 0.0f;
  const bool tensile = sCorrK != 0.0f;  // s_corr is 0 without artificial pressure
  attachPairCache(nb, static_cast<size_t>(nc), tensile, s, in);
  const Solve c{model, p, nb, s, in, s.mixedRadius.data(), s.plain.data(), hU, WallKernel(hU), nc, nw};
  // a Jacobi iteration's correction reaches about h further into the water: a deep pool needs more
  // of them to carry its weight than a splash (the lambda pass measures the densities first)
  const int most = std::max(iterations, maxIterations);
  const double tolerance = model.solver.fluidTolerance;
  int taken = 0;
  withFlags(uniform, tensile, [&](auto uniform, auto tensile) {
    constexpr bool U = decltype(uniform)::value, Tensile = decltype(tensile)::value;
    for (; taken < most; ++taken) {
      lambdaPass<U>(c);
      if (taken >= iterations && stopIterating(meanCompression(model, s), tolerance, taken, last)) break;
      correctionPass<U, Tensile>(c);
      reactionPass<U>(c);
      parallelFor(static_cast<int64_t>(n), [&](int64_t i) {
        if (i >= nc || p.invMass[i] != 0.0f) p.xPred[i] += s.delta[i];
      });
    }
  });
  return taken;
}
namespace {

// what the velocity pass reads
struct VelocityPass {
  const Particles& p;
  const NeighborLists& nb;
  FluidScratch& s;
  const uint8_t* mixed;  // markNeighbourhoods' flags
  pbf::PairKernel<float> kU;  // the kernel of the common radius
  float viscosity;
  int64_t nc;
  bool keepSum;  // the hyperviscosity follows: each particle's XSPH sum (L v) to s.velocitySum
};

// V_ij = m_j over the pair's mean density, the weight of the XSPH and hyperviscosity sums: m_i V_ij is
// symmetric, so sum_i m_i dv_i = 0 (momentum conserved); 0 for a cloth neighbour
inline float pairVolume(const VelocityPass& c, uint32_t j, float di) {
  return c.p.phase[j] == kWaterPhase ? 2.0f * c.p.mass[j] / std::max(di + c.s.density[j], 1e-3f) : 0.0f;
}

// calls f(j, rx, ry, rz, r2, kernel, V_ij) for each water neighbour j of water particle i, x_ij =
// (rx, ry, rz): the one neighbour walk of the XSPH and hyperviscosity sums (U: every radius equal,
// the kernel is c.kU). Cloth neighbours (V_ij = 0) are skipped.
template <bool U, class F>
inline void forWaterPairs(const VelocityPass& c, size_t i, F&& f) {
  const float* X = c.p.xPred[0].data();
  const float* H = c.p.radius.data();
  const float xi = X[3 * i], yi = X[3 * i + 1], zi = X[3 * i + 2], hi = H[i], di = c.s.density[i];
  for (uint32_t k = c.nb.waterBegin(i, static_cast<uint32_t>(c.nc)); k < c.nb.start[i + 1]; ++k) {
    const uint32_t j = c.nb.index[k];
    if (c.p.phase[j] != kWaterPhase) continue;
    const float rx = xi - X[3 * j], ry = yi - X[3 * j + 1], rz = zi - X[3 * j + 2];
    const float h = U ? 0.0f : pairRadius(hi, H[j]);
    const pbf::PairKernel<float> kernel = U ? c.kU : pbf::pairKernel(h, 1.0f / h);
    f(j, rx, ry, rz, rx * rx + ry * ry + rz * rz, kernel, pairVolume(c, j, di));
  }
}

// one water particle's XSPH velocity (Macklin 2013 Eq. 17, weighted by V_ij) to s.delta and, with
// Vort, its vorticity omega_i = sum_j V_j v_ij x grad W_ij (Eq. 15) to s.vorticity
template <bool U, bool Vort>
void xsphOf(const VelocityPass& c, size_t i) {
  const float* V = c.p.v[0].data();
  const float vxi = V[3 * i], vyi = V[3 * i + 1], vzi = V[3 * i + 2];
  float bx = 0.0f, by = 0.0f, bz = 0.0f, ox = 0.0f, oy = 0.0f, oz = 0.0f;
  forWaterPairs<U>(c, i, [&](uint32_t j, float rx, float ry, float rz, float r2, const pbf::PairKernel<float>& kernel,
                             float vol) {
    const float vx = V[3 * j] - vxi, vy = V[3 * j + 1] - vyi, vz = V[3 * j + 2] - vzi;
    const float wgt = vol * pbf::poly6Value(kernel, r2);
    bx += wgt * vx;
    by += wgt * vy;
    bz += wgt * vz;
    if (Vort) {
      const float f = vol * pbf::spikyFactor(kernel, r2, true);  // v_ij x (f r)
      ox += f * (vy * rz - vz * ry);
      oy += f * (vz * rx - vx * rz);
      oz += f * (vx * ry - vy * rx);
    }
  });
  if (Vort) c.s.vorticity[i] = Vec3(ox, oy, oz);
  if (c.keepSum) c.s.velocitySum[i] = Vec3(bx, by, bz);
  c.s.delta[i] = Vec3(vxi, vyi, vzi) + c.viscosity * Vec3(bx, by, bz);
}

// the hyperviscosity's second sum (docs/models.md, "Hyperviscosity"): with b = L v the XSPH sums of the
// first pass, delta_i -= k sum_j V_ij W_ij (b_j - b_i), the same weights as xsphOf's, so that
// sum_i m_i dv_i = 0 and a velocity field linear in position (L v = 0 where the support is full) is kept
template <bool U>
void hyperviscosityOf(const VelocityPass& c, size_t i, float k) {
  const Vec3* B = c.s.velocitySum.data();
  Vec3 sum = Vec3::Zero();
  forWaterPairs<U>(c, i, [&](uint32_t j, float, float, float, float r2, const pbf::PairKernel<float>& kernel,
                             float vol) { sum += (vol * pbf::poly6Value(kernel, r2)) * (B[j] - B[i]); });
  c.s.delta[i] -= k * sum;
}

// vorticity confinement, f = epsilon (N x omega), N = eta / |eta|, eta = grad |omega| (Macklin 2013
// Eq. 16), added as dt f to the XSPH velocities in s.delta
void confineVorticity(const VelocityPass& c, float epsilon, float dt) {
  const Particles& p = c.p;
  FluidScratch& s = c.s;
  const int64_t n = static_cast<int64_t>(p.size()), nc = c.nc;
  s.vorticityNorm.resize(static_cast<size_t>(n));
  parallelFor(n, [&](int64_t j) { s.vorticityNorm[j] = j < nc ? 0.0f : s.vorticity[j].norm(); });
  const float* X = p.xPred[0].data();
  const float* H = p.radius.data();
  const float* D = s.density.data();
  const float* O = s.vorticityNorm.data();
  parallelFor(n - nc, [&](int64_t w) {
    const size_t i = static_cast<size_t>(nc + w);
    const float xi = X[3 * i], yi = X[3 * i + 1], zi = X[3 * i + 2], hi = H[i];
    float ex = 0.0f, ey = 0.0f, ez = 0.0f;
    for (uint32_t k = c.nb.waterBegin(i, static_cast<uint32_t>(nc)); k < c.nb.start[i + 1]; ++k) {
      const uint32_t j = c.nb.index[k];
      const float rx = xi - X[3 * j], ry = yi - X[3 * j + 1], rz = zi - X[3 * j + 2];
      const float h = pairRadius(hi, H[j]);
      const float vol = p.phase[j] == kWaterPhase ? p.mass[j] / std::max(D[j], 1e-3f) : 0.0f;
      const float f = vol * O[j] * pbf::spikyFactor(pbf::pairKernel(h, 1.0f / h), rx * rx + ry * ry + rz * rz, true);
      ex += f * rx;
      ey += f * ry;
      ez += f * rz;
    }
    const Vec3 eta(ex, ey, ez);
    const float len = eta.norm();
    if (len > 1e-9f) s.delta[i] += dt * epsilon * (eta / len).cross(s.vorticity[i]);
  });
}

}  // namespace

void fluidVelocityPass(const Model& model, Particles& p, const NeighborLists& nb, FluidScratch& s, float dt,
                       bool listsOfSolve) {
  const WaterParams& wp = model.water;
  const size_t n = p.size();
  const int64_t nc = model.numCloth;
  const int64_t nw = static_cast<int64_t>(n) - nc;
  const float k = hyperviscosityStep(wp.hyperviscosity, dt);
  if (nw <= 0 || (wp.viscosity <= 0.0f && wp.vorticity <= 0.0f && k <= 0.0f)) return;
  s.delta.resize(n);  // the new velocities: the solver's corrections are spent, their memory reused
  s.vorticity.resize(n);
  if (k > 0.0f) s.velocitySum.resize(n);
  // compile-time flags: every radius equal (the kernel's constants are loop constants, as in
  // solveFluid), vorticity wanted
  float hU = 0.0f;
  const bool uniform = commonRadius(p.radius, hU);
  // as in solveFluid: only the particles with a pair of another radius take the per-pair radius
  // (the radii have not changed since solveFluid marked these lists: the wetting stages come after)
  if (!uniform) {
    hU = wp.supportRadius;
    if (!listsOfSolve) markNeighbourhoods(p, nb, nc, wp.particleMass, hU, &s.mixedRadius, nullptr);
  }
  const VelocityPass c{p, nb, s, s.mixedRadius.data(), pbf::pairKernel(hU, 1.0f / hU), wp.viscosity, nc, k > 0.0f};
  withFlags(uniform, wp.vorticity > 0.0f, [&](auto uniform, auto vortex) {
    constexpr bool Vort = decltype(vortex)::value;
    parallelFor(nw, [&](int64_t w) {
      const size_t i = static_cast<size_t>(nc + w);
      if (decltype(uniform)::value || !c.mixed[i])
        xsphOf<true, Vort>(c, i);
      else
        xsphOf<false, Vort>(c, i);
    });
  });
  if (wp.vorticity > 0.0f) confineVorticity(c, wp.vorticity, dt);
  if (k > 0.0f) {
    parallelFor(nw, [&](int64_t w) {
      const size_t i = static_cast<size_t>(nc + w);
      if (uniform || !c.mixed[i])
        hyperviscosityOf<true>(c, i, k);
      else
        hyperviscosityOf<false>(c, i, k);
    });
  }
  parallelFor(nw, [&](int64_t w) { p.v[nc + w] = s.delta[nc + w]; });
}

}  // namespace soak
