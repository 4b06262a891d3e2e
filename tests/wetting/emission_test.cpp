// emission (section 4.4, Eq. 18-19): no drip before a buffer holds m^threshold, one drip of that mass
// at it, placed without a density spike and held by the cloth; a saturated hanging cloth drains and
// drips (Fig. 6)
#include "wetting/wet_support.hpp"

#include "core/kernels.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

using namespace soak;
using namespace soak::testing;

namespace {

// SPH density at particle q: its own mass, the water and the cloth as Akinci boundary (rho0 V_b);
// particles from index `upTo` on are left out
float densityAt(const Scene& s, const WettingScratch& ws, size_t q, size_t upTo = ~size_t(0)) {
  const Particles& p = s.state.particles;
  float rho = p.mass[q] * poly6(0.0f, p.radius[q]);
  for (size_t j = 0; j < std::min(upTo, p.size()); ++j) {
    if (j == q) continue;
    const float h = pairRadius(p.radius[q], p.radius[j]);
    const float mj = j < size_t(s.model.numCloth) ? s.model.water.restDensity * ws.volume[j] : p.mass[j];
    rho += mj * poly6((p.x[q] - p.x[j]).squaredNorm(), h);
  }
  return rho;
}

// the density a drip of mass m and support hp would have at y, counting particles [0, upTo) but `skip`
float dripDensityAt(const Scene& s, const WettingScratch& ws, const Vec3& y, float m, float hp, size_t skip,
                    size_t upTo = ~size_t(0)) {
  const Particles& p = s.state.particles;
  float rho = m * poly6(0.0f, hp);
  for (size_t j = 0; j < std::min(upTo, p.size()); ++j) {
    if (j == skip) continue;
    const float mj = j < size_t(s.model.numCloth) ? s.model.water.restDensity * ws.volume[j] : p.mass[j];
    rho += mj * poly6((y - p.x[j]).squaredNorm(), pairRadius(hp, p.radius[j]));
  }
  return rho;
}

}  // namespace

