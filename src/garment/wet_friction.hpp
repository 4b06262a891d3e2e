// wet skin friction of Chen, Magnenat-Thalmann, Allen 2012 (section 3.4, Eq. 20-21, Fig. 5): the
// fabric-skin friction coefficient rises from its dry value to a peak at tau1 after the fabric got
// wet, then falls to a plateau reached at tau2. Eq. 20-21 are an RBF fit whose coefficients the
// paper does not print; soak uses two smoothstep pieces with the same three values and two times.
#pragma once
#include <soak/math.hpp>

#include <soak/garment_params.hpp>

namespace soak {

// friction coefficient after `wetTime` seconds wet (the dry value for wetTime <= 0 or not finite):
//   dry + (peak - dry) S(t / tau1)                        for 0 <= t <= tau1
//   peak + (plateau - peak) S((t - tau1) / (tau2 - tau1))  for tau1 < t < tau2
//   plateau                                               for t >= tau2
// with S(s) = 3 s^2 - 2 s^3: continuous with a continuous slope, the extremum exactly at tau1
float wetFriction(double wetTime, const WetFrictionParams& f);

// Coulomb friction at a contact, velocity level: vRel is the velocity relative to the surface
// after the normal correction, n the unit normal, normalDeltaV >= 0 the normal velocity change the
// contact applied this step. The tangential part shrinks by at most mu * normalDeltaV (kinetic
// friction) and stops when that is enough (static friction). Returns the new relative velocity.
Vec3 coulombFriction(const Vec3& vRel, const Vec3& n, float mu, float normalDeltaV);

// mixes a fabric and a collider coefficient as sqrt(a b) (Box2D's b2MixFriction): zero on either
// side gives a frictionless contact
float mixFriction(float fabric, float collider);

}  // namespace soak
