// Chen et al. 2012 section 3.4 (Eq. 20-21, Fig. 5) and Coulomb friction for cloth-body contact
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

Vec3 coulombFriction(const Vec3& vRel, const Vec3& n, float mu, float normalDeltaV) {
  const Vec3 vn = vRel.dot(n) * n;
  const Vec3 vt = vRel - vn;
  const float speed = vt.norm();
  const float budget = mu * std::max(normalDeltaV, 0.0f);
  if (speed <= budget) return vn;  // static: the contact holds
  return vn + vt * (1.0f - budget / speed);
}

float mixFriction(float fabric, float collider) { return std::sqrt(std::max(fabric, 0.0f) * std::max(collider, 0.0f)); }

}  // namespace soak
