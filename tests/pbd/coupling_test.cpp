// the water-cloth coupling of Eq. 21-22 (src/pbd/coupling.cpp): its constraint, no tunnelling of
// fast drops, a moving sheet carrying water, the rigid final pass at dry triangles only, and Fig. 3(a)
// without a crossing (the candidate search and the sides: coupling_search_test.cpp)
#include "support/crossings.hpp"
#include "support/run_scene.hpp"

#include "pbd/coupling.hpp"
#include "pbd/integrate.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace soak;
using namespace soak::testing;

namespace {
// height of the cloth surface under (x, z), by barycentric interpolation over the triangle whose
// projection contains it; NaN when no triangle does
float clothHeightAt(const Model& model, const Particles& p, float x, float z) {
  for (const auto& t : model.triangles) {
    const Vec3 &a = p.x[t[0]], &b = p.x[t[1]], &c = p.x[t[2]];
    const float det = (b.z() - c.z()) * (a.x() - c.x()) + (c.x() - b.x()) * (a.z() - c.z());
    if (std::fabs(det) < 1e-12f) continue;
    const float l1 = ((b.z() - c.z()) * (x - c.x()) + (c.x() - b.x()) * (z - c.z())) / det;
    const float l2 = ((c.z() - a.z()) * (x - c.x()) + (a.x() - c.x()) * (z - c.z())) / det;
    const float l3 = 1.0f - l1 - l2;
    if (l1 >= 0 && l2 >= 0 && l3 >= 0) return l1 * a.y() + l2 * b.y() + l3 * c.y();
  }
  return std::nanf("");
}
}  // namespace

TEST(Coupling, CouplingConstraintIsSignedDistanceMinusThickness) {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 0, 1);  // normal (b - a) x (c - a) = -y
  Vec3 n, bary;
  const float above = couplingConstraint(Vec3(0.2f, 0.05f, 0.2f), a, b, c, -1.0f, 0.01f, n, bary);
  EXPECT_NEAR(above, 0.04f, 1e-6f);
  EXPECT_NEAR(n.y(), -1.0f, 1e-6f);
  EXPECT_NEAR(bary.sum(), 1.0f, 1e-6f);
  // the gradient wrt x_q is side * n: check by finite differences
  const float e = 1e-3f;
  for (int k = 0; k < 3; ++k) {
    Vec3 dp = Vec3::Zero();
    dp[k] = e;
    const float fd = (couplingConstraint(Vec3(0.2f, 0.05f, 0.2f) + dp, a, b, c, -1.0f, 0.01f, n, bary) -
                      couplingConstraint(Vec3(0.2f, 0.05f, 0.2f) - dp, a, b, c, -1.0f, 0.01f, n, bary)) / (2 * e);
    EXPECT_NEAR(fd, -n[k], 1e-3f);
  }
  // crossed to the other side: violated by the depth plus the thickness
  EXPECT_NEAR(couplingConstraint(Vec3(0.2f, -0.02f, 0.2f), a, b, c, -1.0f, 0.01f, n, bary), -0.03f, 1e-6f);
}

TEST(Coupling, FastDropletDoesNotCrossAPinnedCloth) {
  // single droplets thrown at 2 m/s at a fully pinned sheet: they stop on it
  Scene scene = sceneFromJson(R"({
    "solver": {"dt": 0.015, "substeps": 2, "domain": {"min": [-1, -1, -1], "max": [1, 2, 1]}},
    "cloth": [{"mesh": {"type": "rectangle", "center": [0, 0.5, 0], "size": [0.4, 0.4], "resolution": [21, 21]},
               "pin": {"region": {"min": [-1, -1, -1], "max": [1, 1, 1]}}}],
    "emitters": [{"type": "block", "min": [-0.1, 0.6, -0.1], "max": [0.1, 0.62, 0.1], "velocity": [0.3, -2, 0.1]}]
  })");
  runSteps(scene, 60);
  const Particles& p = scene.state.particles;
  ASSERT_GT(p.size(), static_cast<size_t>(scene.model.numCloth));
  for (size_t i = static_cast<size_t>(scene.model.numCloth); i < p.size(); ++i) {
    const float y = clothHeightAt(scene.model, p, p.x[i].x(), p.x[i].z());
    if (!std::isnan(y)) EXPECT_GT(p.x[i].y(), y) << "water particle " << i << " crossed the cloth";
  }
}