TEST(WettingEmission, NoDripBelowTheThresholdOneDripAtIt) {
  // a pinned vertical sheet; its bottom row (y = 0.9) has no neighbour below to pass water to
  Scene s = sceneFromJson(R"({"cloth": [)" +
                          rectangleJson("s", Vec3(0, 1, 0), 0.2f, 0.2f, 11, 11, "[1, 0, 0]", "[0, 1, 0]", kPinAll) +
                          R"(], "wetting": {}})");
  StageRig rig;
  rig.refresh(s.state, s.model);
  const size_t bottom = 5;
  ASSERT_NEAR(s.state.particles.x[bottom].y(), 0.9f, 1e-6f);
  // m^threshold is per wetting.referenceArea (Table 1's 0.02 m cell): this edge particle has half a cell
  const float share = areaShare(s.model.wetting.referenceArea, s.model.clothRestArea[bottom]);
  ASSERT_NEAR(share, 0.5f, 1e-5f);
  const float thr = s.model.wetting.massThreshold * share;
  s.state.clothBuffer[bottom] = 0.99 * thr;
  const float h = s.model.solver.dt;
  EXPECT_EQ(emitExcessWater(s.model, s.state, rig.nb, rig.grid, {}, rig.s, h), 0u);
  EXPECT_EQ(s.state.particles.size(), size_t(s.model.numCloth));
  EXPECT_DOUBLE_EQ(s.state.clothBuffer[bottom], 0.99 * thr);

  s.state.clothBuffer[bottom] = 1.25 * thr;
  const double before = accountedWater(s);
  EXPECT_EQ(emitExcessWater(s.model, s.state, rig.nb, rig.grid, {}, rig.s, h), 1u);
  const Particles& p = s.state.particles;
  ASSERT_EQ(p.size(), size_t(s.model.numCloth) + 1);
  const size_t q = p.size() - 1;
  EXPECT_EQ(p.mass[q], thr);
  EXPECT_NEAR(p.radius[q], std::cbrt(thr / s.model.water.particleMass) * s.model.water.supportRadius, 1e-7f);
  EXPECT_LT(p.x[q].y(), 0.9f);                                          // below the cloth
  EXPECT_LE(densityAt(s, rig.s, q), s.model.water.restDensity * 1.001f);  // no density spike
  EXPECT_GT(densityAt(s, rig.s, q), 0.5f * s.model.water.restDensity);  // but close to the cloth
  EXPECT_NEAR(s.state.clothBuffer[bottom], 0.25 * thr, 1e-12);
  EXPECT_NEAR(accountedWater(s), before, 1e-12);
  ASSERT_EQ(s.state.dripId.size(), 1u);
  EXPECT_EQ(s.state.dripId[0], p.id[q]);
  EXPECT_EQ(s.state.ledger.dripsEmitted, 1u);

  // Eq. 19: the cloth pulls its drip up towards it
  applyDripAttraction(s.model, s.state, rig.nb, rig.s, h);
  EXPECT_GT(p.v[q].y(), 0.0f);
  // the buffer feeds the hanging drip instead of starting a second one
  s.state.clothBuffer[bottom] += 1.0 * thr;
  EXPECT_EQ(emitExcessWater(s.model, s.state, rig.nb, rig.grid, {}, rig.s, h), 0u);
  EXPECT_EQ(p.size(), q + 1);
  EXPECT_NEAR(p.mass[q], 2.25f * thr, 1e-7f);
  EXPECT_NEAR(s.state.clothBuffer[bottom], 0.0, 1e-9);
  EXPECT_NEAR(accountedWater(s), before + thr, 1e-9);

  // a drip grows to four water particles' mass at most (a submerged sheet's buffers pile up, and one
  // drip taking them all made a particle of 0.7 kg in Fig. 9(b)); the rest waits in the buffer
  const float maxDrip = 4.0f * s.model.water.particleMass;
  s.state.clothBuffer[bottom] += 100.0 * thr;
  const double fed = accountedWater(s);
  EXPECT_EQ(emitExcessWater(s.model, s.state, rig.nb, rig.grid, {}, rig.s, h), 0u);
  EXPECT_FLOAT_EQ(p.mass[q], maxDrip);
  EXPECT_NEAR(s.state.clothBuffer[bottom], 102.25 * thr - maxDrip, 1e-7);
  EXPECT_NEAR(accountedWater(s), fed, 1e-12 * fed);
  // then it is let go (no longer the source's drip, so no longer held by Eq. 19) and a new one starts
  rig.refresh(s.state, s.model);
  const uint32_t old = p.id[q];
  EXPECT_EQ(emitExcessWater(s.model, s.state, rig.nb, rig.grid, {}, rig.s, h), 1u);
  ASSERT_EQ(s.state.dripId.size(), 1u);
  EXPECT_NE(s.state.dripId[0], old);
  EXPECT_FLOAT_EQ(s.state.particles.mass[q], maxDrip);
  EXPECT_NEAR(accountedWater(s), fed, 1e-12 * fed);
}

