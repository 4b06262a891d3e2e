// Chen 2012 stages of the step: implicit garment solve, saturation mass, wet signal (stage.hpp)
#include "garment/stage.hpp"

#include "core/parallel.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace soak {

namespace {

std::span<const float> pieceWetStart(const State& state, const ClothPiece& piece) {
  if (state.clothWetStart.size() < static_cast<size_t>(piece.firstParticle + piece.particleCount)) return {};
  return std::span<const float>(state.clothWetStart).subspan(static_cast<size_t>(piece.firstParticle),
                                                             static_cast<size_t>(piece.particleCount));
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
  if (state.clothWetStart.size() != wet.size()) return wet;
  for (const ClothPiece& piece : model.pieces) {
    if (!piece.wetByContact) continue;
    const SaturationParams& s = piece.garment.saturation;
    for (int i = piece.firstParticle; i < piece.firstParticle + piece.particleCount; ++i) {
      const float start = state.clothWetStart[size_t(i)];
      if (!std::isfinite(start)) continue;
      wet[size_t(i)] = s.delta > 0.0f ? static_cast<float>(absorbedRatio(state.time - start, s) / s.delta) : 1.0f;
    }
  }
  return wet;
}

float touchDistance(const Model& model, const ClothPiece& piece) {
  return piece.material.thickness + model.water.spacing;
}

void solveGarments(const Model& model, State& state, GarmentScratch& s, const std::vector<ColliderPose>& poses,
                   float h, StepStats& stats) {
  Particles& p = state.particles;
  s.scratch.resize(model.pieces.size());
  GarmentStats& gs = stats.garment;
  for (size_t k = 0; k < model.pieces.size(); ++k) {
    const ClothPiece& piece = model.pieces[k];
    const std::span<const float> wetStart = pieceWetStart(state, piece);
    if (piece.solver != ClothSolver::Implicit) {
      if (piece.garment.saturationMass)  // Eq. 15-19 on a PBD piece: heavier once wet
        applySaturationMass(model, static_cast<int>(k), wetStart, state.time, piece.garment.saturation, p);
      continue;
    }
    if (!piece.implicit) continue;  // a Model built without the loader's buildGarmentPieces
    const ImplicitStats r = garmentSubstep(model, *piece.implicit, piece.garment, wetStart, state.time, h,
                                           state.stepCount, poses, p, s.scratch[k]);
    ++gs.solves;
    gs.cgIterations += static_cast<uint64_t>(r.cgIterations);
    gs.cgIterationsMax = std::max(gs.cgIterationsMax, r.cgIterations);
    gs.maxResidual = std::max(gs.maxResidual, r.cgResidual);
    gs.unconverged += r.converged ? 0 : 1;
    gs.breakdowns += r.breakdown ? 1 : 0;
    gs.contacts += static_cast<uint64_t>(r.contacts);
    gs.edgeContacts += static_cast<uint64_t>(r.edgeContacts);
    gs.disturbances += static_cast<uint64_t>(r.disturbances);
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

size_t wetClothByContact(const Model& model, State& state, const NeighborLists& nb, GarmentScratch& s,
                         std::vector<uint8_t>& keep, double time) {
  // no cloth, or no piece wetted by contact (clothWetStart is then empty)
  if (model.numCloth == 0 || state.clothWetStart.size() != static_cast<size_t>(model.numCloth)) return 0;
  Particles& p = state.particles;
  const int64_t nc = model.numCloth;
  const float now = static_cast<float>(time);
  auto wettable = [&](int64_t i) { return model.pieces[size_t(clothPiece(p.phase[i]))].wetByContact; };
  if (model.wetting.enabled) {  // Shao's absorption carries the water: wet once it holds some
    for (int64_t i = 0; i < nc; ++i)
      if (wettable(i) && state.clothWater[size_t(i)] > 0.0 && !std::isfinite(state.clothWetStart[size_t(i)]))
        state.clothWetStart[size_t(i)] = now;
    return 0;
  }
  const int64_t n = static_cast<int64_t>(p.size());
  if (n == nc || nb.start.size() < static_cast<size_t>(n) + 1) return 0;
  // each water particle finds the nearest wettable cloth vertex within touch distance (gather)
  s.touch.assign(static_cast<size_t>(n), -1);
  parallelFor(n - nc, [&](int64_t jj) {
    const int64_t j = nc + jj;
    float best = std::numeric_limits<float>::infinity();
    int32_t hit = -1;
    for (uint32_t e = nb.start[size_t(j)]; e < nb.start[size_t(j) + 1]; ++e) {
      const int64_t i = nb.index[e];
      if (i >= nc || !wettable(i)) continue;
      const float d = (p.x[size_t(i)] - p.x[size_t(j)]).norm();
      const float reach = touchDistance(model, model.pieces[size_t(clothPiece(p.phase[i]))]);
      if (d < reach && d < best) {
        best = d;
        hit = static_cast<int32_t>(i);
      }
    }
    s.touch[size_t(j)] = hit;
  });
  // a cloth vertex is wet when any water particle is within reach of it (the particle's footprint)
  parallelFor(nc, [&](int64_t i) {
    if (!wettable(i) || std::isfinite(state.clothWetStart[size_t(i)])) return;
    const float reach = touchDistance(model, model.pieces[size_t(clothPiece(p.phase[i]))]);
    for (uint32_t e = nb.start[size_t(i)]; e < nb.start[size_t(i) + 1]; ++e) {
      const int64_t j = nb.index[e];
      if (j >= nc && s.touch[size_t(j)] >= 0 && (p.x[size_t(i)] - p.x[size_t(j)]).norm() < reach) {
        state.clothWetStart[size_t(i)] = now;
        return;
      }
    }
  });
  // the particles that touched a piece with dropsVanish go, in particle order (deterministic)
  keep.assign(static_cast<size_t>(n), 1);
  size_t taken = 0;
  for (int64_t j = nc; j < n; ++j) {
    const int32_t i = s.touch[size_t(j)];
    if (i < 0 || !model.pieces[size_t(clothPiece(p.phase[i]))].dropsVanish) continue;
    keep[size_t(j)] = 0;
    state.ledger.takenByCloth += p.mass[size_t(j)];
    ++taken;
  }
  state.ledger.particlesTakenByCloth += taken;
  if (taken) p.compact(keep);
  return taken;
}

}  // namespace soak
