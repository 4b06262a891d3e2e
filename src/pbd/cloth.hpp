// PBD cloth: stretch (Eq. 8) and dihedral bending (Eq. 9) constraints with XPBD compliance, solved
// colour by colour in parallel (deterministic), and particle-particle self-collision.
#pragma once
#include <soak/model.hpp>
#include <soak/state.hpp>

#include "core/parallel.hpp"
#include "grid/grid.hpp"
#include "world/colliders.hpp"

#include <cstdint>
#include <memory>
#include <vector>

namespace soak {

// rebuilds model.stretch and model.bend from the triangles of the PBD pieces (Eq. 8: one stretch
// constraint per edge; Eq. 9: one bend constraint per interior edge), coloured and scheduled
// (ConstraintSchedule). Implicit pieces get none: src/garment builds their springs.
void buildClothConstraints(Model& model);

// Eq. 9's XPBD compliance of the hinge of edge (a, b) between triangles (a, b, c) and (a, b, d) at rest:
// material.bendCompliance when >= 0, else (A1 + A2) / (bendRigidity |e|^2) (docs/models.md, Eq. 9)
float hingeCompliance(const ClothMaterial& mat, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

// the global stretch step's factored system (cloth_global_stretch.cpp)
struct GlobalStretch;
struct GlobalStretchDeleter {
  void operator()(GlobalStretch* g) const;
};

// the coarse levels of solver.clothHierarchy (cloth_hierarchy.cpp)
struct ClothHierarchy;
struct ClothHierarchyDeleter {
  void operator()(ClothHierarchy* h) const;
};

// scratch for the cloth solver (XPBD multipliers)
struct ClothScratch {
  std::vector<float> stretchLambda, bendLambda;
  std::vector<float> correction;      // m, the moves of the stretch constraints' particles, 6 per constraint (SoA)
  std::vector<float> correctionBend;  // m, the same for the bend constraints, 12 per constraint
  std::vector<Vec3> delta;            // m, the self-collision moves of a pass (per particle, or per pair owner)
  std::vector<int> contacts;          // the pairs that pass pushed each of them away from
  double selfCollisionMs = 0.0;       // the last stepCloth's time in the self-collision (stage timings)
  std::vector<int> pairCount, pairs;  // CSR: particle i's self-collision pairs are pairs[pairCount[i], pairCount[i + 1])
  std::vector<int> pairOwners;        // the particles with at least one such pair, in order
  std::vector<float> speed;           // m/s, |v| of each cloth particle at the substep's start (findSelfCollisionPairs)
  std::vector<Vec3> displacement;     // m, x* - x of each cloth particle while the constraints solve (solveClothFrom)
  std::vector<Vec3> stepDisplacement, stepVelocity;  // m, m/s: a cloth particle's x* - x and v at a small step's start
  std::vector<Vec3> velocityOffset;  // m/s: the last small step's velocity minus (x* - x)/h (stepCloth)
  std::vector<Vec3> stepStart;       // m, x* before a small step's prediction: where its collider contact starts
  std::vector<float> colliderBound;  // m, a lower bound of each cloth particle's distance to the colliders
  std::vector<int> colliderCandidates;  // the cloth particles that may meet a collider in the substep
  uint64_t colliderPutBack = 0;      // the small steps' collider put-backs of the last stepCloth
  std::unique_ptr<GlobalStretch, GlobalStretchDeleter> globalStretch;  // built at the first globalStretchStep
  std::unique_ptr<ClothHierarchy, ClothHierarchyDeleter> hierarchy;    // built at the first solveHierarchyFrom
};

// the colliders the PBD cloth meets in each of its small steps (step.cpp fills it: smallStepColliders)
struct SmallStepColliders {
  std::vector<std::vector<ColliderPose>> poses;  // the colliders' poses at the end of each small step
  std::vector<uint8_t> include;                  // 1 for each collider, kPosedAhead for a moving mesh sequence
  std::vector<IndexRange> cloth;                 // the PBD cloth's particles
};

// C(x1, x2) = |x1 - x2| - l0 (Eq. 8); returns C and writes gradients wrt x1 and x2
float stretchConstraint(const Vec3& x1, const Vec3& x2, float restLength, Vec3& grad1, Vec3& grad2);

// signed dihedral angle of triangles (a, b, c) and (b, a, d) sharing edge (a, b), minus phi0 (Eq. 9);
// writes the gradients wrt a, b, c, d
float bendConstraint(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, float restAngle, Vec3 grad[4]);

// solves the cloth constraints for `iterations` iterations on x* = base + displacement, moving the
// displacement (XPBD, multipliers reset here once per substep). Each constraint takes the difference of
// two positions as the difference of their bases plus that of their displacements, so moves far below a
// float's resolution at |x| (1.2e-7 m at 1 m), as a small step's are, are kept (docs/models.md, "Single
// precision and the small steps")
void solveClothFrom(const Model& model, const Vec3* base, Vec3* displacement, const float* invMass,
                    ClothScratch& scratch, float dt, int iterations);

// solver.clothHierarchy coarse levels (after Müller 2008, hierarchical PBD) on x* = base + displacement:
// each level a maximal independent set of the finer one's particles (the pins always in); each of its
// particles stands for the weighted mean of a cluster (itself and the finer particles next to it), and
// clusters whose particles are neighbours or share one below are joined by a constraint |centre_a -
// centre_b| <= its rest value, projected as a PBD constraint over the clusters' particles (mass
// weighted, momentum kept). Coarsest first, one Gauss-Seidel pass a level, only the stretched edges
// (never pushing, so the cloth folds freely). Then solver.clothPinPasses passes over the inextensible
// edges within solver.clothPinRings edges of a pin, stretched ones only. Built at the first call; moves
// only free PBD cloth (docs/models.md, Eq. 8, "The coarse levels" and "The pins' neighbourhood")
void solveHierarchyFrom(const Model& model, const Vec3* base, Vec3* displacement, const float* invMass,
                        ClothScratch& scratch);

// a cloth particle the PBD cloth moves: neither pinned nor in an implicit piece
inline bool pbdClothMoves(const Model& model, int64_t i) {
  const bool pinned = i < static_cast<int64_t>(model.clothPinned.size()) && model.clothPinned[static_cast<size_t>(i)];
  return !pinned && !model.implicitCloth(i);
}

// solveHierarchyFrom and solveClothFrom on p.xPred, the displacement from p.x: x* = x + displacement
// after them for the particles the PBD cloth moves (pbdClothMoves), the rest keep their x*
void solveCloth(const Model& model, Particles& p, ClothScratch& scratch, float dt, int iterations);

// the PBD cloth's substep of h: model.solver.clothSubsteps small steps of h/clothSubsteps, each a
// prediction from the last (v += h_s g, x* = x + h_s v), the tethers, clothIterations iterations
// of solveCloth, the self-collision of the pairs near at the substep's start and, with colliders, the
// contact and Coulomb friction of the colliders at the small step's end (Macklin et al. 2019:
// substeps converge faster than iterations). Leaves x* at the last small step's end and
// scratch.velocityOffset for updateVelocities. Moves only free PBD cloth. neighbors: the lists of x*.
void stepCloth(const Model& model, Particles& p, const NeighborLists& neighbors, ClothScratch& scratch, float h,
               const SmallStepColliders* colliders = nullptr);

// solver.clothGlobalStretch: one local/global step of projective dynamics (Bouaziz et al. 2014) on x*
// over the PBD cloth's inextensible edges (stretch compliance 0): x* + delta minimises
// sum_i m_i |delta_i|^2 / 2 + w sum_e |x_i - x_j - d_e|^2 / 2, d_e the edge at its rest length along its
// present direction, w = 1e6 times the mean dry particle mass, held ends fixed; (M_dry + w L) is
// factored at the first call. Keeps each free piece's momentum (wet masses too); moves only free PBD
// cloth. stepCloth calls it in each small step, after the constraints (docs/models.md, Eq. 8, "The
// global stretch step")
void globalStretchStep(const Model& model, Particles& p, ClothScratch& scratch);

// pushes apart cloth particles of the same piece closer than its thickness d that are not mesh
// neighbours nor closer than d at rest: delta_i = sum_j w_i/(w_i + w_j) (d - |x_ij|) x_ij/|x_ij|
// (Jacobi, gather style: each particle sums its own moves), over all of each particle's neighbours;
// returns the pairs pushed, each counted from both sides (once where one end is held)
int clothSelfCollision(const Model& model, Particles& p, const NeighborLists& neighbors, ClothScratch& scratch);

// the pairs clothSelfCollision would consider that may come within its thickness d in the substep of h
// that starts (closer than 1.25 d plus |v_i - v_j| h at x*), into scratch.pairCount / scratch.pairs
// (the small steps' candidates)
void findSelfCollisionPairs(const Model& model, const Particles& p, const NeighborLists& neighbors, float h,
                            ClothScratch& scratch);

// clothSelfCollision's push over the pairs findSelfCollisionPairs found only; returns as it does
int collideSelfCollisionPairs(const Model& model, Particles& p, ClothScratch& scratch);

}  // namespace soak
