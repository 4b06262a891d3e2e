// wet skin friction of Chen, Magnenat-Thalmann, Allen 2012 (section 3.4, Eq. 20-21, Fig. 5): the
// fabric-skin friction coefficient rises from its dry value to a peak at tau1 after the fabric got
// wet, then falls to a plateau reached at tau2. Eq. 20-21 are an RBF fit whose coefficients the
// paper does not print; soak uses two smoothstep pieces with the same three values and two times.
#pragma once
#include <soak/math.hpp>

#include <soak/garment_params.hpp>

#include "core/friction.hpp"

namespace soak {

// friction coefficient after `wetTime` seconds wet (the dry value for wetTime <= 0 or not finite):
//   dry + (peak - dry) S(t / tau1)                        for 0 <= t <= tau1
//   peak + (plateau - peak) S((t - tau1) / (tau2 - tau1))  for tau1 < t < tau2
//   plateau                                               for t >= tau2
// with S(s) = 3 s^2 - 2 s^3: continuous with a continuous slope, the extremum exactly at tau1
float wetFriction(double wetTime, const WetFrictionParams& f);

// Coulomb friction and the mixing of a fabric and a collider coefficient: core/friction.hpp

}  // namespace soak
