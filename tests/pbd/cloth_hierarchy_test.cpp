// the PBD cloth's coarse levels (solver.clothHierarchy) and the passes near the pins
// (solver.clothPinPasses, both src/pbd/cloth_hierarchy.cpp): a sheet without tethers hangs within 10% of
// its length at Fig. 5's small steps, and the pin passes hold the edges at its pins at Fig. 1's; the
// levels keep a free piece's momentum whatever its wet masses, never push a slack sheet, leave held
// particles alone and do nothing unasked; the pin passes move only the inextensible edges near a pin;
// the same state on any thread count
#include "support/run_scene.hpp"

#include "pbd/cloth.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

using namespace soak;
using namespace soak::testing;

namespace {

// a sheet of resolution^2 particles 1 cm apart of Table 1's mass (60 x 60: 24 kg), tethers off, 24 small
// steps of one iteration a substep (Fig. 5's), 6 coarse levels (the default)
std::string sheet(bool pinned, int resolution = 60) {
  const std::string r = std::to_string(resolution), size = std::to_string(0.01 * (resolution - 1));
  return std::string(R"({
  "solver": {"dt": 0.015, "substeps": 2, "clothSubsteps": 24, "clothIterations": 1, "clothHierarchy": 6,
             "domain": {"min": [-2, -2, -2], "max": [2, 3, 2]}},
  "cloth": [{"mesh": {"type": "rectangle", "center": [0, 1.5, 0], "size": [)") + size + "," + size +
         R"(], "resolution": [)" + r + "," + r + R"(],
                      "axisU": [1, 0, 0], "axisV": [0, 1, 0]},
             "material": {"particleMass": 0.0066, "restDensity": 800, "tetherSlack": 1000})" +
         (pinned ? R"(, "pin": {"corners": [2, 3]}}]})" : "}]}");
}

std::vector<float> strains(const Scene& scene, const std::vector<Vec3>& x) {
  const StretchConstraints& st = scene.model.stretch;
  std::vector<float> out(st.ids.size());
  for (size_t k = 0; k < st.ids.size(); ++k) out[k] = (x[st.ids[k][0]] - x[st.ids[k][1]]).norm() / st.restLength[k] - 1.0f;
  return out;
}

float maxStrain(const Scene& scene, const std::vector<Vec3>& x) {
  const std::vector<float> s = strains(scene, x);
  return *std::max_element(s.begin(), s.end());
}

// sum_i m_i d_i: a move's change of it is the momentum it gives, times the step
Vec3d massMoment(const Particles& p, int n, const std::vector<Vec3>& d) {
  Vec3d sum = Vec3d::Zero();
  for (int i = 0; i < n; ++i) sum += double(p.mass[i]) * d[i].cast<double>();
  return sum;
}

// x* set to the rest shape scaled by `scale` about the sheet's centre, plus a jitter of 0.03 mm
void scaleAbout(Particles& p, int n, float scale, std::mt19937& rng) {
  std::uniform_real_distribution<float> jitter(-3e-5f, 3e-5f);
  for (int i = 0; i < n; ++i)
    p.xPred[i] = Vec3(0, 1.5f, 0) + scale * (p.x[i] - Vec3(0, 1.5f, 0)) + Vec3(jitter(rng), jitter(rng), jitter(rng));
}

}  // namespace

TEST(ClothHierarchy, ASheetWithoutTethersHangsNearItsLength) {
  Scene off = sceneFromJson(sheet(true, 100), {"solver.clothHierarchy=0", "solver.clothPinPasses=0"});
  runSteps(off, 40);
  Scene on = sceneFromJson(sheet(true, 100));
  runSteps(on, 40);
  const float strainOff = maxStrain(off, off.state.particles.x), strainOn = maxStrain(on, on.state.particles.x);
  // the 1 m sheet of validation/hanging_cloth.json, measured at 0.6 s: 66% without the levels and the pin
  // passes, 7.4% with the levels alone, 3.0% with both (issue 22's target without tethers: 10%)
  EXPECT_GT(strainOff, 0.4f);
  EXPECT_LT(strainOn, 0.06f);
}

namespace {

// the largest edge strain over the first 0.9 s of the sheet at Fig. 1's and 6's 16 small steps, its
// release from rest shape included (sampled every step)
float peakStrainAtSixteenSmallSteps(const char* pinPasses) {
  Scene scene = sceneFromJson(sheet(true, 100), {"solver.clothSubsteps=16", pinPasses});
  float peak = 0.0f;
  for (int step = 0; step < 60; ++step) {
    runSteps(scene, 1);
    peak = std::max(peak, maxStrain(scene, scene.state.particles.x));
  }
  return peak;
}

}  // namespace

// at 16 small steps the levels alone leave the edges next to the pins, which carry the sheet's weight,
// stretched far more than the rest of the sheet; the pin passes hold them (validation/case_cloth.py
// measures the same sheet at rest over 3 s: 8.9% against 15.3%)
TEST(ClothHierarchy, PinPassesHoldTheEdgesNearThePinsAtSixteenSmallSteps) {
  const float levels = peakStrainAtSixteenSmallSteps("solver.clothPinPasses=0");
  const float both = peakStrainAtSixteenSmallSteps("solver.clothPinPasses=8");
  // measured: 28.0% against 15.7%
  EXPECT_GT(levels, 0.24f);
  EXPECT_LT(both, 0.18f);
}

namespace {

// a pinned sheet stretched by 5% and the pin passes alone (no levels) applied to it; returns the moves
std::vector<Vec3> pinPassesOnAStretchedSheet(const Scene& scene, Particles& p, std::mt19937& rng,
                                             std::vector<Vec3>& before) {
  const int n = scene.model.numCloth;
  scaleAbout(p, n, 1.05f, rng);
  std::vector<Vec3> d(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) d[i] = p.xPred[i] - p.x[i];
  before = d;
  ClothScratch scratch;
  solveHierarchyFrom(scene.model, p.x.data(), d.data(), p.invMass.data(), scratch);
  return d;
}

// the largest strain of the edges at a pin, on x + d
float pinEdgeStrain(const Scene& scene, const Particles& p, const std::vector<Vec3>& d) {
  const Model& model = scene.model;
  const StretchConstraints& st = model.stretch;
  float out = 0.0f;
  for (size_t k = 0; k < st.ids.size(); ++k) {
    const auto [a, b] = st.ids[k];
    if (model.clothPinned[a] || model.clothPinned[b])
      out = std::max(out, ((p.x[a] + d[a]) - (p.x[b] + d[b])).norm() / st.restLength[k] - 1.0f);
  }
  return out;
}

}  // namespace

// the pin passes alone (no levels) on a sheet stretched by 5%: only particles within clothPinRings edges
// of a pin move (5 rings of 1-1.4 cm edges: within 7.1 cm), the pins themselves stay, and enough passes
// bring the edges at the pins to their length; a compliant sheet's edges are not theirs to hold
TEST(ClothHierarchy, PinPassesMoveOnlyTheInextensibleEdgesNearThePins) {
  std::mt19937 rng(5);
  for (const char* set : {"solver.clothPinPasses=8", "solver.clothPinPasses=64"}) {
    Scene scene = sceneFromJson(sheet(true), {"solver.clothHierarchy=0", set});
    Particles& p = scene.state.particles;
    const Model& model = scene.model;
    std::vector<Vec3> before;
    const std::vector<Vec3> d = pinPassesOnAStretchedSheet(scene, p, rng, before);
    std::vector<Vec3> pins;
    for (int i = 0; i < model.numCloth; ++i)
      if (model.clothPinned[i]) pins.push_back(model.clothRestPosition[i]);
    ASSERT_EQ(pins.size(), 2u);
    float farthest = 0.0f;
    for (int i = 0; i < model.numCloth; ++i) {
      if (d[i] == before[i]) continue;
      EXPECT_FALSE(model.clothPinned[i]);
      const Vec3& x = model.clothRestPosition[i];
      farthest = std::max(farthest, std::min((x - pins[0]).norm(), (x - pins[1]).norm()));
    }
    EXPECT_GT(farthest, 0.04f) << set;
    EXPECT_LT(farthest, 0.0711f) << set;
    // 5.1-5.4% before; 64 passes bring the edges at the pins to 0.42% (their rest length is the passes'
    // fixed point; 8 passes, as many as a small step takes, leave 5.3% of a stretch this large, spread
    // in index order: in a run a small step's stretch near the pins is a fraction of a percent)
    EXPECT_GT(pinEdgeStrain(scene, p, before), 0.05f) << set;
    if (scene.model.solver.clothPinPasses == 64) EXPECT_LT(pinEdgeStrain(scene, p, d), 0.005f) << set;
  }
  Scene compliant = sceneFromJson(sheet(true), {"solver.clothHierarchy=0", "cloth.0.material.stretchCompliance=1e-4"});
  std::vector<Vec3> before;
  EXPECT_EQ(pinPassesOnAStretchedSheet(compliant, compliant.state.particles, rng, before), before);
}

TEST(ClothHierarchy, KeepsAFreePiecesMomentumWhateverItsWetMassesAndNeverPushes) {
  Scene scene = sceneFromJson(sheet(false));
  Particles& p = scene.state.particles;
  const int n = scene.model.numCloth;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> wet(1.0f, 4.0f);
  for (int i = 0; i < n; ++i) p.setMass(static_cast<size_t>(i), scene.model.clothDryMass[i] * wet(rng), false);
  ClothScratch scratch;
  // stretched by 5%: the levels pull it in, keeping sum_i m_i d_i
  scaleAbout(p, n, 1.05f, rng);
  std::vector<Vec3> d(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) d[i] = p.xPred[i] - p.x[i];
  const Vec3d before = massMoment(p, n, d);
  solveHierarchyFrom(scene.model, p.x.data(), d.data(), p.invMass.data(), scratch);
  std::vector<Vec3> x(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) x[i] = p.x[i] + d[i];
  EXPECT_LT((massMoment(p, n, d) - before).norm(), 1e-5 * (1.0 + before.norm()));
  // one pass of the levels brings the sheet back to its size: its diagonal from 0.876 to 0.841 m (0.834
  // at rest), its bottom edge from 0.620 to 0.597 m (0.59), measured; the kinks its moves leave between
  // the clusters' particles are the constraint iterations' to remove
  const float diagonal = (p.x[n - 1] - p.x[0]).norm();
  EXPECT_GT((p.xPred[n - 1] - p.xPred[0]).norm(), 1.049f * diagonal);
  EXPECT_LT((x[n - 1] - x[0]).norm(), 1.012f * diagonal);
  EXPECT_NEAR((x[59] - x[0]).norm(), 0.59f, 0.009f);
  // shrunk by 5%: nothing is stretched, nothing moves
  scaleAbout(p, n, 0.95f, rng);
  for (int i = 0; i < n; ++i) d[i] = p.xPred[i] - p.x[i];
  const std::vector<Vec3> shrunk = d;
  solveHierarchyFrom(scene.model, p.x.data(), d.data(), p.invMass.data(), scratch);
  EXPECT_EQ(d, shrunk);
}

TEST(ClothHierarchy, LeavesHeldParticlesAloneAndDoesNothingUnasked) {
  std::mt19937 rng(3);
  for (const char* set : {"solver.clothHierarchy=0", "solver.clothHierarchy=6"}) {
    Scene scene = sceneFromJson(sheet(true), {set, "solver.clothPinPasses=0"});
    Particles& p = scene.state.particles;
    const int n = scene.model.numCloth;
    scaleAbout(p, n, 1.05f, rng);
    std::vector<Vec3> d(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) d[i] = p.xPred[i] - p.x[i];
    const std::vector<Vec3> before = d;
    ClothScratch scratch;
    solveHierarchyFrom(scene.model, p.x.data(), d.data(), p.invMass.data(), scratch);
    int moved = 0;
    for (int i = 0; i < n; ++i) {
      if (scene.model.clothPinned[i]) EXPECT_EQ(d[i], before[i]) << "a held particle stays";
      moved += d[i] != before[i];
    }
    // the levels' clusters hold the first set's particles, a quarter of the sheet (927 of 3600 moved)
    if (scene.model.solver.clothHierarchy > 0) EXPECT_GT(moved, n / 5) << set;
    else EXPECT_EQ(moved, 0) << set;
  }
}

TEST(ClothHierarchy, SameStateOnOneTwoAndThreeThreads) {
  const auto hashes = hashesOnOneTwoThreeThreads([] { return sceneFromJson(sheet(true)); }, 10, [](const Scene&) {});
  EXPECT_EQ(hashes[0], hashes[1]);
  EXPECT_EQ(hashes[0], hashes[2]);
}
