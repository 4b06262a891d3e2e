// wet dynamics: the sticking force of Eq. 20 peaks at S^T and vanishes on dry and on soaked cloth (the
// coupling stiffness of Eq. 22: permeability_test.cpp)
#include "wetting/wet_support.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace soak;
using namespace soak::testing;

TEST(WettingSticking, CoefficientIsLargestAtSTAndNeverNegative) {
  const WettingParams w;
  const float atT = stickingCoefficient(w, w.saturationSticky, w.saturationSticky);
  EXPECT_NEAR(atT, w.stickingStrength, 1e-7f);
  EXPECT_EQ(stickingCoefficient(w, 0.0f, 0.0f), 0.0f);  // dry cloth does not stick
  EXPECT_EQ(stickingCoefficient(w, w.saturationMax, w.saturationMax), 0.0f);  // soaked cloth separates
  EXPECT_LT(stickingCoefficient(w, 0.5f * w.saturationSticky, 0.5f * w.saturationSticky), atT);
  EXPECT_LT(stickingCoefficient(w, w.saturationEmit, w.saturationEmit), atT);
  EXPECT_GT(stickingCoefficient(w, w.saturationEmit, w.saturationEmit), 0.0f);
  for (float a = 0.0f; a <= 0.4f; a += 0.01f)
    for (float b = 0.0f; b <= 0.4f; b += 0.01f) {
      const float c = stickingCoefficient(w, a, b);
      EXPECT_GE(c, 0.0f);
      EXPECT_LE(c, atT + 1e-7f);
      EXPECT_EQ(c, stickingCoefficient(w, b, a));
    }
}

namespace {

// two free parallel sheets (different pieces) 0.01 m apart, both at saturation `sat`; returns the
// mean velocity the sticking stage gives the upper sheet and checks momentum
float pullOnUpperSheet(float sat) {
  Scene s = sceneFromJson(std::string(R"({"solver": {"gravity": [0, 0, 0]}, "cloth": [)") +
                          rectangleJson("low", Vec3(0, 1, 0), 0.2f, 0.2f, 11, 11, "[1, 0, 0]", "[0, 0, 1]", "{}") +
                          ", " +
                          rectangleJson("up", Vec3(0, 1.01f, 0), 0.2f, 0.2f, 11, 11, "[1, 0, 0]", "[0, 0, 1]", "{}") +
                          R"(], "wetting": {"saturation": {"initial": )" + std::to_string(sat) + "}}}");
  StageRig rig;
  rig.refresh(s.state, s.model);
  applySticking(s.model, s.state, rig.nb, rig.s, s.model.solver.dt);
  const Particles& p = s.state.particles;
  Vec3d momentum = Vec3d::Zero();
  double up = 0.0;
  for (int i = 0; i < s.model.numCloth; ++i) {
    momentum += (double(p.mass[i]) * p.v[i].cast<double>());
    if (i >= 121) up += p.v[i].y() / 121.0;
  }
  EXPECT_LT(momentum.norm(), 1e-9) << "S = " << sat;  // equal and opposite pairs
  return float(up);
}

}  // namespace

TEST(WettingSticking, WetLayersPullTogetherMostAtST) {
  const WettingParams w;
  const float atT = pullOnUpperSheet(w.saturationSticky);
  EXPECT_LT(atT, 0.0f);  // the upper sheet is pulled down onto the lower one
  EXPECT_EQ(pullOnUpperSheet(0.0f), 0.0f);
  EXPECT_EQ(pullOnUpperSheet(w.saturationMax), 0.0f);
  const float damp = pullOnUpperSheet(0.5f * w.saturationSticky);
  EXPECT_LT(damp, 0.0f);
  EXPECT_LT(atT, damp);  // stronger (more negative) at S^T
  EXPECT_LT(atT, pullOnUpperSheet(w.saturationEmit));
}