// a drip is never placed inside a collider, nor on the top face of a sheet lying flat: under a sheet on
// the floor the next substep pushed it out through the far side of the thin floor, one inside a ball
// was flung off it at metres a second, and one on top was pushed into the sheet and flung (Fig. 9(b)).
// The buffer keeps its water (Eq. 18 runs it down to an edge)
TEST(WettingEmission, NoDripInsideACollider) {
  for (const char* collider : {R"({"type": "plane"})", R"({"type": "sphere", "radius": 0.3, "position": [0, -0.3, 0]})"}) {
    // a horizontal sheet 2 mm above the floor, or lying on the top of the ball
    Scene s = sceneFromJson(R"({"colliders": [)" + std::string(collider) + R"(], "cloth": [)" +
                            rectangleJson("s", Vec3(0, 0.002f, 0), 0.2f, 0.2f, 11, 11, "[1, 0, 0]", "[0, 0, 1]", kPinAll) +
                            R"(], "wetting": {}})");
    StageRig rig;
    rig.refresh(s.state, s.model);
    const std::vector<ColliderPose> poses{colliderPose(s.model.colliders[0], 0.0)};
    const float thr = s.model.wetting.massThreshold;
    const size_t mid = 5 * 11 + 5;
    s.state.clothBuffer[mid] = 1.25 * thr;
    const double before = accountedWater(s);
    Scene unaware = s;  // the same without the collider: its first place is below the sheet, in the solid
    ASSERT_EQ(emitExcessWater(unaware.model, unaware.state, rig.nb, rig.grid, {}, rig.s, s.model.solver.dt), 1u);
    EXPECT_LT(colliderDistance(s.model.colliders[0], poses[0], unaware.state.particles.x.back(), nullptr), 0.0f) << collider;
    EXPECT_EQ(emitExcessWater(s.model, s.state, rig.nb, rig.grid, poses, rig.s, s.model.solver.dt), 0u) << collider;
    EXPECT_EQ(s.state.particles.size(), size_t(s.model.numCloth));
    EXPECT_DOUBLE_EQ(s.state.clothBuffer[mid], 1.25 * thr);
    EXPECT_NEAR(accountedWater(s), before, 1e-12);
  }
  // the same sheet hung vertically 0.3 m above the floor drips below its bottom edge, clear of the floor
  Scene v = sceneFromJson(R"({"colliders": [{"type": "plane"}], "cloth": [)" +
                          rectangleJson("s", Vec3(0, 0.4f, 0), 0.2f, 0.2f, 11, 11, "[1, 0, 0]", "[0, 1, 0]", kPinAll) +
                          R"(], "wetting": {}})");
  StageRig rig;
  rig.refresh(v.state, v.model);
  v.state.clothBuffer[5] = 1.25 * v.model.wetting.massThreshold;  // bottom row, y = 0.3
  const std::vector<ColliderPose> poses{colliderPose(v.model.colliders[0], 0.0)};
  ASSERT_EQ(emitExcessWater(v.model, v.state, rig.nb, rig.grid, poses, rig.s, v.model.solver.dt), 1u);
  EXPECT_LT(v.state.particles.x.back().y(), 0.3f);
}

