// Chen et al. 2012 section 3.4 (Eq. 20-21, Fig. 5)
#include "garment/wet_friction.hpp"

#include <algorithm>
#include <cmath>

namespace soak {

namespace {

float smoothstep(float s) {
  s = std::clamp(s, 0.0f, 1.0f);
  return s * s * (3.0f - 2.0f * s);
}

}  // namespace

float wetFriction(double wetTime, const WetFrictionParams& f) {
  if (!(wetTime > 0.0) || !std::isfinite(wetTime)) return f.dry;
  const double t = wetTime / static_cast<double>(f.timeScale);
  if (t <= f.tau1) return f.dry + (f.peak - f.dry) * smoothstep(static_cast<float>(t / f.tau1));
  if (t < f.tau2) return f.peak + (f.plateau - f.peak) * smoothstep(static_cast<float>((t - f.tau1) / (f.tau2 - f.tau1)));
  return f.plateau;
}

}  // namespace soak
