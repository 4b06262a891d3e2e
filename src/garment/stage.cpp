// Chen 2012 stages of the step: implicit garment solve, saturation mass, wet signal (stage.hpp)
#include "garment/stage.hpp"

#include "core/parallel.hpp"
#include "pbd/integrate.hpp"
#include "world/garment_mesh.hpp"
#include "world/mesh_distance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <span>

namespace soak {

namespace {

// each vertex's saturation in [0, 1] for the piece (piece-local): Chen's s = absorbed / (delta m_dry)
// from State::clothSaturation, or with Shao's wetting on S / S^MAX; empty when the piece keeps none
std::span<const float> pieceSaturation(const Model& model, const State& state, const ClothPiece& piece,
                                       std::vector<float>& fraction) {
  const size_t first = static_cast<size_t>(piece.firstParticle), n = static_cast<size_t>(piece.particleCount);
  if (state.clothSaturation.size() < first + n) return {};
  const std::span<const float> s = std::span<const float>(state.clothSaturation).subspan(first, n);
  if (!model.wetting.enabled) return s;
  fraction.resize(n);
  const float inv = model.wetting.saturationMax > 0.0f ? 1.0f / model.wetting.saturationMax : 0.0f;
  for (size_t v = 0; v < n; ++v) fraction[v] = std::min(s[v] * inv, 1.0f);
  return fraction;
}

// the water a vertex still takes: unlimited supply always, else while it holds less than delta m_dry
bool takesWater(const Model& model, const State& state, const ClothPiece& piece, int64_t i) {
  if (!piece.wetByContact) return false;
  const SaturationParams& sat = piece.garment.saturation;
  return sat.unlimitedSupply || state.clothWater[size_t(i)] < waterCapacity(model.clothDryMass[size_t(i)], sat);
}

// the vertex of triangle t nearest x among those that take water, or -1
int32_t nearestTakingVertex(const Model& model, const State& state, const ClothPiece& piece, uint32_t t, const Vec3& x) {
  int32_t best = -1;
  float bestD2 = std::numeric_limits<float>::infinity();
  for (int v : model.triangles[t]) {
    const float d2 = (state.particles.x[size_t(v)] - x).squaredNorm();
    if (d2 < bestD2 && takesWater(model, state, piece, v)) {
      bestD2 = d2;
      best = v;
    }
  }
  return best;
}

// each water particle's touch: the cloth vertex that takes water nearest to it within touch distance
// (its neighbours), or, nearer still, a triangle of its path's coupling candidates whose surface is
// within touch distance, at that triangle's nearest vertex that takes water; -1 where none (gather).
// The triangles make the catch independent of the step: a drop the coupling stopped on the fabric
// lies within the thickness of its surface but may be an edge length from every vertex.
void findTouches(const Model& model, const State& state, const NeighborLists& nb, const DropCandidates& candidates,
                 std::vector<int32_t>& touch) {
  const Particles& p = state.particles;
  const int64_t n = static_cast<int64_t>(p.size()), nc = model.numCloth;
  const bool paths = candidates.start.size() == static_cast<size_t>(n - nc) + 1;  // searched for these particles
  touch.assign(static_cast<size_t>(n), -1);
  parallelFor(n - nc, [&](int64_t jj) {
    const int64_t j = nc + jj;
    float best = std::numeric_limits<float>::infinity();
    int32_t hit = -1;
    for (uint32_t e = nb.start[size_t(j)]; e < nb.start[size_t(j) + 1]; ++e) {
      const int64_t i = nb.index[e];
      if (i >= nc) continue;
      const ClothPiece& piece = model.pieces[size_t(clothPiece(p.phase[i]))];
      if (!takesWater(model, state, piece, i)) continue;
      const float d = (p.x[size_t(i)] - p.x[size_t(j)]).norm();
      if (d < touchDistance(model, piece) && d < best) {
        best = d;
        hit = static_cast<int32_t>(i);
      }
    }
    const uint32_t first = paths ? candidates.start[size_t(jj)] : 0, last = paths ? candidates.start[size_t(jj) + 1] : 0;
    const Vec3d xj = p.x[size_t(j)].cast<double>();
    for (uint32_t c = first; c < last; ++c) {
      const uint32_t t = candidates.triangles[c];
      const auto& f = model.triangles[t];
      const ClothPiece& piece = model.pieces[size_t(clothPiece(p.phase[f[0]]))];
      if (!piece.wetByContact) continue;
      int feature = 0;  // which part of the triangle is nearest: not needed here
      const Vec3d q = closestOnTriangle(xj, p.x[f[0]].cast<double>(), p.x[f[1]].cast<double>(),
                                        p.x[f[2]].cast<double>(), &feature);
      const float d = static_cast<float>((q - xj).norm());
      if (!(d < touchDistance(model, piece) && d < best)) continue;
      const int32_t v = nearestTakingVertex(model, state, piece, t, q.cast<float>());
      if (v < 0) continue;
      best = d;
      hit = v;
    }
    touch[size_t(j)] = hit;
  });
}

// soaks a drop of m kg into the fabric around vertex i (drops supply): the vertices of the piece
// with room, breadth first over the mesh from i, each filled up to delta m_dry, until the drop is
// in (a drop heavier than one vertex holds spreads over the spot it wets). False, with nothing
// changed, when the nearest kMaxSoakVertices vertices have no room for all of it.
bool soakDrop(const Model& model, State& state, int32_t i, double m, float now, GarmentScratch& s) {
  constexpr size_t kMaxSoakVertices = 256;
  const SaturationParams& sat = model.pieces[size_t(clothPiece(state.particles.phase[i]))].garment.saturation;
  s.soakOrder.assign(1, i);
  s.soakSeen.resize(static_cast<size_t>(model.numCloth), 0);
  s.soakSeen[size_t(i)] = 1;
  double room = 0.0;
  for (size_t k = 0; k < s.soakOrder.size() && room < m && k < kMaxSoakVertices; ++k) {
    const int v = s.soakOrder[k];
    room += std::max(0.0, waterCapacity(model.clothDryMass[size_t(v)], sat) - state.clothWater[size_t(v)]);
    for (int e = model.vertexNeighborStart[size_t(v)]; e < model.vertexNeighborStart[size_t(v) + 1]; ++e) {
      const int w = model.vertexNeighbors[size_t(e)];
      if (!s.soakSeen[size_t(w)]) {
        s.soakSeen[size_t(w)] = 1;
        s.soakOrder.push_back(w);
      }
    }
  }
  for (int v : s.soakOrder) s.soakSeen[size_t(v)] = 0;
  if (room < m) return false;
  for (size_t k = 0; k < s.soakOrder.size() && m > 0.0; ++k) {
    const size_t v = static_cast<size_t>(s.soakOrder[k]);
    const double put = std::min(m, std::max(0.0, waterCapacity(model.clothDryMass[v], sat) - state.clothWater[v]));
    if (!(put > 0.0)) continue;
    state.clothWater[v] += put;
    m -= put;
    if (!std::isfinite(state.clothWetStart[v])) state.clothWetStart[v] = now;
  }
  return true;
}

// the touching particles go, in particle order (deterministic): into the fabric around the vertex
// (soakDrop; a drop the fabric there has no room for stays and runs off), or with an unlimited
// supply and dropsVanish out of the simulation (counted in WaterLedger::takenByCloth)
size_t takeTouchingWater(const Model& model, State& state, GarmentScratch& s, float now, std::vector<uint8_t>& keep) {
  Particles& p = state.particles;
  const int64_t n = static_cast<int64_t>(p.size());
  keep.assign(static_cast<size_t>(n), 1);
  size_t taken = 0;
  for (int64_t j = model.numCloth; j < n; ++j) {
    const int32_t i = s.touch[size_t(j)];
    if (i < 0) continue;
    const ClothPiece& piece = model.pieces[size_t(clothPiece(p.phase[i]))];
    if (piece.garment.saturation.unlimitedSupply) {
      if (!piece.dropsVanish) continue;
      state.ledger.takenByCloth += p.mass[size_t(j)];
    } else if (!soakDrop(model, state, i, p.mass[size_t(j)], now, s)) {
      continue;
    }
    keep[size_t(j)] = 0;
    ++taken;
  }
  state.ledger.particlesTakenByCloth += taken;
  if (taken) p.compact(keep);
  return taken;
}

}  // namespace

void buildGarmentPieces(Model& model) {
  std::vector<std::shared_ptr<const GarmentPiece>> built(model.pieces.size());
  for (size_t k = 0; k < model.pieces.size(); ++k) {
    const ClothPiece& piece = model.pieces[k];
    if (piece.solver != ClothSolver::Implicit) continue;
    GarmentPiece g = buildGarmentPiece(model, static_cast<int>(k), piece.garment);
    if (piece.panelOfVertex.size() == static_cast<size_t>(piece.particleCount)) {
      // section 3.5: "we first divide the garment in several subdomains according to the cloth pattern"
      std::map<int, std::vector<int>> panels;
      for (int v = 0; v < piece.particleCount; ++v) panels[piece.panelOfVertex[v]].push_back(v);
      g.subdomains.clear();
      for (auto& [id, vertices] : panels) g.subdomains.push_back(std::move(vertices));
    }
    built[k] = std::make_shared<const GarmentPiece>(std::move(g));
  }
  for (size_t k = 0; k < model.pieces.size(); ++k) model.pieces[k].implicit = std::move(built[k]);
}

std::vector<float> clothWetness(const Model& model, const State& state) {
  std::vector<float> wet(static_cast<size_t>(model.numCloth), 0.0f);
  std::vector<float> fraction;
  for (const ClothPiece& piece : model.pieces) {
    if (!piece.wetByContact) continue;
    const std::span<const float> s = pieceSaturation(model, state, piece, fraction);
    std::copy(s.begin(), s.end(), wet.begin() + piece.firstParticle);
  }
  return wet;
}

GarmentShape garmentShape(const Model& model, const State& state) {
  GarmentShape g;
  const std::vector<float> wet = clothWetness(model, state);
  double lowest = std::numeric_limits<double>::infinity(), height = 0.0, distance = 0.0, saturation = 0.0;
  const PosedBody body(model.colliders, state.time);
  for (const ClothPiece& piece : model.pieces) {
    if (piece.solver != ClothSolver::Implicit && !piece.wetByContact) continue;
    for (int i = piece.firstParticle; i < piece.firstParticle + piece.particleCount; ++i) {
      const Vec3& x = state.particles.x[size_t(i)];
      lowest = std::min(lowest, double(x.y()));
      height += x.y();
      if (!model.colliders.empty()) distance += body.distance(x, nullptr);
      saturation += wet[size_t(i)];
      ++g.vertices;
    }
  }
  if (g.vertices == 0) return g;
  g.lowest = lowest;
  g.meanHeight = height / g.vertices;
  g.meanColliderDistance = distance / g.vertices;
  g.meanSaturation = saturation / g.vertices;
  return g;
}

float touchDistance(const Model& model, const ClothPiece& piece) {
  return piece.material.thickness + model.water.spacing;
}

namespace {

// a step's cost (CG iterations and wall time) into the frame's statistics: also a step that was redone
void addStepCost(const ImplicitStats& r, StepStats& stats) {
  stats.garment.cgIterations += static_cast<uint64_t>(r.cgIterations);
  stats.garment.cgIterationsMax = std::max(stats.garment.cgIterationsMax, r.cgIterations);
  stats.ms.part(StagePart::garmentAssemble) += r.msAssemble;
  stats.ms.part(StagePart::garmentCg) += r.msCg;
  stats.ms.part(StagePart::garmentIntegrate) += r.msIntegrate;
  stats.ms.part(StagePart::garmentSelfContact) += r.msSelfContact;
}

// a step kept: its cost and what it did
void addStepStats(const ImplicitStats& r, StepStats& stats) {
  addStepCost(r, stats);
  GarmentStats& gs = stats.garment;
  ++gs.solves;
  gs.maxResidual = std::max(gs.maxResidual, r.cgResidual);
  gs.unconverged += r.converged ? 0 : 1;
  gs.breakdowns += r.breakdown ? 1 : 0;
  gs.factorFailures += r.factorFailed ? 1 : 0;
  gs.contacts += static_cast<uint64_t>(r.contacts);
  gs.contactRows += static_cast<uint64_t>(r.contactRows);
  gs.stickingRows += static_cast<uint64_t>(r.stickingRows);
  gs.edgeContacts += static_cast<uint64_t>(r.edgeContacts);
  gs.selfContacts += static_cast<uint64_t>(r.selfContacts);
  gs.selfEdgeContacts += static_cast<uint64_t>(r.selfEdgeContacts);
  gs.selfReverted += static_cast<uint64_t>(r.selfReverted);
  gs.disturbances += static_cast<uint64_t>(r.disturbances);
  gs.maxStrain = std::max(gs.maxStrain, r.maxStrain);
  gs.strainLimited += static_cast<uint64_t>(r.strainLimited);
}

float fastestOf(const Particles& p, size_t first, size_t count) {
  float fastest = 0.0f;
  for (size_t i = first; i < first + count; ++i) fastest = std::max(fastest, p.v[i].norm());
  return fastest;
}

}  // namespace

void stepPiece(const Model& model, State& state, GarmentScratch& s, size_t k, const PieceStepInputs& in, float h,
               StepStats& stats) {
  const ClothPiece& piece = model.pieces[k];
  Particles& p = state.particles;
  const size_t first = static_cast<size_t>(piece.firstParticle), n = static_cast<size_t>(piece.particleCount);
  const auto run = [&](float hp, double time, const std::vector<ColliderPose>& poses) {
    s.steps.push_back(garmentSubstep(model, *piece.implicit, piece.garment, in.saturation, hp, time, state.stepCount,
                                     poses, p, s.scratch[k], in.velocityChange));
  };
  s.startV.assign(p.v.begin() + first, p.v.begin() + first + n);  // the step overwrites v, not x
  s.startDv.assign(in.velocityChange.begin(), in.velocityChange.end());
  s.steps.clear();
  run(h, state.time, in.poses);
  // departure: a step that leaves a vertex faster than solver.maxSpeed, which would end the run as
  // diverged, is redone from its start as 2, 4, then 8 steps (docs/garment.md departure 4)
  for (int level = 1; level <= kMaxHalvings && fastestOf(p, first, n) > model.solver.maxSpeed; ++level) {
    for (const ImplicitStats& r : s.steps) addStepCost(r, stats);  // the steps dropped
    s.steps.clear();
    ++stats.garment.halvedSteps;
    if (level == 1) s.startX.assign(p.x.begin() + first, p.x.begin() + first + n);  // the parts move x on
    const int parts = 1 << level;
    const float hp = h / static_cast<float>(parts);
    std::copy(s.startV.begin(), s.startV.end(), p.v.begin() + first);
    std::copy(s.startDv.begin(), s.startDv.end(), in.velocityChange.begin());
    for (int part = 0; part < parts; ++part) {
      const double time = state.time + part * static_cast<double>(hp);
      updateColliderPoses(model, time + hp, in.colliderKeys, s.partPoses);
      if (part > 0) std::copy(p.xPred.begin() + first, p.xPred.begin() + first + n, p.x.begin() + first);
      run(hp, time, s.partPoses);
    }
    std::copy(s.startX.begin(), s.startX.end(), p.x.begin() + first);  // the substep's start, for the commit
  }
  for (const ImplicitStats& r : s.steps) addStepStats(r, stats);
}

void solveGarments(const Model& model, State& state, GarmentScratch& s, const std::vector<ColliderPose>& poses,
                   std::span<const std::vector<Keyframe>> colliderKeys, float h, StepStats& stats) {
  Particles& p = state.particles;
  s.scratch.resize(model.pieces.size());
  for (size_t k = 0; k < model.pieces.size(); ++k) {
    const ClothPiece& piece = model.pieces[k];
    if (piece.wetByContact && !model.wetting.enabled && !state.clothSaturation.empty())
      updateSaturation(model, static_cast<int>(k), piece.garment.saturation, state.time, h, state);  // Eq. 18
    const std::span<const float> saturation = pieceSaturation(model, state, piece, s.fraction);
    if (piece.solver != ClothSolver::Implicit) {
      if (piece.garment.saturationMass)  // Eq. 15-19 on a PBD piece: heavier once wet
        applySaturationMass(model, static_cast<int>(k), saturation, piece.garment.saturation, p);
      continue;
    }
    if (!piece.implicit) continue;  // a Model built without the loader's buildGarmentPieces
    const std::span<Vec3> velocityChange =
        state.clothVelocityChange.empty()
            ? std::span<Vec3>()
            : std::span<Vec3>(state.clothVelocityChange).subspan(size_t(piece.firstParticle), size_t(piece.particleCount));
    stepPiece(model, state, s, k, {saturation, velocityChange, poses, colliderKeys}, h, stats);
  }
  if (!model.hasImplicitCloth()) return;
  // remember where the solve put the implicit cloth, so the coupling's push can become velocity
  s.solved.resize(static_cast<size_t>(model.numCloth));
  for (int64_t i = 0; i < model.numCloth; ++i)
    if (model.implicitCloth(i)) s.solved[size_t(i)] = p.xPred[size_t(i)];
}

void addCouplingVelocity(const Model& model, Particles& p, const GarmentScratch& s, float h) {
  if (!model.hasImplicitCloth() || s.solved.size() < static_cast<size_t>(model.numCloth)) return;
  const float inv = 1.0f / h;
  parallelFor(model.numCloth, [&](int64_t i) {
    if (!model.implicitCloth(i)) return;
    if (!model.wetting.enabled && model.pieces[size_t(clothPiece(p.phase[i]))].dropsVanish) {
      p.xPred[i] = s.solved[size_t(i)];  // drops vanish into it: they do not push it (docs/models.md)
      return;
    }
    p.v[i] += (p.xPred[i] - s.solved[size_t(i)]) * inv;
  });
}

size_t wetClothByContact(const Model& model, State& state, const NeighborLists& nb, const DropCandidates& candidates,
                         GarmentScratch& s, std::vector<uint8_t>& keep, double time) {
  // no cloth, or no piece wetted by contact (clothWetStart is then empty)
  if (model.numCloth == 0 || state.clothWetStart.size() != static_cast<size_t>(model.numCloth)) return 0;
  const Particles& p = state.particles;
  const int64_t nc = model.numCloth;
  const float now = static_cast<float>(time);
  if (model.wetting.enabled) {  // Shao's absorption carries the water: wet once it holds some
    for (int64_t i = 0; i < nc; ++i)
      if (model.pieces[size_t(clothPiece(p.phase[i]))].wetByContact && state.clothWater[size_t(i)] > 0.0 &&
          !std::isfinite(state.clothWetStart[size_t(i)]))
        state.clothWetStart[size_t(i)] = now;
    return 0;
  }
  const int64_t n = static_cast<int64_t>(p.size());
  if (n == nc || nb.start.size() < static_cast<size_t>(n) + 1) return 0;
  findTouches(model, state, nb, candidates, s.touch);
  // unlimited supply (Chen as printed): a vertex is wet when any water particle is within reach of it
  parallelFor(nc, [&](int64_t i) {
    const ClothPiece& piece = model.pieces[size_t(clothPiece(p.phase[i]))];
    if (!piece.wetByContact || !piece.garment.saturation.unlimitedSupply || std::isfinite(state.clothWetStart[size_t(i)]))
      return;
    const float reach = touchDistance(model, piece);
    for (uint32_t e = nb.start[size_t(i)]; e < nb.start[size_t(i) + 1]; ++e) {
      const int64_t j = nb.index[e];
      if (j >= nc && s.touch[size_t(j)] >= 0 && (p.x[size_t(i)] - p.x[size_t(j)]).norm() < reach) {
        state.clothWetStart[size_t(i)] = now;
        return;
      }
    }
  });
  for (int64_t j = nc; j < n; ++j) {  // and the vertex a particle touched, through a triangle too
    const int32_t i = s.touch[size_t(j)];
    if (i >= 0 && model.pieces[size_t(clothPiece(p.phase[i]))].garment.saturation.unlimitedSupply &&
        !std::isfinite(state.clothWetStart[size_t(i)]))
      state.clothWetStart[size_t(i)] = now;
  }
  return takeTouchingWater(model, state, s, now, keep);
}

}  // namespace soak
