// whole-state diagnostics used by the step (checkState and stateHash are in soak/step.hpp)
#pragma once
#include <soak/state.hpp>

namespace soak {

// the largest particle speed (m/s)
float maxSpeed(const Particles& p);

}  // namespace soak
