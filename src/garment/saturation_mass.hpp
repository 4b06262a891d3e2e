// saturation model of Chen, Magnenat-Thalmann, Allen 2012 (section 3.3, Eq. 15-19): a wet fabric
// vertex gains water mass Q(t) per unit dry mass, Q(t) = delta (1 - exp(-t / a3)), t counted from
// the moment the vertex first got wet. Table 1 gives delta and a3 for three fabrics.
#pragma once
#include <soak/model.hpp>
#include <soak/state.hpp>

#include <soak/garment_params.hpp>

#include <limits>
#include <span>
#include <string>
#include <vector>

namespace soak {

// "never wet": the wet start time of a dry vertex
constexpr float kNeverWet = std::numeric_limits<float>::infinity();

// Table 1 presets: "cotton" (0.84, 8.844), "coarse_wool" (1.24, 4.8936), "high_absorption"
// (2.492, 3.3803); timeScale 1. An unknown name throws soak::Error listing the known ones; `where`
// names the file / JSON path for the message.
SaturationParams saturationPreset(const std::string& name, const std::string& where = "fabric");
const std::vector<std::string>& saturationPresetNames();

// Eq. 18: water mass per unit dry fabric mass after `wetTime` seconds wet (0 for wetTime <= 0)
double absorbedRatio(double wetTime, const SaturationParams& s);
// Eq. 19: dQ/dt = delta / a3 exp(-t / a3), per second of simulated time
double absorptionRate(double wetTime, const SaturationParams& s);

// mass of a vertex of dry mass m_dry at `time`, wet since `wetStart` (kNeverWet: dry): m_dry (1 + Q).
// Eq. 15 integrates Eq. 19 step by step; the closed form is its exact integral (no drift).
double wetMass(double dryMass, float wetStart, double time, const SaturationParams& s);

// sets mass and invMass of the vertices of cloth piece `piece` to wetMass(model.clothDryMass,
// wetStart[v], time) (v local to the piece; missing entries are dry); pinned vertices keep invMass 0.
// Call before the solve ("in each time step, before numerically solving the system, the system
// matrix is updated").
void applySaturationMass(const Model& model, int piece, std::span<const float> wetStart, double time,
                         const SaturationParams& s, Particles& p);

// records the first wet time: wetStart[v] = time for each v < min(sizes) with wet[v] != 0 that was dry
void markWet(std::span<const uint8_t> wet, double time, std::span<float> wetStart);

}  // namespace soak
