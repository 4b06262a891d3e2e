// Chen 2012 wet skin friction (section 3.4, Eq. 20-21, Fig. 5) as two smoothstep pieces, Coulomb friction at
// a contact, and the sqrt mix of two coefficients
#include "garment/wet_friction.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace soak {
namespace {

TEST(GarmentFriction, PeaksAtTau1AndIsOnItsPlateauAfterTau2) {
  const WetFrictionParams f{0.3f, 0.7f, 0.5f, 2.0f, 5.0f, 1.5f};  // times in s: tau1 = 3 s, tau2 = 7.5 s
  EXPECT_FLOAT_EQ(wetFriction(-1.0, f), 0.3f);
  EXPECT_FLOAT_EQ(wetFriction(INFINITY, f), 0.3f);
  EXPECT_FLOAT_EQ(wetFriction(-INFINITY, f), 0.3f);
  EXPECT_FLOAT_EQ(wetFriction(3.0, f), 0.7f);
  double best = -1.0, bestT = -1.0, prev = wetFriction(0.0, f);
  for (int k = 0; k <= 12000; ++k) {
    const double t = k * 1e-3;
    const double mu = wetFriction(t, f);
    if (mu > best) {
      best = mu;
      bestT = t;
    }
    EXPECT_LT(std::abs(mu - prev), 1e-3) << "continuous at t " << t;
    if (t < 3.0) {
      EXPECT_GE(mu, prev - 1e-7) << "rises before tau1, t " << t;
    } else if (t > 3.0 && t < 7.5) {
      EXPECT_LE(mu, prev + 1e-7) << "falls after tau1, t " << t;
    } else if (t >= 7.5) {
      EXPECT_FLOAT_EQ(mu, 0.5f) << "plateau after tau2, t " << t;
    }
    prev = mu;
  }
  EXPECT_NEAR(bestT, 3.0, 1e-3);
  EXPECT_FLOAT_EQ(best, 0.7f);
  EXPECT_GT(wetFriction(7.4, f), 0.5f);  // still falling just before tau2
}

// S(s) = 3 s^2 - 2 s^3 has S(1/4) = 5/32 and S(1/2) = 1/2: the coefficient at a quarter and half of each
// phase, with the paper's time unit stretched by timeScale
TEST(GarmentFriction, SmoothstepValuesAtAQuarterAndHalfOfEachPhase) {
  const WetFrictionParams f{0.3f, 0.7f, 0.5f, 2.0f, 5.0f, 1.5f};  // tau1 = 3 s, tau2 = 7.5 s
  EXPECT_NEAR(wetFriction(0.75, f), 0.3 + 0.4 * 5.0 / 32.0, 1e-6);
  EXPECT_NEAR(wetFriction(1.5, f), 0.5, 1e-6);                      // half way from 0.3 to 0.7
  EXPECT_NEAR(wetFriction(3.0 + 0.25 * 4.5, f), 0.7 - 0.2 * 5.0 / 32.0, 1e-6);
  EXPECT_NEAR(wetFriction(5.25, f), 0.6, 1e-6);                     // half way from 0.7 to 0.5
  EXPECT_FLOAT_EQ(wetFriction(7.5, f), 0.5f);
  EXPECT_FLOAT_EQ(wetFriction(0.0, f), 0.3f);
}

// the pieces join with zero slope at 0, tau1 and tau2 (a linear ramp would have slope (peak - dry) / tau1
// there): one-sided differences over 1e-3 of a phase stay below 1% of the ramp's slope
TEST(GarmentFriction, SlopeIsZeroWhereThePiecesJoin) {
  const WetFrictionParams f{0.3f, 0.7f, 0.5f, 2.0f, 5.0f, 1.5f};
  const double tau1 = 3.0, tau2 = 7.5, e1 = 1e-3 * tau1, e2 = 1e-3 * (tau2 - tau1);
  const double rise = 0.4 / tau1, fall = 0.2 / (tau2 - tau1);
  EXPECT_LT(std::abs(wetFriction(e1, f) - wetFriction(0.0, f)) / e1, 0.01 * rise);
  EXPECT_LT(std::abs(wetFriction(tau1, f) - wetFriction(tau1 - e1, f)) / e1, 0.01 * rise);
  EXPECT_LT(std::abs(wetFriction(tau1 + e2, f) - wetFriction(tau1, f)) / e2, 0.01 * fall);
  EXPECT_LT(std::abs(wetFriction(tau2, f) - wetFriction(tau2 - e2, f)) / e2, 0.01 * fall);
  // in the middle of the rise the slope is S'(1/2) = 1.5 times the ramp's
  const double mid = (wetFriction(1.5 + e1, f) - wetFriction(1.5 - e1, f)) / (2.0 * e1);
  EXPECT_NEAR(mid, 1.5 * rise, 1e-3 * rise);
}

}  // namespace
}  // namespace soak
