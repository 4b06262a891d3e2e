// per-frame statistics as JSON lines (stats.jsonl): one object per written frame
#pragma once
#include <soak/model.hpp>
#include <soak/state.hpp>
#include <soak/output.hpp>
#include <soak/stats.hpp>

#include <nlohmann/json.hpp>

#include <fstream>
#include <string>

namespace soak {

// the parts of the stages (StagePart) as {"stage.part": ms}, in StagePart's order
nlohmann::ordered_json stagePartsJson(const StageTimes& t);

// the largest particle speed in the state (m/s), used for frame 0 where no step ran
float stateMaxSpeed(const State& state);

}  // namespace soak
