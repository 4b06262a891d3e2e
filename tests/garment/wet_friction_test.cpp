// Chen 2012 wet skin friction (section 3.4, Eq. 20-21, Fig. 5) as two smoothstep pieces over the
// saturation, Coulomb friction at a contact, and the sqrt mix of two coefficients
#include "garment/wet_friction.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace soak {
namespace {

constexpr WetFrictionParams kCurve{0.3f, 0.7f, 0.5f, 0.3f, 0.75f};  // peak at s = 0.3, plateau from 0.75

TEST(GarmentFriction, PeaksAtPeakSaturationAndIsOnItsPlateauAfter) {
  const WetFrictionParams& f = kCurve;
  EXPECT_FLOAT_EQ(wetFriction(-1.0f, f), 0.3f);
  EXPECT_FLOAT_EQ(wetFriction(NAN, f), 0.3f);
  EXPECT_FLOAT_EQ(wetFriction(INFINITY, f), 0.3f);
  EXPECT_FLOAT_EQ(wetFriction(0.3f, f), 0.7f);
  float best = -1.0f, bestS = -1.0f, prev = wetFriction(0.0f, f);
  for (int k = 0; k <= 10000; ++k) {
    const float s = k * 1e-4f;
    const float mu = wetFriction(s, f);
    if (mu > best) {
      best = mu;
      bestS = s;
    }
    EXPECT_LT(std::abs(mu - prev), 1e-3f) << "continuous at s " << s;
    if (s < 0.3f) {
      EXPECT_GE(mu, prev - 1e-6f) << "rises before the peak, s " << s;
    } else if (s > 0.3f && s < 0.75f) {
      EXPECT_LE(mu, prev + 1e-6f) << "falls after the peak, s " << s;
    } else if (s >= 0.75f) {
      EXPECT_FLOAT_EQ(mu, 0.5f) << "plateau, s " << s;
    }
    prev = mu;
  }
  EXPECT_NEAR(bestS, 0.3f, 2e-4f);
  EXPECT_FLOAT_EQ(best, 0.7f);
  EXPECT_GT(wetFriction(0.74f, f), 0.5f);  // still falling just before the plateau
}

// S(x) = 3 x^2 - 2 x^3 has S(1/4) = 5/32 and S(1/2) = 1/2: the coefficient at a quarter and half of
// each phase
TEST(GarmentFriction, SmoothstepValuesAtAQuarterAndHalfOfEachPhase) {
  const WetFrictionParams& f = kCurve;
  EXPECT_NEAR(wetFriction(0.075f, f), 0.3 + 0.4 * 5.0 / 32.0, 1e-6);
  EXPECT_NEAR(wetFriction(0.15f, f), 0.5, 1e-6);  // half way from 0.3 to 0.7
  EXPECT_NEAR(wetFriction(0.3f + 0.25f * 0.45f, f), 0.7 - 0.2 * 5.0 / 32.0, 1e-6);
  EXPECT_NEAR(wetFriction(0.525f, f), 0.6, 1e-6);  // half way from 0.7 to 0.5
  EXPECT_FLOAT_EQ(wetFriction(0.75f, f), 0.5f);
  EXPECT_FLOAT_EQ(wetFriction(1.0f, f), 0.5f);
  EXPECT_FLOAT_EQ(wetFriction(0.0f, f), 0.3f);
}

// the pieces join with zero slope at 0, the peak and the plateau (a linear ramp would have slope
// (peak - dry) / s1 there): one-sided differences over 1e-3 of a phase stay below 1% of the ramp's slope
TEST(GarmentFriction, SlopeIsZeroWhereThePiecesJoin) {
  const WetFrictionParams& f = kCurve;
  const float s1 = 0.3f, s2 = 0.75f, e1 = 1e-3f * s1, e2 = 1e-3f * (s2 - s1);
  const double rise = 0.4 / s1, fall = 0.2 / (s2 - s1);
  EXPECT_LT(std::abs(wetFriction(e1, f) - wetFriction(0.0f, f)) / e1, 0.01 * rise);
  EXPECT_LT(std::abs(wetFriction(s1, f) - wetFriction(s1 - e1, f)) / e1, 0.01 * rise);
  EXPECT_LT(std::abs(wetFriction(s1 + e2, f) - wetFriction(s1, f)) / e2, 0.01 * fall);
  EXPECT_LT(std::abs(wetFriction(s2, f) - wetFriction(s2 - e2, f)) / e2, 0.01 * fall);
  // in the middle of the rise the slope is S'(1/2) = 1.5 times the ramp's
  const double mid = (wetFriction(0.15f + 1e-3f, f) - wetFriction(0.15f - 1e-3f, f)) / 2e-3;
  EXPECT_NEAR(mid, 1.5 * rise, 2e-3 * rise);
}

}  // namespace
}  // namespace soak
