// implicit mass-spring cloth of Chen, Magnenat-Thalmann, Allen 2012 (section 3.1, Eq. 1-5): one
// backward Euler step linearised once (Baraff & Witkin 1998),
//   (M - h df/dv - h^2 df/dx) dv = h (f0 + h df/dx v0),   v1 = v0 + dv,   x1 = x0 + h v1,
// with the KES springs of springs.hpp, gravity, Rayleigh damping D = alpha M + beta K (Eq. 22-24),
// the saturation mass of Eq. 15-19 (read from Particles::mass), pinned vertices and temporary
// position constraints (wrinkles.hpp) and the contact of vertices resting on a collider, with Coulomb
// friction at the wet friction curve of Fig. 5 (wet_friction.hpp), enforced by the filtered PCG of
// block_cg.hpp; after the solve, contact and friction of the vertices that reached a collider during
// the step, the strain limiting (strain_limit.hpp) and the self-collision (self_collision.hpp).
//
// Use from the step, for a piece whose scene says "solver": "implicit" (docs/garment.md): one call
//   ImplicitStats s = garmentSubstep(model, g, params, saturation, h, time, stepIndex, poses, p, scratch);
// which is
//   applySaturationMass(model, k, saturation, params.saturation, p);      // Eq. 15-19
//   auto wr = computeDisturbances(model, k, g.springs, g.subdomains, p, poses, params.wrinkles, step, saturation);
//   implicitStep(model, g, params, h, time, poses, saturation, wr, p, scratch);  // Eq. 1-5, contact
// It reads x, v, mass of the piece and writes xPred (= x1) and v (= v1); x is left for the caller's
// commit (x = xPred). The PBD stages leave the piece alone: predictPositions, solveCloth and
// updateVelocities move only the particles of pbdParticles (pbd/integrate.hpp).
#pragma once
#include <soak/model.hpp>
#include <soak/state.hpp>

#include "core/friction.hpp"
#include "garment/block_cg.hpp"
#include "garment/saturation_mass.hpp"
#include "garment/self_collision.hpp"
#include "garment/springs.hpp"
#include "garment/wet_friction.hpp"
#include "garment/wrinkles.hpp"
#include "world/colliders.hpp"

#include <span>
#include <string>
#include <vector>

