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

double absorbedRatio(double wetTime, const SaturationParams& s) {
  if (!(wetTime > 0.0)) return 0.0;
  const double tau = static_cast<double>(s.a3) * s.timeScale;
  return s.delta * -std::expm1(-wetTime / tau);  // Eq. 18
}

double absorptionRate(double wetTime, const SaturationParams& s) {
  if (!(wetTime >= 0.0)) return 0.0;
  const double tau = static_cast<double>(s.a3) * s.timeScale;
  return s.delta / tau * std::exp(-wetTime / tau);  // Eq. 19
}

double wetMass(double dryMass, float wetStart, double time, const SaturationParams& s) {
  if (!std::isfinite(wetStart)) return dryMass;
  return dryMass * (1.0 + absorbedRatio(time - static_cast<double>(wetStart), s));
}

void applySaturationMass(const Model& model, int piece, std::span<const float> wetStart, double time,
                         const SaturationParams& s, Particles& p) {
  const ClothPiece& pc = model.pieces[static_cast<size_t>(piece)];
  parallelFor(pc.particleCount, [&](int64_t v) {
    const size_t i = static_cast<size_t>(pc.firstParticle + v);
    const float start = static_cast<size_t>(v) < wetStart.size() ? wetStart[v] : kNeverWet;
    const float m = static_cast<float>(wetMass(model.clothDryMass[i], start, time, s));
    p.setMass(i, m, model.clothPinned[i]);
  });
}

void markWet(std::span<const uint8_t> wet, double time, std::span<float> wetStart) {
  const size_t n = std::min(wet.size(), wetStart.size());
  for (size_t v = 0; v < n; ++v)
    if (wet[v] && !std::isfinite(wetStart[v])) wetStart[v] = static_cast<float>(time);
}

}  // namespace soak
