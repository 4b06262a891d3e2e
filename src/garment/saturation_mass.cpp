// Chen et al. 2012 Eq. 15-19: mass of a wetting garment vertex from fabric absorption measurements
#include "garment/saturation_mass.hpp"

#include <soak/error.hpp>

#include "core/parallel.hpp"

#include <algorithm>
#include <cmath>

namespace soak {

namespace {

struct Preset {
  const char* name;
  float delta, a3;
};

// Table 1 of Chen 2012 (the "theta" row is delta: NOTES.md)
constexpr Preset kPresets[] = {
    {"cotton", 0.84f, 8.844f},
    {"coarse_wool", 1.24f, 4.8936f},
    {"high_absorption", 2.492f, 3.3803f},
};

// the time constant of Eq. 18 in seconds
double timeConstant(const SaturationParams& s) { return static_cast<double>(s.a3) * s.timeScale; }

// Eq. 18 over delta: 1 - exp(-t / a3), 0 before the fabric is wet (or never)
double saturationAfter(double wetTime, const SaturationParams& s) {
  if (!(wetTime > 0.0) || !std::isfinite(wetTime)) return 0.0;
  return -std::expm1(-wetTime / timeConstant(s));
}

}  // namespace

const std::vector<std::string>& saturationPresetNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const Preset& p : kPresets) v.emplace_back(p.name);
    return v;
  }();
  return names;
}

SaturationParams saturationPreset(const std::string& name, const std::string& where) {
  for (const Preset& p : kPresets)
    if (name == p.name) return SaturationParams{p.delta, p.a3, 1.0f};
  std::string known;
  for (const std::string& n : saturationPresetNames()) known += (known.empty() ? "" : ", ") + n;
  throw Error(where + ": unknown fabric \"" + name + "\" (known fabrics: " + known +
              "; or give saturation.delta and saturation.a3 explicitly)");
}

double absorbedRatio(double wetTime, const SaturationParams& s) { return s.delta * saturationAfter(wetTime, s); }

double absorptionRate(double wetTime, const SaturationParams& s) {
  if (!(wetTime >= 0.0)) return 0.0;
  const double tau = timeConstant(s);
  return s.delta / tau * std::exp(-wetTime / tau);  // Eq. 19
}

float unlimitedSaturation(double wetTime, const SaturationParams& s) {
  return static_cast<float>(saturationAfter(wetTime, s));
}

float absorbStep(float saturation, double heldFraction, double h, const SaturationParams& s) {
  const double target = std::clamp(heldFraction, 0.0, 1.0);
  if (!(target > saturation)) return saturation;  // absorbed water stays absorbed
  return static_cast<float>(saturation + (target - saturation) * -std::expm1(-h / timeConstant(s)));  // Eq. 18's ODE
}

double waterCapacity(double dryMass, const SaturationParams& s) { return static_cast<double>(s.delta) * dryMass; }

double wetMass(double dryMass, float saturation, const SaturationParams& s) {
  if (!(saturation > 0.0f)) return dryMass;
  return dryMass * (1.0 + static_cast<double>(s.delta) * std::min(saturation, 1.0f));
}

void applySaturationMass(const Model& model, int piece, std::span<const float> saturation, const SaturationParams& s,
                         Particles& p) {
  const ClothPiece& pc = model.pieces[static_cast<size_t>(piece)];
  parallelFor(pc.particleCount, [&](int64_t v) {
    const size_t i = static_cast<size_t>(pc.firstParticle + v);
    const float sat = static_cast<size_t>(v) < saturation.size() ? saturation[v] : 0.0f;
    p.setMass(i, static_cast<float>(wetMass(model.clothDryMass[i], sat, s)), model.clothPinned[i]);
  });
}

void updateSaturation(const Model& model, int piece, const SaturationParams& s, double time, float h, State& state) {
  const ClothPiece& pc = model.pieces[static_cast<size_t>(piece)];
  const double tEnd = time + static_cast<double>(h);
  parallelFor(pc.particleCount, [&](int64_t v) {
    const size_t i = static_cast<size_t>(pc.firstParticle + v);
    float& sat = state.clothSaturation[i];
    if (s.unlimitedSupply) {
      sat = unlimitedSaturation(tEnd - static_cast<double>(state.clothWetStart[i]), s);
      return;
    }
    const double capacity = waterCapacity(model.clothDryMass[i], s);
    sat = absorbStep(sat, capacity > 0.0 ? state.clothWater[i] / capacity : 0.0, h, s);
  });
}

}  // namespace soak