TEST(Coupling, DropletFasterThanItsSupportRadiusPerStepDoesNotTunnel) {
  // 8 m/s at one substep of 0.015 s: 0.12 m per step, three support radii. The particles' predicted
  // positions are already past the sheet, beyond its neighbours: the crossing must be found on the
  // way (their path), not around where they end up
  Scene scene = sceneFromJson(R"({
    "solver": {"dt": 0.015, "substeps": 1, "gravity": [0, 0, 0], "domain": {"min": [-1, -1, -1], "max": [1, 2, 1]}},
    "cloth": [{"mesh": {"type": "rectangle", "center": [0, 0.5, 0], "size": [0.4, 0.4], "resolution": [21, 21]},
               "pin": {"region": {"min": [-1, -1, -1], "max": [1, 1, 1]}}}],
    "emitters": [{"type": "block", "min": [-0.1, 0.56, -0.1], "max": [0.1, 0.58, 0.1], "velocity": [1.5, -8, 0.7]}]
  })");
  for (int s = 0; s < 10; ++s) {
    runSteps(scene, 1);
    const Particles& p = scene.state.particles;
    ASSERT_GT(p.size(), static_cast<size_t>(scene.model.numCloth));
    for (size_t i = static_cast<size_t>(scene.model.numCloth); i < p.size(); ++i) {
      const float y = clothHeightAt(scene.model, p, p.x[i].x(), p.x[i].z());
      if (!std::isnan(y)) EXPECT_GT(p.x[i].y(), y) << "water particle " << i << " crossed the cloth in step " << s;
    }
  }
}

TEST(Coupling, SheetSweptPastStillWaterCarriesItAlong) {
  // a free sheet thrown up at 3.2 m/s into a layer of still water 1.5 cm above it: in one step of
  // 0.015 s the sheet moves 4.8 cm and its predicted position lies 3.3 cm beyond the water. The
  // candidate search must reach that far (its reach grows with the cloth's motion in the substep),
  // or the water is left behind, under the sheet
  Scene scene = sceneFromJson(R"({
    "solver": {"dt": 0.015, "substeps": 1, "gravity": [0, 0, 0], "domain": {"min": [-1, -1, -1], "max": [1, 2, 1]}},
    "cloth": [{"mesh": {"type": "rectangle", "center": [0, 0.5, 0], "size": [0.4, 0.4], "resolution": [41, 41]}}],
    "emitters": [{"type": "block", "min": [-0.1, 0.505, -0.1], "max": [0.1, 0.525, 0.1]}]
  })");
  WorkspacePtr ws = makeWorkspace();
  StepStats stats;
  step(scene.model, scene.state, *ws, scene.model.solver.dt, stats);  // the block appears
  Particles& p = scene.state.particles;
  ASSERT_GT(p.size(), static_cast<size_t>(scene.model.numCloth));
  for (size_t i = 0; i < p.size(); ++i) p.v[i] = i < static_cast<size_t>(scene.model.numCloth) ? Vec3(0, 3.2f, 0) : Vec3::Zero();
  const float sheet0 = p.x[0].y();
  step(scene.model, scene.state, *ws, scene.model.solver.dt, stats);
  ASSERT_GT(p.x[0].y() - sheet0, 0.04f);  // the sheet really moved past the water's start
  size_t over = 0;
  for (size_t i = static_cast<size_t>(scene.model.numCloth); i < p.size(); ++i) {
    const float y = clothHeightAt(scene.model, p, p.x[i].x(), p.x[i].z());
    ASSERT_FALSE(std::isnan(y));
    EXPECT_GT(p.x[i].y(), y) << "water particle " << i << " was left under the sheet";
    ++over;
  }
  EXPECT_GT(over, 50u);
}

TEST(Coupling, RigidCouplingPassHoldsWaterAtDryTrianglesOnly) {
  // a flat sheet and a water particle whose path goes through it: the rigid pass puts it back above
  // the dry triangles under it, and lets it through where they are wet (Eq. 22), also when every other
  // triangle is dry or when none is (the pass then does nothing at all)
  const auto run = [](float under, float elsewhere) {
    Scene scene = sceneFromJson(R"({
      "solver": {"gravity": [0, 0, 0], "domain": {"min": [-1, -1, -1], "max": [1, 1, 1]}},
      "cloth": [{"mesh": {"type": "rectangle", "center": [0, 0, 0], "size": [0.16, 0.16], "resolution": [9, 9],
                 "axisU": [1, 0, 0], "axisV": [0, 0, 1]}}]
    })");
    Particles& p = scene.state.particles;
    const Vec3 from(0.03f, 0.01f, 0.025f), to(0.03f, -0.02f, 0.025f);
    p.add(kWaterPhase, 1000, scene.model.water.particleMass, scene.model.water.supportRadius, from, Vec3::Zero());
    p.xPred.back() = to;
    CouplingScratch s;
    findCouplingCandidates(scene.model, p, s);
    s.triangleStiffness.assign(scene.model.triangles.size(), elsewhere);
    for (size_t t = 0; t < scene.model.triangles.size(); ++t) {
      Vec3 c = Vec3::Zero();
      for (int v : scene.model.triangles[t]) c += p.x[static_cast<size_t>(v)] / 3.0f;
      if ((c - Vec3(from.x(), 0.0f, from.z())).norm() < 0.03f) s.triangleStiffness[t] = under;
    }
    solveCoupling(scene.model, p, s, true);
    return p.xPred.back().y();
  };
  EXPECT_GT(run(1.0f, 1.0f), 0.0f);   // dry everywhere: held above
  EXPECT_GT(run(1.0f, 0.3f), 0.0f);   // dry under it, wet elsewhere: held
  EXPECT_FLOAT_EQ(run(0.3f, 1.0f), -0.02f);  // wet under it: through
  EXPECT_FLOAT_EQ(run(0.3f, 0.3f), -0.02f);  // wet everywhere: through, the pass skipped
}

