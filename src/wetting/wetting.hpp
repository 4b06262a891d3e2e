// cloth wetting of Shao, Wu, Wang 2017 section 4: cloth particles are porous and hold water. One
// model per file, each a stage of the wetting pass after a step's last substep (src/sim/step.cpp;
// wetting.everySubstep: after every substep), in the order of Algorithm 1:
//   permeability.cpp  Eq. 22   coupling stiffness from saturation (before the coupling, every substep)
//   porosity.cpp      Eq. 10   particle volume, saturation, wet mass
//   absorption.cpp    Eq. 11   water particles soak into the cloth (gravity weighted)
//   diffusion.cpp     Eq. 12-17 water spreads inside the cloth (PBD projection, pairwise exchange)
//   emission.cpp      Eq. 18-19 excess water runs down, gathers and drips
//   sticking.cpp      Eq. 20   wet cloth sticks to itself
// Every stage returns at once when model.wetting.enabled (or its own switch) is off, keeps the water
// ledger exact (the cloth gains what the water loses) and gives the same result for any thread count.
#pragma once
#include <soak/model.hpp>
#include <soak/state.hpp>

#include "core/parallel.hpp"
#include "core/simd.hpp"
#include "grid/grid.hpp"
#include "world/colliders.hpp"

#include <cmath>
#include <string>
#include <vector>

