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

float wetFriction(float s, const WetFrictionParams& f) {
  if (!(s > 0.0f) || !std::isfinite(s)) return f.dry;
  const float s1 = f.peakSaturation, s2 = f.plateauSaturation;
  if (s <= s1) return f.dry + (f.peak - f.dry) * smoothstep(s / s1);
  if (s < s2) return f.peak + (f.plateau - f.peak) * smoothstep((s - s1) / (s2 - s1));
  return f.plateau;
}

}  // namespace soak