TEST(WettingEmission, DripsMadeInOnePassDoNotCrowdEachOther) {
  // every particle of the bottom row is due a drip at once: their places are 0.01 m apart and a drip's
  // support is 0.025 m, so each drip must account for those made before it in the same pass (the
  // placement is searched in parallel, then settled in cloth order)
  Scene s = sceneFromJson(R"({"cloth": [)" +
                          rectangleJson("s", Vec3(0, 1, 0), 0.2f, 0.2f, 21, 21, "[1, 0, 0]", "[0, 1, 0]", kPinAll) +
                          R"(], "wetting": {"c": 4e-4, "referenceArea": 0}})");  // a 0.01 m cloth holds the 2 g threshold (docs/models.md on c)
  StageRig rig;
  rig.refresh(s.state, s.model);
  const float thr = s.model.wetting.massThreshold;
  for (size_t c = 0; c < 21; ++c) s.state.clothBuffer[c] = 1.25 * thr;  // row y = 0.9
  const double before = accountedWater(s);
  const size_t made = emitExcessWater(s.model, s.state, rig.nb, rig.grid, {}, rig.s, s.model.solver.dt);
  EXPECT_GE(made, 3u);
  EXPECT_LE(made, 21u);
  const Particles& p = s.state.particles;
  ASSERT_EQ(p.size(), size_t(s.model.numCloth) + made);
  ASSERT_EQ(s.state.dripSource.size(), made);
  const float hDrip = std::cbrt(thr / s.model.water.particleMass) * s.model.water.supportRadius;
  const float rho0 = s.model.water.restDensity;
  const auto firstPlace = [&](size_t src) { return Vec3(p.x[src] + Vec3(0, -0.25f * hDrip, 0)); };
  // the row crowds itself: at its first place, a quarter of h_p straight below its source, the middle
  // drip has room beside the cloth alone, but not beside the cloth and the 20 others at their first
  // places (so the test is not passed by drips that never meet)
  {
    const size_t nc = size_t(s.model.numCloth);
    const float clothOnly = dripDensityAt(s, rig.s, firstPlace(10), thr, hDrip, ~size_t(0), nc);
    float rhoMid = clothOnly;
    for (size_t c = 0; c < 21; ++c)
      if (c != 10) rhoMid += thr * poly6((firstPlace(c) - firstPlace(10)).squaredNorm(), hDrip);
    EXPECT_LT(clothOnly, rho0);
    EXPECT_GT(rhoMid, rho0);
  }
  std::vector<int> dripOf(21, -1);
  int movedOn = 0;
  for (size_t d = 0; d < made; ++d) {
    const size_t q = size_t(s.model.numCloth) + d, src = size_t(s.state.dripSource[d]);
    ASSERT_LT(src, 21u);
    dripOf[src] = int(q);
    // when it was made: the drips made before it included (a later one may add to it)
    EXPECT_LE(densityAt(s, rig.s, q, q + 1), rho0 * 1.001f) << q;
    // a drip moved on from its first place only where that place is crowded (later drips only add)
    if ((p.x[q] - firstPlace(src)).norm() > 1e-6f) {
      ++movedOn;
      EXPECT_GT(dripDensityAt(s, rig.s, firstPlace(src), thr, hDrip, q), rho0 * 0.999f) << "drip " << q;
    }
  }
  // a source got no drip only where its first place is crowded by the drips that were made
  for (size_t c = 0; c < 21; ++c)
    if (dripOf[c] < 0) EXPECT_GT(dripDensityAt(s, rig.s, firstPlace(c), thr, hDrip, ~size_t(0)), rho0 * 0.999f) << c;
  EXPECT_GT(movedOn + int(21 - made), 0);  // and the crowding was resolved by moving or skipping drips
  EXPECT_NEAR(accountedWater(s), before, 1e-12);
}

TEST(WettingEmission, ExcessRunsDownAVerticalSheet) {
  // held water above S^EW goes to the buffers, and the buffers move down (Eq. 18)
  Scene s = sceneFromJson(R"({"cloth": [)" +
                          rectangleJson("s", Vec3(0, 1, 0), 0.2f, 0.4f, 11, 21, "[1, 0, 0]", "[0, 1, 0]", kPinAll) +
                          R"(], "wetting": {"referenceArea": 0, "saturation": {"initial": 0.4}, "emission": {"massThreshold": 0.005}}})");
  StageRig rig;
  rig.refresh(s.state, s.model);
  const double before = accountedWater(s);
  const auto rowBuffer = [&](int r) {
    double b = 0.0;
    for (int c = 0; c < 11; ++c) b += s.state.clothBuffer[size_t(r * 11 + c)];
    return b;
  };
  for (int it = 0; it < 20; ++it) emitExcessWater(s.model, s.state, rig.nb, rig.grid, {}, rig.s, s.model.solver.dt);
  EXPECT_NEAR(accountedWater(s), before, 1e-12 * before);
  // held water is capped at S^EW
  for (float si : s.state.clothSaturation) EXPECT_LE(si, s.model.wetting.saturationEmit * (1.0f + 1e-5f));
  // the bottom row gathered the excess of the rows above; the top row, fed by nobody, drained
  EXPECT_GT(rowBuffer(0), 2.0 * rowBuffer(10));
  EXPECT_LT(rowBuffer(20), 0.5 * rowBuffer(10));
  // without gravity nothing moves down: every buffer keeps its own excess
  Scene flat = sceneFromJson(R"({"solver": {"gravity": [0, 0, 0]}, "cloth": [)" +
                             rectangleJson("s", Vec3(0, 1, 0), 0.2f, 0.4f, 11, 21, "[1, 0, 0]", "[0, 1, 0]", kPinAll) +
                             R"(], "wetting": {"referenceArea": 0, "saturation": {"initial": 0.4}, "emission": {"massThreshold": 0.005}}})");
  rig.refresh(flat.state, flat.model);
  emitExcessWater(flat.model, flat.state, rig.nb, rig.grid, {}, rig.s, flat.model.solver.dt);
  const size_t mid = 10 * 11 + 5;
  EXPECT_NEAR(flat.state.clothBuffer[mid], (0.4 - 0.35) * rig.s.volume[mid] / flat.model.wetting.c, 1e-9);
}

