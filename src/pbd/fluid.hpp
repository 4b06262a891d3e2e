// Position Based Fluids (Macklin & Müller 2013) for the water particles, with cloth particles and
// colliders acting as boundaries (Akinci et al. 2012), as in section 3.2 of Shao et al. 2017.
#pragma once
#include <soak/model.hpp>
#include <soak/state.hpp>

#include "grid/grid.hpp"
#include "pbd/boundary.hpp"
#include "world/colliders.hpp"

#include <algorithm>
#include <vector>

namespace soak {

struct FluidScratch {
  std::vector<float> psi;          // kg, Akinci boundary mass Psi_b = rho0 V_b of cloth particles (0 with no water near)
  std::vector<float> density;      // kg/m^3, rho_i of water particles (last iteration)
  std::vector<float> lambda;       // m^2, lambda_i / m_i of the density constraint
  std::vector<Vec3> delta;         // m, position corrections of the current iteration; m/s, velocities after XSPH
  std::vector<Vec3> vorticity;     // 1/s, omega_i
  std::vector<Vec3> velocitySum;   // m/s, each water particle's XSPH sum sum_j V_ij W_ij (v_j - v_i) = L v (hyperviscosity)
  std::vector<float> vorticityNorm; // 1/s, |omega_i| (0 for cloth)
  std::vector<float> massOrPsi;    // kg, what a neighbour lends the density: m_j (water) or Psi_j (cloth)
  float sCorrScale = 0.0f;         // m^2, lambda scale of the artificial pressure
  std::vector<BoundaryPart> parts; // convex collider parts at this substep's poses
  std::vector<float> wallClear;    // m, per water particle: a lower bound of its distance to the nearest part at wallFrom
  std::vector<uint8_t> mixedRadius;  // 1: a pair of the particle's list has another radius than water.supportRadius
  std::vector<uint8_t> plain;        // 1: a water particle of water.particleMass whose neighbours all are (markNeighbourhoods)
  std::vector<Vec3> wallFrom;      // m, where each water particle was when wallClear was measured
  // per entry of the water particles' neighbour lists, written by the lambda pass and read by the
  // correction pass of the same iteration: m_j sf_ij r_ij (kg m, the spiky gradient's factor sf) and
  // |r_ij|^2 (m^2, only with artificial pressure: pairR2 is empty without); used only while the
  // arrays take at most pairCacheLimit bytes
  std::vector<float> pairGx, pairGy, pairGz, pairR2;
  size_t pairCacheLimit = size_t(256) << 20;
};

// Akinci volume of each cloth particle, V_b = 1 / sum_k W_bk over the same piece (Eq. 10), and
// its boundary mass Psi_b = rho0 V_b, for the cloth particles with water in their lists (0 elsewhere)
void computeBoundaryPsi(const Model& model, const Particles& p, const NeighborLists& nb, FluidScratch& s);

// the PBF density constraint (Eq. 6-7), Jacobi iterations on p.xPred: `iterations`, then more up to
// maxIterations (<= iterations: none) while the water's meanCompression exceeds solver.fluidTolerance;
// last: the count of the previous solve (State::fluidIterations, for stopIterating). Cloth particles
// are moved by the boundary reaction (two-way coupling). Returns the iterations taken
int solveFluid(const Model& model, const std::vector<ColliderPose>& poses, Particles& p, const NeighborLists& nb,
               FluidScratch& s, int iterations, int maxIterations = 0, int last = 0);

// whether the solve stops after `taken` iterations at this mean compression. Hysteresis: it stops
// below the last solve's count only while the compression is under half the tolerance, so a pool at
// rest keeps one count; a count that switched from substep to substep would jolt the whole pool by one
// iteration's correction each time it changed
inline bool stopIterating(double compression, double tolerance, int taken, int last) {
  return compression <= (taken < last ? 0.5 * tolerance : tolerance);
}

// mean over the water particles of max(rho_i / rho_0 - 1, 0), from the densities of the last lambda pass
double meanCompression(const Model& model, const FluidScratch& s);

// the hyperviscosity's coefficient for a substep of h: rate h, at most kMaxHyperviscosityStep. A mode
// that L (the XSPH sum) scales by -mu keeps 1 - k mu^2 of itself a substep; mu is at most twice a row's
// weight sum sum_j V_ij W_ij < 1 (Gershgorin), so k <= 0.5 never amplifies one (about 1.1 in settled water);
// 0.4: at 0.45-0.5 a block dropped at one substep of 0.03 s threw spray far higher (docs/models.md)
constexpr float kMaxHyperviscosityStep = 0.4f;
inline float hyperviscosityStep(float rate, float h) { return std::min(rate * h, kMaxHyperviscosityStep); }

// XSPH viscosity, vorticity confinement and the hyperviscosity (v -= k L(L v), docs/models.md) on water
// velocities (after v = (x* - x)/dt).
// listsOfSolve: nb are the lists solveFluid last ran on with s, and no radius has changed since, so its
// mixed-radius flags (s.mixedRadius) hold; false marks them again
void fluidVelocityPass(const Model& model, Particles& p, const NeighborLists& nb, FluidScratch& s, float dt,
                       bool listsOfSolve);

}  // namespace soak
