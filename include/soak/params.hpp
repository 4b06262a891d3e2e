// parameters read from the scene file; defaults are Table 1 of Shao et al. 2017 unless noted
#pragma once
#include <soak/math.hpp>

namespace soak {

struct SolverParams {
  float dt = 0.015f;              // s, time step per frame-step (Table 1)
  int substeps = 1;               // substeps per step; dt/substeps is the integration step
  int fluidIterations = 4;        // PBF density iterations per substep
  int clothIterations = 8;        // cloth constraint iterations per substep
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
  float tensileK = 0.1f;          // artificial pressure k (Macklin 2013 Eq. 13)
  float tensileDq = 0.2f;         // artificial pressure delta q, as a fraction of h
  int tensileN = 4;               // artificial pressure exponent n
  float boundaryFriction = 0.1f;  // tangential damping of water against colliders, 0..1
};

struct ClothMaterial {
  float particleMass = 0.0066f;     // kg per cloth particle when dry (Table 1)
  float restDensity = 800.0f;       // kg/m^3 (Table 1)
  float stretchCompliance = 0.0f;   // m/N, XPBD compliance of Eq. 8 (0 = inextensible)
  float bendCompliance = 1.0e-3f;   // 1/(N m), XPBD compliance of Eq. 9
  float damping = 0.0f;             // 1/s, velocity damping of the cloth
  float thickness = 0.01f;          // m, d of Eq. 21 and the self-collision distance
  float friction = 0.3f;            // Coulomb-like friction against colliders, 0..1
  bool selfCollision = true;
};

}  // namespace soak
