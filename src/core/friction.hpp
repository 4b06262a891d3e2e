// Coulomb friction at a contact, the one formula every contact in soak uses (PBD colliders, the
// implicit garment's body contact), and the rule that mixes two surfaces' coefficients
#pragma once
#include <soak/math.hpp>

#include <algorithm>
#include <cmath>

namespace soak {

// static and kinetic Coulomb coefficients of a contact
struct FrictionCoefficients {
  float staticCoef = 0.0f;
  float kinetic = 0.0f;
};

// Coulomb friction on a relative motion `rel` (a velocity, or a displacement over one step) at a
// contact with unit normal n, where the contact's normal correction this step was normalDelta >= 0
// (a velocity change, or a displacement). The tangential part stops when it is at most
// mu_s * normalDelta (static friction) and otherwise shrinks by mu_k * normalDelta (kinetic), keeping
// its direction; the normal part is kept. Returns the new relative motion. At position level (PBD,
// Macklin et al. 2014 section 6.1) a particle resting on a slope gets normalDelta = g_n h^2 a substep
// and slips g_t h^2: it holds when tan(theta) <= mu_s for any h, and slides with a = g_t - mu_k g_n.
inline Vec3 coulombFriction(const Vec3& rel, const Vec3& n, FrictionCoefficients mu, float normalDelta) {
  const Vec3 normal = rel.dot(n) * n;
  const Vec3 tangential = rel - normal;
  const float slip = tangential.norm();
  const float push = std::max(normalDelta, 0.0f);
  if (slip <= std::max(mu.staticCoef, mu.kinetic) * push) return normal;  // static: the contact holds
  return normal + tangential * std::max(0.0f, 1.0f - mu.kinetic * push / slip);
}

// one coefficient for static and kinetic friction
inline Vec3 coulombFriction(const Vec3& rel, const Vec3& n, float mu, float normalDelta) {
  return coulombFriction(rel, n, FrictionCoefficients{mu, mu}, normalDelta);
}

// mixes the coefficients of two surfaces as sqrt(a b) (Box2D's b2MixFriction): zero on either side
// gives a frictionless contact
inline float mixFriction(float a, float b) { return std::sqrt(std::max(a, 0.0f) * std::max(b, 0.0f)); }
inline FrictionCoefficients mixFriction(FrictionCoefficients a, FrictionCoefficients b) {
  return {mixFriction(a.staticCoef, b.staticCoef), mixFriction(a.kinetic, b.kinetic)};
}

}  // namespace soak
