// wet skin friction of Chen, Magnenat-Thalmann, Allen 2012 (section 3.4, Eq. 20-21, Fig. 5): the
// fabric-skin friction coefficient rises from its dry value to a peak, then falls to a plateau, as
// the fabric takes up water. Eq. 20-21 are an RBF fit over time whose coefficients the paper does not
// print; soak uses two smoothstep pieces with the same three values, over the fabric's saturation
// (docs/garment.md, departure 8: the time of Fig. 5 read through Eq. 18).
#pragma once
#include <soak/math.hpp>

#include <soak/garment_params.hpp>

#include "core/friction.hpp"

namespace soak {

// friction coefficient at saturation s (absorbed water / delta m_dry; the dry value for s <= 0 or
// not finite), with s1 = peakSaturation, s2 = plateauSaturation:
//   dry + (peak - dry) S(s / s1)                     for 0 <= s <= s1
//   peak + (plateau - peak) S((s - s1) / (s2 - s1))  for s1 < s < s2
//   plateau                                          for s >= s2
// with S(x) = 3 x^2 - 2 x^3: continuous with a continuous slope, the extremum exactly at s1
float wetFriction(float saturation, const WetFrictionParams& f);

// Coulomb friction and the mixing of a fabric and a collider coefficient: core/friction.hpp

}  // namespace soak
