// strain limiting after the implicit step (strain_limit.hpp)
#include "garment/strain_limit.hpp"

#include <cmath>

namespace soak {

namespace {

constexpr float kAtPole = 1e-5f;  // a spring this close above its pole (relative) is at it: rounding of a projection

// one pass over springs [begin, end) of one law; returns the springs shortened
int limitPass(const SpringSet& springs, int begin, int end, const KesLaw& law, std::span<const float> invMass,
              float h, std::span<Vec3> x, std::span<Vec3> v, std::vector<uint8_t>& moved) {
  const float stretch = 1.0f + kesPoleStrain(law);
  if (!std::isfinite(stretch)) return 0;  // a linear law (a2 = 0) has no pole to keep away from
  int shortened = 0;
  for (int s = begin; s < end; ++s) {
    const int a = springs.ids[s][0], b = springs.ids[s][1];
    const Vec3 d = x[b] - x[a];
    const float l = d.norm(), lmax = springs.restLength[s] * stretch;
    const float wsum = invMass[a] + invMass[b];
    if (l <= lmax * (1.0f + kAtPole) || wsum == 0.0f) continue;
    const Vec3 pull = ((l - lmax) / (l * wsum)) * d;  // per unit inverse mass, from a towards b
    x[a] += invMass[a] * pull;
    x[b] -= invMass[b] * pull;
    v[a] += (invMass[a] / h) * pull;
    v[b] -= (invMass[b] / h) * pull;
    moved[a] = moved[b] = 1;
    ++shortened;
  }
  return shortened;
}

}  // namespace

int limitStrain(const SpringSet& springs, const SpringLaws& laws, std::span<const float> invMass, float h,
                std::span<Vec3> x, std::span<Vec3> v, std::vector<uint8_t>& moved) {
  moved.assign(x.size(), 0);
  int total = 0;
  for (int pass = 0; pass < kStrainLimitPasses; ++pass) {
    const int n = limitPass(springs, springs.kindStart[0], springs.kindStart[1], laws.stretch, invMass, h, x, v,
                            moved) +
                  limitPass(springs, springs.kindStart[1], springs.kindStart[2], laws.shear, invMass, h, x, v, moved);
    total += n;
    if (n == 0) break;
  }
  return total;
}

}  // namespace soak
