// parameters of the garment model (Chen, Magnenat-Thalmann, Allen 2012): plain data with no
// dependency beyond soak/math.hpp, so a scene loader or a public header can hold them. Defaults are
// the paper's where it gives a value (Table 1, Eq. 22's beta) and documented choices elsewhere
// (docs/garment.md).
#pragma once
#include <soak/math.hpp>

#include <cstdint>

namespace soak {

// one KES law: Eq. 11 sigma = a1 eps / (1 - a2 |eps|)^3 for stretch and shear, Eq. 14
// sigma = a1 eps + a2 eps |eps| for bending. sigma is a force per unit width (N/m).
struct KesLaw {
  float a1 = 1000.0f;  // N/m, initial (small strain) stiffness, > 0
  float a2 = 0.0f;     // >= 0; Eq. 11: dimensionless, pole at |eps| = 1/a2; Eq. 14: N/m; 0 is Hooke's law
};

struct SpringLaws {
  KesLaw stretch{2000.0f, 4.0f};
  KesLaw shear{100.0f, 2.0f};
  KesLaw bend{20.0f, 0.0f};
  // Eq. 11 is followed up to |eps| = strainLimit / a2 and continued by its tangent beyond, so the
  // pole at 1/a2 is never reached (departure, docs/garment.md)
  float strainLimit = 0.9f;
  // N/m, a seam's pull per metre of gap (seamForce, garment/springs.hpp); the scene loader gives it the
  // stretch law's a1 unless the scene sets garment.seams.stiffness
  float seamStiffness = 2000.0f;
};

struct SpringBuildOptions {
  float bendStraightness = 0.8f;  // cosine of the largest turn a bend spring may make at its middle vertex
};

// saturation of Eq. 15-19 (saturation_mass.hpp)
struct SaturationParams {
  float delta = 0.84f;     // kg of water per kg of dry fabric at saturation (Table 1's "theta" row, see NOTES.md)
  float a3 = 8.844f;       // time constant of Eq. 18, in the paper's (unstated) time unit
  float timeScale = 1.0f;  // s of simulated time per paper time unit: t_paper = t / timeScale (default: seconds)
  bool unlimitedSupply = false;  // Chen as printed: a wet vertex absorbs Q(t) from its first touch; false: it
                                 // absorbs the water that reached it (State::clothWater), at Eq. 18's rate
};

// wet skin friction of Fig. 5 over the saturation s = absorbed water / (delta m_dry) (wet_friction.hpp)
struct WetFrictionParams {
  float dry = 0.35f;               // Coulomb coefficient of the dry fabric (s = 0)
  float peak = 0.60f;              // at s = peakSaturation
  float plateau = 0.45f;           // from s = plateauSaturation on
  float peakSaturation = 0.2f;     // in (0, 1)
  float plateauSaturation = 0.5f;  // in (peakSaturation, 1]
};

// wrinkle disturbances of section 3.5 (wrinkles.hpp)
struct WrinkleParams {
  bool enabled = false;
  float compressionThreshold = 0.05f;  // a stretch spring is compressed when eps < -threshold
  float equilibriumSpeed = 0.5f;       // m/s: a subdomain is disturbed only while its RMS speed is below this
  int interval = 10;                   // disturb every `interval` steps (the constraint lasts one step)
  int patchSize = 100;                 // vertices per subdomain when the garment has no panels
  float tieTolerance = 1e-3f;          // |AA1| = |AA2| when they differ by less than this fraction of l0 (step 5)
  uint32_t seed = 1;                   // the paper's random choice between equal candidates, made reproducible
  float strength = 1.0f;               // fraction of the way from A to the chosen point A' a saturated vertex is moved, (0, 1]
  float dryStrength = 0.0f;            // the same for a dry vertex, [0, strength]; linear in the saturation between
};

// a sewn garment's seams (world/pattern.hpp) close during the first moments of the run
struct SeamParams {
  float closeTime = 0.5f;            // s: each seam's rest length shrinks linearly from its starting gap to 0
  bool gravityWhileClosing = false;  // false: the piece feels no gravity before closeTime, as garment tools sew
  float settleTime = 0.25f;          // s after closeTime: the piece drapes without friction on the colliders
};

// the preconditioner of the conjugate gradient of Eq. 5 (garment/block_cg.hpp)
enum class CgPreconditioner : uint8_t {
  BlockJacobi,  // the inverse 3x3 diagonal blocks: cheap per iteration, hundreds of iterations on stiff cloth
  Cholesky,     // the exact sparse Cholesky factor of the filtered system: one iteration, a costly factor
  Multigrid,    // one V-cycle of two-level smoothed aggregation (garment/multigrid.hpp)
  GaussSeidel,  // symmetric block Gauss-Seidel in a colour order, Eisenstat's form (garment/gauss_seidel_cg.hpp)
};

// everything the implicit garment solver of one cloth piece reads (implicit.hpp)
struct GarmentParams {
  SpringLaws laws;                    // KES laws (Eq. 11, 14)
  SpringBuildOptions build;
  SaturationParams saturation;        // Eq. 18, Table 1 (cotton by default)
  WetFrictionParams friction;         // Fig. 5
  WrinkleParams wrinkles;             // section 3.5 (off by default)
  SeamParams seams;                   // a sewn garment's seams (ClothPiece::seams)
  bool saturationMass = true;         // garmentSubstep sets the mass by Eq. 15-19; false: the mass is
                                      // left to another model (Shao 2017 absorption)
  float rayleighAlpha = 0.0f;         // 1/s, mass-proportional damping, >= 0 (the paper's -9 is a typo: NOTES.md)
  float rayleighBeta = 3.81413e-3f;   // s, stiffness-proportional damping (Eq. 22)
  float cgTolerance = 1e-4f;          // relative preconditioned residual
  int cgMaxIterations = 300;
  CgPreconditioner cgPreconditioner = CgPreconditioner::BlockJacobi;
  bool cgWarmStart = false;           // the CG starts from the last substep's velocity change (State::clothVelocityChange)
  bool edgeContact = false;           // also push the mesh edges' midpoints out of the colliders (implicit.cpp)
  bool strainLimiting = true;         // no stretch or shear spring ends a step past 1/a2 (strain_limit.hpp)
};

}  // namespace soak