// a buffer that already holds m^threshold (a drip that found no place: under water the water around is
// at rest density) takes no more water, neither its particle's excess nor the flow from above, so a
// sheet under water does not pump the pool into its buffers (Fig. 5's buffers grew by 0.4 kg every
// 0.3 s, Fig. 9(b)'s reached 3 kg on one particle)
TEST(WettingEmission, AFullBufferTakesNoMore) {
  const char* kWet = R"(], "wetting": {"referenceArea": 0, "saturation": {"initial": 0.4}, "emission": {"massThreshold": 0.005}}})";
  for (bool fullBuffer : {false, true}) {
    Scene s = sceneFromJson(R"({"cloth": [)" +
                            rectangleJson("s", Vec3(0, 1, 0), 0.2f, 0.4f, 11, 21, "[1, 0, 0]", "[0, 1, 0]", kPinAll) + kWet);
    StageRig rig;
    rig.refresh(s.state, s.model);
    const double thr = s.model.wetting.massThreshold;
    const size_t k = 5, above = 11 + 5;  // the middle of the bottom row (nothing below it) and the one above
    ASSERT_GT(s.state.particles.x[above].y(), s.state.particles.x[k].y());
    s.state.clothBuffer[k] = fullBuffer ? thr : 0.0;
    const double held = s.state.clothWater[k], before = accountedWater(s);
    const size_t made = emitExcessWater(s.model, s.state, rig.nb, rig.grid, {}, rig.s, s.model.solver.dt);
    EXPECT_NEAR(accountedWater(s), before, 1e-12 * before);
    if (fullBuffer) {
      EXPECT_DOUBLE_EQ(s.state.clothWater[k], held);  // kept above S^EW: Eq. 11 stops absorbing at S^MAX
      EXPECT_EQ(made, 1u);                             // the full buffer made its drip (in air here)
      EXPECT_DOUBLE_EQ(s.state.clothBuffer[k], 0.0);  // and nothing came in, from it or from above
    } else {
      EXPECT_EQ(made, 0u);
      EXPECT_LT(s.state.clothWater[k], held);  // the excess went to the buffer, and more came from above
      EXPECT_GT(s.state.clothBuffer[k], held - s.state.clothWater[k]);
    }
    EXPECT_GT(s.state.clothBuffer[above], 0.0);  // the particle above has its own excess either way
  }
}