// Coulomb friction between water and cloth (water.clothFriction): a particle that slides 2 cm over a
// fixed sheet while sinking 5 mm into its thickness keeps 2 cm - mu 5 mm of its slip, all of it at
// mu = 0, none once mu times the push covers the slip; the normal push is the same
TEST(Coupling, WaterClothFrictionIsCoulombsLaw) {
  const auto run = [](float mu) {
    Scene scene = sceneFromJson(R"({
      "solver": {"gravity": [0, 0, 0], "domain": {"min": [-1, -1, -1], "max": [1, 1, 1]}},
      "cloth": [{"mesh": {"type": "rectangle", "center": [0, 0, 0], "size": [0.16, 0.16], "resolution": [9, 9],
                 "axisU": [1, 0, 0], "axisV": [0, 0, 1]}, "material": {"thickness": 0.01}}]
    })");
    scene.model.water.clothFriction = mu;
    Particles& p = scene.state.particles;
    p.add(kWaterPhase, 1000, scene.model.water.particleMass, scene.model.water.supportRadius,
          Vec3(0.0f, 0.01f, 0.025f), Vec3::Zero());
    p.xPred.back() = Vec3(0.02f, 0.005f, 0.025f);
    CouplingScratch s;
    findCouplingCandidates(scene.model, p, s);
    s.triangleStiffness.assign(scene.model.triangles.size(), 1.0f);
    solveCoupling(scene.model, p, s, true);
    return p.xPred.back();
  };
  for (float mu : {0.0f, 1.0f, 2.0f, 4.0f, 10.0f}) {
    const Vec3 x = run(mu);
    EXPECT_NEAR(x.x(), std::max(0.0f, 0.02f - mu * 0.005f), 1e-5f) << "mu " << mu;
    EXPECT_NEAR(x.y(), 0.01f, 1e-5f) << "mu " << mu;
    EXPECT_NEAR(x.z(), 0.025f, 1e-6f) << "mu " << mu;
  }
}

TEST(Coupling, Fig3aNoWaterCrossesTheCloth) {
  // Fig. 3(a) of Shao 2017 at full size for 2 simulated seconds, checked after every step: a particle
  // that passed through the sheet and then left the domain is caught too (825 crossings in the first
  // 0.6 s before the tethers and the coupling's sheet side were mended)
  Scene scene = sceneFromFile("scenes/fig3a_cube_on_cloth.json");
  const int steps = static_cast<int>(std::ceil(2.0 / scene.model.solver.dt));
  WorkspacePtr ws = makeWorkspace();
  CrossingCounter counter(scene.model, 0.05f);
  StepStats stats;
  size_t crossed = 0;
  for (int s = 0; s < steps; ++s) {
    step(scene.model, scene.state, *ws, scene.model.solver.dt, stats);
    const size_t now = counter.update(scene.model, scene.state.particles);
    EXPECT_EQ(now, 0u) << "water crossed the cloth in step " << s << ", first id " << (now ? counter.crossedIds()[0] : 0);
    crossed += now;
  }
  EXPECT_GT(stats.couplingContacts, 0u);  // the water really lay on the cloth
  EXPECT_EQ(crossed, 0u);
  // part of it splashes and runs off the edges; the bag holds the rest
  const Particles& p = scene.state.particles;
  size_t over = 0;
  for (size_t i = static_cast<size_t>(scene.model.numCloth); i < p.size(); ++i) {
    const float y = clothHeightAt(scene.model, p, p.x[i].x(), p.x[i].z());
    if (!std::isnan(y) && p.x[i].y() > y) ++over;
  }
  EXPECT_GT(over, 2000u);
}

