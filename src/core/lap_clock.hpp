// a wall clock read in laps: the stage timings (sim/step.cpp) and the implicit garment step's parts
#pragma once
#include <chrono>

namespace soak {

struct LapClock {
  std::chrono::steady_clock::time_point t = std::chrono::steady_clock::now();
  // the ms since the last lap (or the clock's start); the next lap counts from now
  double lap() {
    const auto now = std::chrono::steady_clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - t).count();
    t = now;
    return ms;
  }
};

}  // namespace soak
