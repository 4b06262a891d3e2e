// saturation model of Chen, Magnenat-Thalmann, Allen 2012 (section 3.3, Eq. 15-19): a fabric vertex
// in water gains water mass Q(t) per unit dry mass, Q(t) = delta (1 - exp(-t / a3)), t counted from
// the moment it got wet. Table 1 gives delta and a3 for three fabrics. soak tracks the saturation
// s = Q / delta per vertex and limits it by the water that actually reached the vertex.
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

// saturation s = Q / delta in [0, 1] of a vertex wet for `wetTime` s with an unlimited supply (Chen as
// printed): 1 - exp(-t / a3); 0 for wetTime <= 0 or not finite
float unlimitedSaturation(double wetTime, const SaturationParams& s);
// Eq. 18 as its differential equation dQ/dt = (delta - Q) / a3, with delta replaced by the water the
// vertex holds, `heldFraction` = min(held / (delta m_dry), 1): the saturation after h seconds, exact
// for a constant supply (so independent of the step), never above heldFraction when starting below it
float absorbStep(float saturation, double heldFraction, double h, const SaturationParams& s);
// the water a vertex of dry mass m_dry can absorb: delta m_dry (kg)
double waterCapacity(double dryMass, const SaturationParams& s);

// mass of a vertex of dry mass m_dry at saturation s: m_dry (1 + delta s) (Eq. 15 with Q = delta s)
double wetMass(double dryMass, float saturation, const SaturationParams& s);

// sets mass and invMass of the vertices of cloth piece `piece` to wetMass(model.clothDryMass,
// saturation[v]) (v local to the piece; missing entries are dry); pinned vertices keep invMass 0.
// Call before the solve ("in each time step, before numerically solving the system, the system
// matrix is updated").
void applySaturationMass(const Model& model, int piece, std::span<const float> saturation, const SaturationParams& s,
                         Particles& p);

// advances State::clothSaturation of the piece's vertices to time + h: with unlimitedSupply from the
// wet start times (unlimitedSaturation), else by absorbStep towards the water each holds
// (State::clothWater). Needs both arrays sized to the cloth (a piece with wetByContact).
void updateSaturation(const Model& model, int piece, const SaturationParams& s, double time, float h, State& state);


}  // namespace soak