namespace soak {

// throws soak::Error "<where>.<key>: expected ..., got ..." for the first parameter out of its range
// (a1 > 0, a2 >= 0, 0 < strainLimit < 1, a3 > 0, 0 < tau1 < tau2, alpha >= 0, beta >= 0, ...)
void checkGarmentParams(const GarmentParams& params, const std::string& where);

// the constant data of a piece solved implicitly: springs, the system's block pattern, subdomains
struct GarmentPiece {
  int piece = -1;
  int firstParticle = 0, count = 0;
  SpringSet springs;
  // row v of the system: [rowStart[v], rowStart[v + 1]): the diagonal, then one block per spring of v
  // in springs.vertexSpring order
  std::vector<int> rowStart, col;
  std::vector<std::vector<int>> subdomains;  // piece-local vertex sets for the wrinkle model
  SelfCollisionMesh mesh;  // piece-local triangles, edges and seam groups
};

// builds the garment data of model.pieces[piece]; subdomains are connected patches of
// params.wrinkles.patchSize vertices (the garment's panels, where the mesh has no panel data)
GarmentPiece buildGarmentPiece(const Model& model, int piece, const GarmentParams& params);

struct ImplicitScratch {
  BlockMatrix A;
  CgScratch cg;
  std::vector<Vec3d> springForce;              // N, on ids[s][0]
  std::vector<Eigen::Matrix3d> springStiffness;
  std::vector<float> strain;
  std::vector<Vec3d> rhs, dv;
  // per vertex: 0 free, 1 pinned, 2 disturbed, kContactRow (sliding), kStickRow; 3 after the step: in contact
  std::vector<uint8_t> constrained;
  std::vector<Vec3d> contactNormal;     // per contact row: the collider's unit normal
  std::vector<Vec3> contactVelocity;    // per contact row: the collider's surface velocity (m/s)
  std::vector<float> fabricMu;          // per vertex: the fabric's friction at its saturation (0 while sewing)
  std::vector<FrictionCoefficients> contactMu;  // per contact row: the fabric's friction mixed with the collider's
  std::vector<Vec3d> frictionImpulse;   // per vertex: a sliding row's kinetic friction on the right-hand side (kg m/s)
  std::vector<Vec3d> frictionChange;    // updateContactRows' change of frictionImpulse
  std::vector<int> contactCollider;     // per vertex: the collider of its contact row, -1 none
  std::vector<double> contactSpeed;     // per vertex in a collider's band: the row's prescribed normal speed (m/s)
  std::vector<int> watchedCollider;     // per vertex: free in a collider's band (held off, or released), -1 none
  std::vector<double> throughSpeed;     // per watched vertex: the normal speed below which it ends inside (m/s)
  std::vector<Vec3> edgeMid;       // m, the mesh edges' midpoints (pushEdgesOut)
  std::vector<float> edgeBound;    // m, a lower bound of each midpoint's distance to the colliders
  std::vector<float> invMass;      // strain limiting and self-collision: 1/m, 0 for pinned and disturbed vertices
  std::vector<uint8_t> strainMoved;  // per vertex: moved by the strain limiting this step
  SelfCollisionScratch self;
};

struct ImplicitStats {
  int cgIterations = 0;
  int solves = 0;            // CG solves: the contact rounds and the last (contact_rows.hpp)
  double cgResidual = 0.0;   // relative, at exit
  bool converged = true;     // false: the CG hit cgMaxIterations (or broke down); the step still ran
  bool breakdown = false;    // the system was not positive definite
  bool factorFailed = false; // the Cholesky or multigrid coarse factor failed: block Jacobi was used
  int constrainedVertices = 0;  // pinned + disturbed
  int contacts = 0;             // vertices held on (contact rows) or pushed out of a collider
  int contactRows = 0;          // vertices held on a collider by the solve (kContactRow, kStickRow)
  int stickingRows = 0;         // of them, sticking to it (static friction)
  int edgeContacts = 0;         // mesh edges whose midpoint was pushed out of a collider
  int selfContacts = 0;         // vertex-triangle pushes of the self-collision (material.selfCollision)
  int selfEdgeContacts = 0;     // its edge-edge pushes
  int selfReverted = 0;         // vertices its fail-safe moved into impact zones (a pair still through)
  int disturbances = 0;         // wrinkle constraints applied (garmentSubstep)
  int strainLimited = 0;        // stretch and shear springs the strain limiting shortened (strain_limit.hpp)
  float minStrain = 0.0f, maxStrain = 0.0f;  // over stretch springs, at the start of the step
  // wall ms of the step's parts: forces, rows and system (with Eq. 15-19 and section 3.5), the CG with
  // its contact rounds, the integration with the collider contact, strain limiting and edge contact,
  // the self-collision
  double msAssemble = 0.0, msCg = 0.0, msIntegrate = 0.0, msSelfContact = 0.0;
};

// one implicit step of length h from `time` for the piece (see the header comment); seams pull towards
// their starting gap times max(0, 1 - time / closeTime), and gravity is off while they close unless
// params.seams.gravityWhileClosing. saturation (piece-local, in [0, 1], empty = all dry) sets each
// vertex's friction with wetFriction; poses are the colliders at time + h. velocityChange (piece-local,
// State::clothVelocityChange) holds the last step's dv: the solve starts from it when
// params.cgWarmStart, and it receives this step's; empty: a cold start. Deterministic for any thread
// count.
ImplicitStats implicitStep(const Model& model, const GarmentPiece& g, const GarmentParams& params, float h, double time,
                           const std::vector<ColliderPose>& poses, std::span<const float> saturation,
                           const std::vector<PositionConstraint>& constraints, Particles& p, ImplicitScratch& scratch,
                           std::span<Vec3> velocityChange = {});

// the garment stage of one piece for one step of length h from `time` (s; it paces the seams'
// closing, SeamParams) (see the header comment); stepIndex paces the wrinkle disturbances;
// velocityChange as for implicitStep
ImplicitStats garmentSubstep(const Model& model, const GarmentPiece& g, const GarmentParams& params,
                             std::span<const float> saturation, float h, double time, uint64_t stepIndex,
                             const std::vector<ColliderPose>& poses, Particles& p, ImplicitScratch& scratch,
                             std::span<Vec3> velocityChange = {});

// kinetic + gravitational + elastic energy of the piece (J), for tests and diagnostics
double garmentEnergy(const Model& model, const GarmentPiece& g, const GarmentParams& params, const Particles& p);

}  // namespace soak