namespace soak {

// cloth particles per chunk of the wetting loops scheduled dynamically (parallelForDynamic): the wet
// part of a cloth costs far more per particle than the dry part, and is rarely split evenly
constexpr int64_t kWetChunk = 256;

// scratch of the wetting stages, reused from pass to pass
struct WettingScratch {
  // per thread: the per-pair terms of one particle's neighbour loop; a vectorised loop writes them, a
  // scalar loop then sums them in list order (the order of the sums, and every result, stays that of
  // the scalar code)
  ThreadBuffers<float> pairFloat;
  ThreadBuffers<double> pairDouble;
  std::vector<float> volume;       // m^3, V_i of each cloth particle (Eq. 10) this pass
  std::vector<float> areaShare;    // A_i / wetting.referenceArea of each cloth particle (areaShare), this pass
  std::vector<float> capacity;     // kg a cloth particle can still absorb (Eq. 11)
  std::vector<float> clothScale;   // share of its requests a cloth particle grants (Eq. 11)
  std::vector<float> waterScale;   // share of its mass a water particle can give (Eq. 11)
  std::vector<double> waterLost;   // kg each water particle lost to the cloth this pass
  // absorption's stage 4: for each water particle that lost water, one slot per entry of its list's
  // cloth part from lostStart[water index]; then the slots of each cloth particle, water ascending
  std::vector<uint32_t> lostStart;  // per water particle (and one past the end): its first slot
  std::vector<double> gain;         // kg a slot's cloth particle gains (a share, then the gain)
  std::vector<uint8_t> absorber;    // the slot's cloth particle takes a share of the water's loss
  std::vector<uint32_t> gainStart;  // per thread and cloth particle: where its slots start in gainSlot
  std::vector<uint32_t> gainFirst;  // per cloth particle (and one past the end): its first slot in gainSlot
  std::vector<uint32_t> gainSlot;   // slots by cloth particle, water ascending
  std::vector<uint32_t> gainWater;  // the water particle of each of them
  std::vector<uint8_t> isDrip;     // water particles hanging as drips (not absorbed)
  std::vector<uint8_t> keep;       // 0 for water absorbed whole; compacted by finishWetting
  bool anyAbsorbedWhole = false;
  std::vector<double> delta;       // kg, change of held water or buffer of this pass
  // diffusion (Eq. 12-17 as a rate): per entry of a cloth particle's cloth part, like the pair geometry
  std::vector<float> diffusionNorm;    // nu of each piece, from the rest shape (computed once a run)
  std::vector<float> pairConductance;  // kg/s, T_ij = D nu V_i V_j lap W_ij / c (0 for another piece)
  std::vector<float> pairRise;         // m, z_j - z_i (up against gravity)
  std::vector<double> pairFlow;        // kg, the water entering i from j in one sub-step
  std::vector<float> lossRate;         // 1/s, the fastest a particle can lose its water
  std::vector<double> inScale;         // share of its inflow a particle has room for below S^MAX
  std::vector<uint8_t> wetPair;        // the particle or a cloth neighbour holds water (else no flow)
  std::vector<uint8_t> transfers;  // Eq. 18 holds for the particle
  std::vector<float> outScale;     // keeps a buffer's outflow within the buffer (Eq. 18)
  std::vector<int64_t> dripOf;     // index of the drip hanging from each cloth particle, -1 when none
  std::vector<int32_t> dripSources;  // cloth particles due a new drip this pass, in cloth order
  std::vector<int32_t> dripTry;      // per source: its first placement whose density before this pass's drips is at most rho0 (-1: none)
  std::vector<float> dripBase;       // per source: that density (kg/m^3)
  std::vector<Vec3> dripNormal;      // per source: its vertex normal (the placements' directions)
  std::vector<Vec3> force;         // N, sticking force per cloth particle (Eq. 20)
  // geometry of the cloth pairs at this pass's positions x (pairGeometry), one value per entry e of
  // the cloth part [start[i], clothEnd(i)) of a cloth particle i's neighbour list, j = index[e], with
  // h_ij = pairRadius(h_i, h_j) and x_ij = x_i - x_j; the other entries are not set. Porosity,
  // diffusion and emission read them instead of each taking a norm and divisions per pair.
  std::vector<float> pairPoly6;    // W_poly6(|x_ij|^2, h_ij) (Eq. 10, Eq. 18)
  std::vector<float> pairLap;      // lap W_visc(|x_ij|, h_ij) (Eq. 12)
  std::vector<float> pairCos;      // cos theta_ij = cosGravity(x_i, x_j, g); exactly -cos theta_ji
  std::vector<float> pairSpiky;    // f of grad W_spiky(x_ij, h_ij) = f x_ij (Eq. 18)
  bool pairsValid = false;         // set by updatePorosity, cleared by finishWetting
  const uint32_t* pairsList = nullptr;  // nb.index.data() of the lists they were computed for
  size_t pairsSize = 0;                 // and its size
};

// a rate per rateStep (0..1, a fraction removed per step) converted to a step of h seconds, so that n
// substeps of h = rateStep / n do what one step of rateStep does: 1 - (1 - kappa)^(h / rateStep)
inline float rateForStep(float kappa, float h, float rateStep) {
  if (kappa <= 0.0f) return 0.0f;
  if (kappa >= 1.0f) return 1.0f;
  return 1.0f - std::pow(1.0f - kappa, h / rateStep);
}

// unit gravity direction, zero when there is no gravity (then every gravity factor is 1)
inline Vec3 gravityDirection(const Model& model) {
  const float g = model.solver.gravity.norm();
  return g > 1e-12f ? Vec3(model.solver.gravity / g) : Vec3::Zero();
}

// cos theta_ij from (x_i - x_j) . g and |x_i - x_j| (0 for coincident particles); a select, for
// `omp simd` loops
inline float cosGravityOf(float dot, float len) { return simd::divideOrZero(len > 1e-12f, dot, len); }
// cos theta_ij of Shao 2017: the angle between x_i - x_j and gravity; positive when i lies below j
inline float cosGravity(const Vec3& xi, const Vec3& xj, const Vec3& gDir) {
  const Vec3 d = xi - xj;
  return cosGravityOf(d.dot(gDir), d.norm());
}

// porosity.cpp ------------------------------------------------------------------------------------

// V_i = 1 / sum_k W_ik over the cloth particles of the same piece within h of i, k including i (Eq. 10,
// Akinci et al. 2012), at the rest shape: used at load for the initial water and the checks
std::vector<float> restVolumes(const Model& model, const std::vector<float>& radius);

// sizes the wetting state of a loaded scene and fills the cloth with model.wetting.initialSaturation
// (counted as emitted in the ledger). volume: restVolumes of the cloth.
void initWettingState(const Model& model, const std::vector<float>& volume, State& state);

// V_i = 1 / sum_k W_ik (Eq. 10) of every cloth particle from neighbour lists built on positions x
void clothVolumes(const Model& model, const std::vector<Vec3>& x, const std::vector<float>& radius,
                  const std::vector<int32_t>& phase, const NeighborLists& nb, std::vector<float>& volume);

// Eq. 10 at this pass's positions: V_i, S_i = c m^water_i / V_i, and the wet mass
// m_i = dry + held + buffer (pinned particles keep inverse mass 0). Held water beyond S^MAX V_i / c
// (the cloth was squeezed: V_i shrank) moves to the buffer, so S_i <= S^MAX.
void updatePorosity(const Model& model, State& state, const NeighborLists& nb, WettingScratch& s);

// fills the pair geometry of the scratch (WettingScratch::pairPoly6 ...) for the cloth pairs of nb at
// the positions p.x (one vectorised pass); updatePorosity calls it, and diffusion and emission call
// ensurePairGeometry, which computes it only when the scratch holds none for these lists (a stage
// run on its own, as in the tests). Positions must not change between updatePorosity and the stages
// that read the pairs (they do not within a pass: x is committed before the wetting stages).
void pairGeometry(const Model& model, const Particles& p, const NeighborLists& nb, WettingScratch& s);
void ensurePairGeometry(const Model& model, const Particles& p, const NeighborLists& nb, WettingScratch& s);

// the one home of a cloth particle's mass: m_i = dry + held + buffer (pinned particles stay
// kinematic); every stage that moves water calls it for the particles it changed
void setWetMass(const Model& model, State& state, int64_t i);
// setWetMass of every cloth particle
void updateWetMasses(const Model& model, State& state);

// S_i = c m / V_i (Eq. 10) of one cloth particle: the one expression every stage that changes the held
// water uses, so S_i is bit for bit the same wherever it is updated
inline float saturationOf(double c, double heldWater, float volume) { return static_cast<float>(c * heldWater / volume); }
// the most water a cloth particle of volume V_i holds, S^MAX V_i / c (Eq. 10 at S = S^MAX)
inline double mostHeldWater(const WettingParams& w, float volume) {
  return static_cast<double>(w.saturationMax) * volume / w.c;
}

// S_i = c m / V_i for the held water of every cloth particle
void computeSaturation(const Model& model, const State& state, const WettingScratch& s, std::vector<float>& sat);

// permeability.cpp --------------------------------------------------------------------------------

// Eq. 22: kappa^couple = clamp(1 - (S~a + S~b + S~c) / (3 (S^MAX - S^T)), 0, 1), S~ = max(0, S - S^T),
// per triangle from the saturations of the last wetting stage; 1 everywhere when wetting is off
void updateCouplingStiffness(const Model& model, const State& state, std::vector<float>& triangleStiffness);
float couplingStiffness(const WettingParams& w, float sa, float sb, float sc);

// the same factor per cloth particle, kappa^couple(S_i, S_i, S_i), applied to its Akinci boundary mass
// Psi_i in the water's density: a soaked particle no longer holds water up (docs/models.md)
void scaleBoundaryByPermeability(const Model& model, const State& state, std::vector<float>& psi);

// absorption.cpp ----------------------------------------------------------------------------------

// Eq. 11 with the corrections of NOTES.md: water particle j gives its cloth neighbours i up to
// kappa^a (1 + eta^a cos theta_ij) (S^MAX - S_i) V_i / c each; a particle left lighter than the
// minimum mass is absorbed whole (marked in s.keep, removed by finishWetting), else it shrinks to
// h' = (m'/m0)^(1/3) h0. Returns the number of particles absorbed whole. Uses p.x (after the commit).
size_t absorbWater(const Model& model, State& state, const NeighborLists& nb, WettingScratch& s, float h);

// removes the water absorbed whole (stable compaction, ids kept) and brings the ledger's held and
// buffered totals up to date; the last wetting stage of a pass
void finishWetting(const Model& model, State& state, WettingScratch& s);

// diffusion.cpp -----------------------------------------------------------------------------------

// Eq. 12-17 as a rate in time with a capillary equilibrium (docs/models.md, "Diffusion"): held water
// moves between neighbouring particles of the same piece at q_{j->i} = T_ij (1 + eta^d cos)
// [(S_j - S_i) + lambda S_up (z_j - z_i)], conserved exactly, S_i kept <= S^MAX; over h seconds in
// explicit sub-steps. Returns the number of sub-steps (0 when nothing is held).
int diffuseWater(const Model& model, State& state, const NeighborLists& nb, WettingScratch& s, float h);

// the water entering i from j over tau seconds (kg): T_ij (1 + eta^d cos) [(S_j - S_i) + lambda S_up
// (z_j - z_i)] tau, S_up of the higher particle, cos = cos theta_ij taken along the flow (> 0 going
// down); rise = z_j - z_i. Exactly minus the value seen from j, so the held total is conserved
inline double diffusionFlow(double tau, float conductance, float eta, float cosIJ, float si, float sj, float lambda,
                            float rise) {
  const double sUp = rise > 0.0f ? sj : si;
  const double push = (static_cast<double>(sj) - si) + static_cast<double>(lambda) * sUp * rise;
  const float cosFlow = push > 0.0 ? cosIJ : -cosIJ;
  return tau * conductance * (1.0 + static_cast<double>(eta * cosFlow)) * push;
}

// explicit sub-steps for a pass of h seconds when no particle may lose water faster than lossRate (1/s):
// tau lossRate <= 1/2, times iterations (wetting.diffusion.iterations, for accuracy)
int diffusionSubsteps(float lossRate, float h, int iterations);

// emission.cpp ------------------------------------------------------------------------------------

// Eq. 18's flow from the buffer of an upper particle u to a lower neighbour l over a pass, before u's
// outflow scale: rate cos theta_lu V_u W_lu EW_u (kg), cos theta_lu > 0 (l below u). The one formula
// of the outflow and the net-flow loops, so that the water leaving u is the water arriving at l
inline double bufferFlow(double rate, float cosLU, float volumeU, float w, double bufferU) {
  return rate * static_cast<double>(cosLU * (volumeU * w)) * bufferU;
}

// section 4.4: water above S^EW moves into the buffer; buffers pass down to the neighbours below when
// Eq. 18 holds; a buffer that reaches m^threshold forms a drip below the cloth (placed where its
// density is not above rest and clear of every collider at `poses` by the water's contact margin), and
// feeds the drip hanging from it. Returns the number of drips created.
size_t emitExcessWater(const Model& model, State& state, const NeighborLists& nb, const NeighborGrid& grid,
                       const std::vector<ColliderPose>& poses, WettingScratch& s, float h);

// the particle index of each drip of state.dripId, -1 for one that is gone; the water particles may be
// in any order (they are sorted by cell from time to time), so this does not rely on ids ascending
void findDrips(const Model& model, const State& state, std::vector<int64_t>& index);

// Eq. 19: the cloth around a drip pulls it (and is pulled back) until it is heavy enough to fall
void applyDripAttraction(const Model& model, State& state, const NeighborLists& nb, const WettingScratch& s,
                         float h);

// a cloth particle's share of the amounts the scene gives per wetting.referenceArea of cloth
// (m^threshold and eta^e; per pair, both shares times eta^ad and kappa^ad): its rest area A_i over
// referenceArea, so a finer mesh of the same cloth drips and sticks alike; 1 when referenceArea is 0
// (per particle, as Table 1 prints them; departure: docs/models.md)
inline float areaShare(float referenceArea, float restArea) {
  return referenceArea > 0.0f ? restArea / referenceArea : 1.0f;
}

// kg, the m^threshold of a cloth particle of that share: a buffer this full makes a drip of this mass
// and takes no more water
inline float dripThreshold(float massThreshold, float share) { return massThreshold * share; }
inline float dripThreshold(const WettingParams& w, float share) { return dripThreshold(w.massThreshold, share); }

// sticking.cpp ------------------------------------------------------------------------------------

// Eq. 20 coefficient of a touching pair, N: (eta^ad - kappa^ad |(S_i - S^T)(S_j - S^T)|)+, times a
// wetness ramp min(1, S/S^T) of each particle so dry cloth does not stick; largest at S^T; 0 when
// either particle is dry. Selects only: applySticking's vectorised loop calls it too
inline float stickingCoefficient(float si, float sj, float st, float strength, float rate) {
  const float fc = strength - rate * std::fabs((si - st) * (sj - st));
  const float rampI = si / st < 1.0f ? si / st : 1.0f, rampJ = sj / st < 1.0f ? sj / st : 1.0f;
  const float coef = fc * (st > 0.0f ? rampI * rampJ : 1.0f);
  return ((si > 0.0f) & (sj > 0.0f) & (fc > 0.0f) & (coef > 0.0f)) ? coef : 0.0f;
}
inline float stickingCoefficient(const WettingParams& w, float si, float sj) {
  return stickingCoefficient(si, sj, w.saturationSticky, w.stickingStrength, w.stickingRate);
}

// Eq. 20 between touching wet cloth particles (those far apart on the rest shape), applied to the
// velocities; equal and opposite per pair
void applySticking(const Model& model, State& state, const NeighborLists& nb, WettingScratch& s, float h);

// output.cpp --------------------------------------------------------------------------------------

// vertex colours of the cloth by saturation S / S^MAX: "red" fades red to black (Fig. 3), "green" green
// to black (Fig. 4); empty for "none" or when wetting is off
std::vector<Vec3> saturationColors(const Model& model, const State& state, const std::string& ramp);
// the same ramp for any per-vertex value: valueMax is drawn black (fully wet), 0 in the ramp's colour
std::vector<Vec3> rampColors(const std::vector<float>& value, float valueMax, const std::string& ramp);
// one value of the ramp, linear in value / valueMax (clamped to [0, 1]); a ramp other than "green" is red.
// Display (sRGB) values: POV-Ray is given them as `srgb`, an OBJ viewer shows them as they are
Vec3 rampColor(const std::string& ramp, float value, float valueMax);

}  // namespace soak