TEST(WettingEmission, SaturatedHangingClothDrainsAndDrips) {
  // Fig. 6, scaled down: a saturated cloth hung by two corners; the excess gathers at the bottom edge,
  // forms drips there and the drips fall
  Scene s = sceneFromJson(R"({"solver": {"dt": 0.015, "substeps": 2},
      "cloth": [)" + rectangleJson("s", Vec3(0, 1, 0), 0.3f, 0.3f, 16, 16, "[1, 0, 0]", "[0, 1, 0]",
                                   R"({"corners": [2, 3]})") +
                          R"(], "wetting": {"saturation": {"initial": 0.4}}})");
  const double emitted = s.state.ledger.emitted;
  WorkspacePtr ws = makeWorkspace();
  StepStats st;
  double maxBufferBeforeFirstDrip = 0.0;
  for (int k = 0; k < 150; ++k) {
    if (s.state.ledger.dripsEmitted == 0)
      maxBufferBeforeFirstDrip = std::max(maxBufferBeforeFirstDrip,
                                          *std::max_element(s.state.clothBuffer.begin(), s.state.clothBuffer.end()));
    step(s.model, s.state, *ws, s.model.solver.dt, st);
  }
  EXPECT_GT(s.state.ledger.dripsEmitted, 0u);
  EXPECT_LT(maxBufferBeforeFirstDrip, double(s.model.wetting.massThreshold));
  EXPECT_NEAR(accountedWater(s), emitted, 1e-9 * emitted);
  // some drip fell well below the cloth's lowest point
  const Particles& p = s.state.particles;
  float lowestCloth = 1e9f, lowestWater = 1e9f;
  for (size_t i = 0; i < p.size(); ++i)
    (i < size_t(s.model.numCloth) ? lowestCloth : lowestWater) =
        std::min(i < size_t(s.model.numCloth) ? lowestCloth : lowestWater, p.x[i].y());
  EXPECT_TRUE(lowestWater < lowestCloth - 0.1f || s.state.ledger.particlesRemovedAtBounds > 0);
}

// Eq. 18's flow from an upper particle's buffer: rate cos V_u W EW_u, linear in each factor, 0 with
// no slope; the outflow and net-flow loops both take it from bufferFlow
TEST(WettingEmission, BufferFlowIsEq18) {
  const double rate = 0.25, bu = 3e-5;
  const float cosLU = 0.6f, vu = 2e-7f, w = 1.5e5f;
  const double expected = rate * double(cosLU) * double(vu) * double(w) * bu;
  EXPECT_NEAR(bufferFlow(rate, cosLU, vu, w, bu), expected, 1e-6 * expected);
  EXPECT_NEAR(bufferFlow(2.0 * rate, cosLU, vu, w, bu), 2.0 * expected, 2e-6 * expected);
  EXPECT_NEAR(bufferFlow(rate, 0.5f * cosLU, vu, w, bu), 0.5 * expected, 1e-6 * expected);
  EXPECT_EQ(bufferFlow(rate, 0.0f, vu, w, bu), 0.0);
}

TEST(WettingEmission, MassFollowsTheBuffersAndTheDripsForAnyDt) {
  // a pinned vertical sheet above S^EW: its buffers run down and drip. After the stage every cloth
  // particle's mass is dry + held + buffer, and the water moved per unit time: one pass of 0.03 s moves
  // what two passes of 0.015 s move (Eq. 18's transfer cut into parts of rateStep)
  const auto run = [](float h, int passes) {
    Scene s = sceneFromJson(R"({"cloth": [)" +
                            rectangleJson("s", Vec3(0, 1, 0), 0.2f, 0.2f, 11, 11, "[1, 0, 0]", "[0, 1, 0]", kPinAll) +
                            R"(], "wetting": {"saturation": {"initial": 0.38}, "emission": {"massThreshold": 0.005}}})");
    StageRig rig;
    rig.refresh(s.state, s.model);
    const double before = accountedWater(s);
    for (int k = 0; k < passes; ++k) emitExcessWater(s.model, s.state, rig.nb, rig.grid, {}, rig.s, h);
    for (int i = 0; i < s.model.numCloth; ++i)
      EXPECT_EQ(s.state.particles.mass[i], s.model.clothDryMass[i] + float(s.state.clothWater[i] + s.state.clothBuffer[i]));
    EXPECT_NEAR(accountedWater(s), before, 1e-12 * before);
    return s.state.clothBuffer;
  };
  const std::vector<double> one = run(0.03f, 1), two = run(0.015f, 2);
  double most = 0.0, diff = 0.0;
  for (size_t k = 0; k < one.size(); ++k) most = std::max(most, two[k]), diff = std::max(diff, std::fabs(one[k] - two[k]));
  EXPECT_GT(most, 0.0);
  EXPECT_LT(diff, 1e-9 * most + 1e-15);
}
