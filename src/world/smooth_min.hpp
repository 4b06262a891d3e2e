// the smooth union of a Body collider's parts (model.hpp, ColliderShape::Body): one formula, used by
// the exact distance, its vectorised lower bound and the tests
#pragma once
#include <algorithm>
#include <cmath>

namespace soak {

// Quilez's quadratic smooth minimum of radius k > 0: s(a, b) = min(a, b) - k h^2 / 4 with
// h = max(k - |a - b|, 0) / k. s = min(a, b) once |a - b| >= k, min - k / 4 <= s <= min, s is C1 and
// non-decreasing in a and b. Its gradient is (1 - w) grad a + w grad b with w = bWeight (w = h / 2
// when a <= b, 1 - h / 2 otherwise), so the surface's normal and velocity blend with the same weight.
// Folded over any number of distances, r = s(r, d_j), the result stays >= min_j d_j - k (if r >= m - k
// for the min m so far, s(r, d) >= min(m, d) - k): a body's surface is within k of its parts' union
[[gnu::always_inline]] inline float smoothMin(float a, float b, float k, float* bWeight) {
  const float h = std::max(k - std::fabs(a - b), 0.0f) / k;
  *bWeight = a <= b ? 0.5f * h : 1.0f - 0.5f * h;
  return std::min(a, b) - 0.25f * k * h * h;
}

}  // namespace soak
