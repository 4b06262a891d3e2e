// parameters read from the scene file; defaults are Table 1 of Shao et al. 2017 unless noted
#pragma once
#include <soak/math.hpp>

namespace soak {

struct SolverParams {
  float dt = 0.015f;              // s, time step per frame-step (Table 1)
  int substeps = 1;               // substeps per step; dt/substeps is the integration step
  int fluidIterations = 4;        // PBF density iterations per substep, at least
  int fluidMaxIterations = 32;    // at most: more than fluidIterations while the water's mean compression exceeds fluidTolerance
  float fluidTolerance = 0.01f;   // mean over the water of max(rho_i / rho_0 - 1, 0) the extra iterations stop at
  int clothSubsteps = 1;          // small steps the PBD cloth takes per substep (Macklin et al. 2019)
  int clothIterations = 8;        // cloth constraint iterations per small step
  bool clothCollidersInSmallSteps = true;  // colliders meet the PBD cloth in each small step (false: once a substep)
  int clothHierarchy = 6;         // coarse levels whose cluster distances the PBD cloth keeps within rest before each small step's iterations
  int clothPinPasses = 8;         // extra passes, before each small step's iterations, over the inextensible edges near a pinned particle
  int clothPinRings = 5;          // how near: edges within this many edges of a pinned particle
  bool clothGlobalStretch = false;  // a global step brings the PBD cloth's inextensible edges to length in each small step
  int couplingIterations = 2;     // water-cloth coupling passes per substep (Eq. 21)
  Vec3 gravity{0.0f, -9.81f, 0.0f};  // m/s^2
  Vec3 domainMin{-10.0f, -10.0f, -10.0f};  // m; particles leaving this box are removed and counted
  Vec3 domainMax{10.0f, 10.0f, 10.0f};     // m
  int maxParticles = 2'000'000;   // cap on the number of particles (emitters stop at it)
  float maxSpeed = 50.0f;         // m/s; a particle faster than this stops the run as diverged
};

struct WaterParams {
  float restDensity = 1000.0f;    // kg/m^3, rho_0 of water (Table 1)
  float spacing = 0.02f;          // m, r_0: initial particle spacing (Table 1)
  float supportRadius = 0.04f;    // m, h: SPH support radius (Table 1)
  float particleMass = 0.0082f;   // kg, mass of a full-size water particle (Table 1)
  float relaxation = 0.1f;        // CFM epsilon of PBF's lambda (Macklin 2013 Eq. 11), in units of w_i / h_i^2
  float viscosity = 0.02f;        // XSPH coefficient c (Macklin 2013 Eq. 17), with volume-weighted W
  float vorticity = 0.0f;         // vorticity confinement epsilon (Macklin 2013 Eq. 16), m/s^2 scale
  float hyperviscosity = 50.0f;   // 1/s: v -= (rate h) L(L v) a substep, L the XSPH sum: damps particle-scale noise (docs/models.md)
  float tensileK = 0.0f;          // artificial pressure k (Macklin 2013 Eq. 13); off: see docs/models.md on Eq. 6
  float tensileDq = 0.2f;         // artificial pressure delta q, as a fraction of h
  int tensileN = 4;               // artificial pressure exponent n
  float boundaryFriction = 0.1f;  // Coulomb coefficient of water against colliders (static = kinetic), mixed with theirs
  float clothFriction = 0.0f;     // Coulomb coefficient of water on cloth (Eq. 21 contacts; static = kinetic)
};

struct ClothMaterial {
  float particleMass = 0.0f;        // kg per cloth particle when dry and > 0 (Table 1: 0.0066); else arealDensity
  float arealDensity = 16.5f;       // kg/m^2 of dry fabric: a particle weighs it times its mixed Voronoi area
                                    // on the rest mesh, so a remesh keeps the weight (Table 1's 0.0066 kg on
                                    // its 0.02 m spacing)
  float restDensity = 800.0f;       // kg/m^3 (Table 1)
  float stretchCompliance = 0.0f;   // m/N, XPBD compliance of Eq. 8 (0 = inextensible)
  float bendRigidity = 1.3e-3f;     // N m, flexural rigidity B of the fabric: Eq. 9's hinge compliance is
                                    // (A1 + A2) / (B |e|^2) (cloth_constraints.cpp); the default gives the
                                    // default arealDensity a 2 cm bending length (B / (arealDensity g))^(1/3)
  float bendCompliance = -1.0f;     // 1/(N m), XPBD compliance of every Eq. 9 hinge when >= 0, else from
                                    // bendRigidity
  float damping = 0.0f;             // 1/s, velocity damping of the cloth
  float thickness = 0.01f;          // m, d of Eq. 21 and the self-collision distance
  float friction = 0.3f;            // kinetic Coulomb coefficient against colliders, mixed with theirs
  float staticFriction = 0.3f;      // static Coulomb coefficient, >= friction
  bool selfCollision = true;
  float tetherSlack = 0.0f;         // fraction a particle may stray beyond its rest path length from the pins
};

// cloth wetting of Shao et al. 2017 section 4 (docs/models.md, "Wetting"). Saturations are
// dimensionless (Table 1's "L"); the per-step rates refer to a step of rateStep seconds and are
// converted to the substep actually taken, so a scene wets the same with any substep count.
struct WettingParams {
  bool enabled = false;              // the scene turns it on when a "wetting" section is present
  float c = 1.0e-3f;                 // m^3/kg, c of Eq. 10: 1/rho_water, so S is the water volume fraction of V_i
  float saturationSticky = 0.12f;    // S^T: sticking peaks here (Eq. 20), coupling softens above it (Eq. 22)
  float saturationEmit = 0.35f;      // S^EW: water above it goes to the emission buffer (section 4.4)
  float saturationMax = 0.4f;        // S^MAX: absorption stops here (Eq. 11)
  float initialSaturation = 0.0f;    // S of every cloth particle at load (Fig. 6 starts saturated)
  float rateStep = 0.015f;           // s, the step the rates kappa^a and the Eq. 18 transfer refer to
  float referenceArea = 4.0e-4f;     // m^2, the cloth area m^threshold, eta^e, eta^ad and kappa^ad are given for
                                     // (Table 1's 0.02 m spacing squared); 0: per particle, as printed
  bool everySubstep = false;         // false: the wetting stages run once a step, with the step's dt (Algorithm 1)
  // absorption, Eq. 11
  bool absorption = true;
  float absorptionRate = 0.1f;       // kappa^a per rateStep
  float absorptionGravity = 0.6f;    // eta^a
  float minMassFraction = 0.1f;      // a water particle lighter than this times water.particleMass is absorbed whole
  // diffusion, Eq. 12-17 as a rate in time with a capillary equilibrium (docs/models.md, "Diffusion")
  bool diffusion = true;
  bool diffusionGravity = true;      // gravity in the wicking: the equilibrium height H and (1 + eta^d cos theta) (Fig. 5c); off gives Fig. 5b
  float diffusivity = 0.03f;          // m^2/s, D: Eq. 12's kappa^d as the diffusion coefficient of S
  float wickingHeight = 0.15f;        // m, H: at capillary equilibrium S halves every H of height
  float diffusionGravityFactor = 0.4f;  // eta^d
  int diffusionIterations = 1;       // explicit sub-steps per stable one (accuracy only)
  // emission, Eq. 18-19
  bool emission = true;
  float beta = 1.5f;                 // s^2/m, beta of Eq. 18
  float massThreshold = 0.002f;      // kg, m^threshold for a particle of referenceArea: a buffer this full forms a drip
  float maxDripMass = 0.0f;          // kg, a hanging drip this heavy is let go (0: four water.particleMass)
  float attraction = 10.0f;          // m/s^2, kappa^e of Eq. 19
  float attractionSaturation = 0.01f;  // kg, eta^e of Eq. 19 (for a particle of referenceArea)
  // wet dynamics, Eq. 20 and Eq. 22
  bool sticking = true;
  float stickingRate = 0.3f;         // N, kappa^ad of Eq. 20 (for a pair of referenceArea particles)
  float stickingStrength = 0.02f;    // N, eta^ad of Eq. 20 (likewise)
  bool permeability = true;          // Eq. 22: wetter triangles let water through
};

}  // namespace soak
