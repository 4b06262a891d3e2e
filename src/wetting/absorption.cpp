// water absorption, section 4.2 of Shao et al. 2017 (Eq. 11): a cloth particle i soaks up to
//   m_i^absorbed = kappa^a (1 + eta^a cos theta_ij) (S^MAX - S_i) V_i / c
// from each neighbouring water particle j, more from water above it than below it. As NOTES.md reads
// Eq. 11, the cloth gains exactly the mass the water loses; a shrunken particle keeps
// h' = (m'/m0)^(1/3) h0, and one left below the minimum mass is absorbed whole. The 1/c turns Eq. 11's
// saturation volume into kilograms (S = c m / V, Eq. 10).
#include "wetting/wetting.hpp"

#include "core/parallel.hpp"

#include <algorithm>
#include <cmath>

#include <omp.h>

namespace soak {

namespace {

// marks the water particles hanging as drips (section 4.4): they are held by Eq. 19, not soaked up
void markDrips(const Model& model, const State& state, std::vector<uint8_t>& isDrip) {
  const Particles& p = state.particles;
  isDrip.assign(p.size(), 0);
  std::vector<int64_t> index;
  findDrips(model, state, index);
  for (const int64_t q : index)
    if (q >= 0) isDrip[static_cast<size_t>(q)] = 1;
}

// Eq. 11's request: the most cloth particle i may take from water particle j this pass (kg)
struct Requests {
  const Particles& p;
  const std::vector<float>& capacity;
  float kappa, eta;
  Vec3 g;
  float operator()(int64_t i, int64_t j) const {
    return kappa * (1.0f + eta * cosGravity(p.x[i], p.x[j], g)) * capacity[i];
  }
};

// what each cloth particle can still take, kg: (S^MAX - S_i) V_i / c, the buffer counting as held
void clothCapacity(const Model& model, const State& state, WettingScratch& s) {
  const WettingParams& w = model.wetting;
  const int64_t nc = model.numCloth;
  s.capacity.resize(static_cast<size_t>(nc));
  parallelFor(nc, [&](int64_t i) {
    const double room = mostHeldWater(w, s.volume[i]) - state.clothWater[i] - state.clothBuffer[i];
    s.capacity[i] = static_cast<float>(std::max(0.0, room));
  });
}

// the shares of the requests that can be met: per water particle, of its mass (s.waterScale); per
// cloth particle, of its capacity (s.clothScale); both gathered
void shareRequests(const Model& model, const Particles& p, const NeighborLists& nb, const Requests& request,
                   WettingScratch& s) {
  const int64_t nc = model.numCloth;
  const int64_t n = static_cast<int64_t>(p.size());
  const uint32_t cloth = static_cast<uint32_t>(nc);
  const auto absorbs = [&](int64_t j) { return isWater(p.phase[j]) && !s.isDrip[j]; };
  // per water particle: the share of the requests its mass can meet
  s.waterScale.assign(static_cast<size_t>(n), 0.0f);
  parallelFor(n - nc, [&](int64_t k) {
    const int64_t j = nc + k;
    if (!absorbs(j)) return;
    float total = 0.0f;
    for (uint32_t e = nb.start[j], end = nb.clothEnd(j, cloth); e < end; ++e) {  // the cloth part
      const int64_t i = nb.index[e];
      if (i < nc) total += request(i, j);
    }
    if (total > 0.0f) s.waterScale[j] = total > p.mass[j] ? p.mass[j] / total : 1.0f;
  });
  // per cloth particle: the share of what it is offered that fits its capacity
  s.clothScale.assign(static_cast<size_t>(nc), 0.0f);
  parallelFor(nc, [&](int64_t i) {
    if (s.capacity[i] <= 0.0f) return;
    float offered = 0.0f;
    for (uint32_t e = nb.waterBegin(i, static_cast<uint32_t>(nc)); e < nb.start[i + 1]; ++e) {  // water part
      const int64_t j = nb.index[e];
      if (j >= nc && s.waterScale[j] > 0.0f) offered += s.waterScale[j] * request(i, j);
    }
    s.clothScale[i] = offered > s.capacity[i] ? s.capacity[i] / offered : 1.0f;
  });
}

// what each water particle loses (s.waterLost): partial absorption shrinks it, a remnant is taken
// whole (s.keep[j] = 0)
void shrinkWater(const Model& model, Particles& p, const NeighborLists& nb, const Requests& request,
                 WettingScratch& s) {
  const int64_t nc = model.numCloth;
  const int64_t n = static_cast<int64_t>(p.size());
  const uint32_t cloth = static_cast<uint32_t>(nc);
  const float m0 = model.water.particleMass, h0 = model.water.supportRadius;
  const float minMass = model.wetting.minMassFraction * m0;
  s.waterLost.assign(static_cast<size_t>(n), 0.0);
  s.keep.assign(static_cast<size_t>(n), 1);
  parallelFor(n - nc, [&](int64_t k) {
    const int64_t j = nc + k;
    if (s.waterScale[j] <= 0.0f) return;
    float loss = 0.0f;
    for (uint32_t e = nb.start[j], end = nb.clothEnd(j, cloth); e < end; ++e) {  // the cloth part
      const int64_t i = nb.index[e];
      if (i < nc) loss += s.clothScale[i] * s.waterScale[j] * request(i, j);
    }
    if (loss <= 0.0f) return;
    const float before = p.mass[j];
    const float after = before - loss;
    if (after < minMass) {
      s.waterLost[j] = before;  // full absorption: the particle leaves at the end of the wetting pass
      s.keep[j] = 0;
      p.mass[j] = 0.0f;
      return;
    }
    p.setMass(static_cast<size_t>(j), after, false);
    p.radius[j] = std::cbrt(after / m0) * h0;  // h' = (m'/m0)^(1/3) h0, the adaptive sampling of Eq. 11
    s.waterLost[j] = static_cast<double>(before) - static_cast<double>(after);  // exact: both are floats
  });
}

// each water particle's loss split over its absorbers by their share, the last taking the remainder
// exactly (s.gain, one slot per entry of its list's cloth part from s.lostStart), in parallel per
// water particle; counts the water particles absorbed whole in the ledger and returns how many.
// anyLost: whether any water particle lost water
size_t splitLosses(const Model& model, State& state, const NeighborLists& nb, const Requests& request,
                   WettingScratch& s, bool& anyLost) {
  const int64_t nc = model.numCloth;
  const int64_t n = static_cast<int64_t>(state.particles.size());
  const uint32_t cloth = static_cast<uint32_t>(nc);
  const int64_t nw = n - nc;
  s.lostStart.resize(static_cast<size_t>(nw) + 1);
  s.lostStart[0] = 0;
  for (int64_t k = 0; k < nw; ++k)
    s.lostStart[k + 1] = s.lostStart[k] + (s.waterLost[nc + k] > 0.0 ? nb.clothEnd(nc + k, cloth) - nb.start[nc + k] : 0u);
  size_t whole = 0;
  for (int64_t j = nc; j < n; ++j) whole += s.waterLost[j] > 0.0 && !s.keep[j] ? 1 : 0;
  s.anyAbsorbedWhole = whole > 0;
  state.ledger.particlesAbsorbed += whole;
  anyLost = s.lostStart[nw] > 0;
  if (!anyLost) return whole;  // nothing to hand out
  s.gain.resize(s.lostStart[nw]);
  s.absorber.resize(s.lostStart[nw]);
  parallelFor(nw, [&](int64_t k) {
    const int64_t j = nc + k;
    const double lost = s.waterLost[j];
    if (lost <= 0.0) return;
    const uint32_t e0 = nb.start[j], e1 = nb.clothEnd(j, cloth);  // the cloth part
    double* const gain = s.gain.data() + s.lostStart[k];
    uint8_t* const takes = s.absorber.data() + s.lostStart[k];
    double shares = 0.0;
    int64_t last = -1;
    for (uint32_t e = e0; e < e1; ++e) {
      const int64_t i = nb.index[e];
      const double t = i < nc ? static_cast<double>(s.clothScale[i]) * s.waterScale[j] * request(i, j) : 0.0;
      gain[e - e0] = t;  // the share for now
      takes[e - e0] = t > 0.0;
      if (t > 0.0) shares += t, last = i;
    }
    double given = 0.0;
    for (uint32_t e = e0; e < e1; ++e) {
      if (!takes[e - e0]) continue;
      const double g = static_cast<int64_t>(nb.index[e]) == last ? lost - given : lost * (gain[e - e0] / shares);
      given += g;
      gain[e - e0] = g;
    }
  });
  return whole;
}

// s.gainFirst / gainSlot / gainWater: the gains' slots by cloth particle, water ascending
void sortGainsByCloth(const Model& model, const State& state, const NeighborLists& nb, WettingScratch& s) {
  const int64_t nc = model.numCloth;
  const int64_t nw = static_cast<int64_t>(state.particles.size()) - nc;
  // the slots by cloth particle, water ascending: counted and placed per thread over a contiguous
  // range of the water, the ranges in thread order
  const int threads = threadCount();
  const size_t stride = static_cast<size_t>(nc) + 1;
  s.gainStart.assign(stride * static_cast<size_t>(threads), 0);
  std::vector<uint32_t>& first = s.gainFirst;
  first.resize(stride);
#pragma omp parallel num_threads(threads) if (s.lostStart[nw] >= 512)
  {
    const int t = omp_get_thread_num(), nt = omp_get_num_threads();
    const int64_t kb = nw * t / nt, ke = nw * (t + 1) / nt;
    uint32_t* const at = s.gainStart.data() + stride * static_cast<size_t>(t);
    const auto forSlots = [&](auto&& f) {
      for (int64_t k = kb; k < ke; ++k)
        for (uint32_t c = s.lostStart[k], c1 = s.lostStart[k + 1], e = nb.start[nc + k]; c < c1; ++c, ++e)
          if (s.absorber[c]) f(nb.index[e], c, static_cast<uint32_t>(nc + k));
    };
    forSlots([&](uint32_t i, uint32_t, uint32_t) { ++at[i]; });
#pragma omp barrier
#pragma omp single
    {
      uint32_t sum = 0;  // thread u's first slot of cloth particle i: after those of i's lower threads
      for (int64_t i = 0; i < nc; ++i) {
        first[static_cast<size_t>(i)] = sum;
        for (int u = 0; u < nt; ++u) {
          uint32_t& c = s.gainStart[stride * static_cast<size_t>(u) + static_cast<size_t>(i)];
          const uint32_t count = c;
          c = sum;
          sum += count;
        }
      }
      first[static_cast<size_t>(nc)] = sum;
      s.gainSlot.resize(sum);
      s.gainWater.resize(sum);
    }
    forSlots([&](uint32_t i, uint32_t c, uint32_t j) {
      const uint32_t to = at[i]++;
      s.gainSlot[to] = c;
      s.gainWater[to] = j;
    });
  }
}

// each cloth particle takes its gains in that order, with their momentum; what does not fit below
// S^MAX (the remnant of a water particle absorbed whole) goes to its buffer, so S_i <= S^MAX
void applyGains(const Model& model, State& state, const WettingScratch& s) {
  const int64_t nc = model.numCloth;
  Particles& p = state.particles;
  const std::vector<uint32_t>& first = s.gainFirst;
  parallelForDynamic(nc, kWetChunk, [&](int64_t i) {
    const double most = mostHeldWater(model.wetting, s.volume[i]);
    for (uint32_t g = first[static_cast<size_t>(i)]; g < first[static_cast<size_t>(i) + 1]; ++g) {
      const double gain = s.gain[s.gainSlot[g]];
      const uint32_t j = s.gainWater[g];
      const double held = std::min(gain, std::max(0.0, most - state.clothWater[i]));
      state.clothWater[i] += held;
      state.clothBuffer[i] += gain - held;
      // the absorbed water brings its momentum (inelastic: the cloth particle gets heavier)
      const float mi = p.mass[i];
      setWetMass(model, state, i);
      if (!model.clothPinned[i]) p.v[i] = (mi * p.v[i] + (p.mass[i] - mi) * p.v[j]) / p.mass[i];
    }
  });
}

}  // namespace

size_t absorbWater(const Model& model, State& state, const NeighborLists& nb, WettingScratch& s, float h) {
  s.anyAbsorbedWhole = false;
  const WettingParams& w = model.wetting;
  Particles& p = state.particles;
  const int64_t nc = model.numCloth;
  if (!w.enabled || !w.absorption || nc == 0 || static_cast<int64_t>(p.size()) == nc) return 0;
  clothCapacity(model, state, s);
  markDrips(model, state, s.isDrip);  // drips are held by Eq. 19, not soaked up
  const Requests request{p, s.capacity, rateForStep(w.absorptionRate, h, w.rateStep), w.absorptionGravity,
                         gravityDirection(model)};
  shareRequests(model, p, nb, request, s);
  shrinkWater(model, p, nb, request, s);
  // the cloth gains in a fixed order (water ascending, neighbours in list order), the order of a serial
  // loop over the water, in parallel per cloth particle: a gain changes only its own cloth particle,
  // so no sum depends on the thread count
  bool anyLost = false;
  const size_t whole = splitLosses(model, state, nb, request, s, anyLost);
  if (!anyLost) return whole;
  sortGainsByCloth(model, state, nb, s);
  applyGains(model, state, s);
  return whole;
}

void finishWetting(const Model& model, State& state, WettingScratch& s) {
  s.pairsValid = false;  // the next substep moves the cloth and rebuilds the lists
  if (!model.wetting.enabled) return;
  if (s.anyAbsorbedWhole) {
    // drips made after the absorption stage sit past the end of keep: they stay
    s.keep.resize(state.particles.size(), 1);
    state.particles.compact(s.keep);
    s.anyAbsorbedWhole = false;
  }
  double held = 0.0, buffered = 0.0;
  for (size_t i = 0; i < state.clothWater.size(); ++i) {
    held += state.clothWater[i];
    buffered += state.clothBuffer[i];
  }
  state.ledger.heldInCloth = held;
  state.ledger.inBuffers = buffered;
}

}  // namespace soak
