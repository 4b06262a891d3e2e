// porosity of the cloth particles (wetting/porosity.cpp, Shao 2017 section 4.1, Eq. 10): V_i = 1 / sum_k W_ik
// over the particles of the same piece (k including i), S_i = c m^water_i / V_i, the wet mass, the
// initial water at load, and the per-pair kernel values the other wetting stages read
#include "wetting/wet_support.hpp"

#include "core/kernels.hpp"
#include "pbd/integrate.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace soak;
using namespace soak::testing;

namespace {

// V of a particle whose neighbours lie at the given distances (m), itself included: 1 / sum W(r, h), with
// W(r, h) = 315 / (64 pi h^9) (h^2 - r^2)^3 (poly6) in double
double volumeOf(const std::vector<double>& distances, double h) {
  double sum = 0.0;
  for (double r : distances)
    if (r < h) sum += 315.0 / (64.0 * M_PI * std::pow(h, 9)) * std::pow(h * h - r * r, 3);
  return 1.0 / sum;
}

// a square lattice's neighbours of an interior point within 2.5 spacings: 0, a (4), a sqrt 2 (4), 2a (4),
// a sqrt 5 (8), 2a sqrt 2 (4)
std::vector<double> latticeDistances(double a) {
  std::vector<double> d{0.0};
  const std::pair<double, int> rings[] = {{1.0, 4}, {std::sqrt(2.0), 4}, {2.0, 4}, {std::sqrt(5.0), 8}, {std::sqrt(8.0), 4}};
  for (const auto& [f, n] : rings)
    for (int k = 0; k < n; ++k) d.push_back(f * a);
  return d;
}

// neighbour lists on positions x with the scene's radii
void lists(const Particles& p, const std::vector<Vec3>& x, NeighborGrid& grid, NeighborLists& nb) {
  buildGrid(x, maxSupportRadius(p), grid);
  buildNeighborLists(x, p.radius, grid, nb);
}

}  // namespace

TEST(WettingParams, InitialSaturationFillsTheClothAndCountsAsEmitted) {
  const Scene s = sceneFromJson(kHanging, {"wetting.saturation.initial=0.4"});
  const std::vector<float> v = restVolumes(s.model, s.state.particles.radius);
  double expected = 0.0;
  for (float vi : v) expected += double(0.4f) * vi / s.model.wetting.c;
  EXPECT_NEAR(sum(s.state.clothWater), expected, 1e-9 * expected);
  EXPECT_NEAR(s.state.ledger.emitted, expected, 1e-9 * expected);
  // an interior particle of a 0.02 m sheet: V = 1 / sum W = 1.28e-5 m^3, holding 5.1 g at S^MAX
  const size_t mid = 10 * 21 + 10;
  EXPECT_NEAR(v[mid], 1.2816e-5f, 2e-8f);
  // the wet cloth is heavier: dry mass + held water; pinned corners stay kinematic
  const Particles& p = s.state.particles;
  EXPECT_NEAR(p.mass[mid], 0.0066f + 0.4f * v[mid] / 1.0e-3f, 1e-6f);
  EXPECT_NEAR(p.invMass[mid], 1.0f / p.mass[mid], 1e-3f);
  for (size_t i = 0; i < p.size(); ++i)
    if (s.model.clothPinned[i]) EXPECT_EQ(p.invMass[i], 0.0f);
}


// an interior particle of the 0.02 m sheet (h = 0.04): itself, 4 at a and 4 at a sqrt 2 (2a is on the
// kernel's edge); squeezed to 0.018 m the ring at 2a comes in and V shrinks to the new closed form.
// clothVolumes on the squeezed positions agrees with the closed form to 1e-5
TEST(WettingPorosity, InteriorVolumeIsTheLatticeKernelSum) {
  const Scene s = sceneFromJson(kHanging);
  const Model& m = s.model;
  const std::vector<float> rest = restVolumes(m, s.state.particles.radius);
  const size_t mid = 10 * 21 + 10;
  EXPECT_NEAR(rest[mid], volumeOf(latticeDistances(0.02), 0.04), 1e-5 * rest[mid]);
  // a particle on the edge (not a corner) has half the lattice: 3 at a, 2 at a sqrt 2, a larger volume
  const size_t edge = 10;
  EXPECT_NEAR(rest[edge], volumeOf({0.0, 0.02, 0.02, 0.02, 0.02 * std::sqrt(2.0), 0.02 * std::sqrt(2.0)}, 0.04),
              1e-5 * rest[edge]);
  EXPECT_GT(rest[edge], rest[mid]);
  std::vector<Vec3> squeezed = s.state.particles.x;
  for (int i = 0; i < m.numCloth; ++i) squeezed[i] = Vec3(0, 1, 0) + 0.9f * (squeezed[i] - Vec3(0, 1, 0));
  NeighborGrid grid;
  NeighborLists nb;
  lists(s.state.particles, squeezed, grid, nb);
  std::vector<float> v;
  clothVolumes(m, squeezed, s.state.particles.radius, s.state.particles.phase, nb, v);
  ASSERT_EQ(v.size(), size_t(m.numCloth));
  EXPECT_NEAR(v[mid], volumeOf(latticeDistances(0.018), 0.04), 1e-5 * v[mid]);
  EXPECT_LT(v[mid], rest[mid]);
}

// a particle with no neighbour of its piece within h has the volume of its own kernel, 64 pi h^3 / 315;
// two pieces in the same place do not count each other (same piece only), so each keeps its own volumes
TEST(WettingPorosity, PiecesDoNotShareVolume) {
  const std::string far = R"({"name": "far", "mesh": {"type": "rectangle", "center": [0, 1, 0], "size": [0.2, 0.2],
      "resolution": [2, 2], "axisU": [1, 0, 0], "axisV": [0, 1, 0]}})";
  const std::string sheet = R"({"name": "a", "mesh": {"type": "rectangle", "center": [0, 0.5, 0], "size": [0.1, 0.1],
      "resolution": [6, 6], "axisU": [1, 0, 0], "axisV": [0, 1, 0]}})";
  std::string twin = sheet;
  twin.replace(twin.find("\"a\""), 3, "\"b\"");
  const Scene one = sceneFromJson("{\"cloth\": [" + far + "], \"wetting\": {\"emission\": {\"enabled\": false}}}");
  const std::vector<float> alone = restVolumes(one.model, one.state.particles.radius);
  for (float v : alone) EXPECT_NEAR(v, 64.0 * M_PI * std::pow(0.04, 3) / 315.0, 1e-6 * v);
  const Scene single = sceneFromJson("{\"cloth\": [" + sheet + "], \"wetting\": {\"emission\": {\"enabled\": false}}}");
  const Scene doubled =
      sceneFromJson("{\"cloth\": [" + sheet + ", " + twin + "], \"wetting\": {\"emission\": {\"enabled\": false}}}");
  const std::vector<float> v1 = restVolumes(single.model, single.state.particles.radius);
  const std::vector<float> v2 = restVolumes(doubled.model, doubled.state.particles.radius);
  ASSERT_EQ(v2.size(), 2 * v1.size());
  for (size_t i = 0; i < v1.size(); ++i) {
    EXPECT_NEAR(v2[i], v1[i], 1e-6 * v1[i]) << i;
    EXPECT_NEAR(v2[i + v1.size()], v1[i], 1e-6 * v1[i]) << i;
  }
}

// updatePorosity on moved positions: V_i bit for bit as clothVolumes, S_i = c m^water_i / V_i (as
// computeSaturation), and the mass dry + held + buffer with the pinned corners kinematic
TEST(WettingPorosity, UpdateGivesVolumeSaturationAndWetMass) {
  Scene s = sceneFromJson(kHanging);
  const Model& m = s.model;
  Particles& p = s.state.particles;
  for (int i = 0; i < m.numCloth; ++i) {
    p.x[i] += Vec3(0.003f * std::sin(0.7f * i), 0.002f * std::cos(1.3f * i), 0.004f * std::sin(0.4f * i));
    s.state.clothWater[i] = 1e-4 * (i % 7);
    s.state.clothBuffer[i] = 2e-5 * (i % 3);
  }
  NeighborGrid grid;
  NeighborLists nb;
  lists(p, p.x, grid, nb);
  WettingScratch scratch;
  updatePorosity(m, s.state, nb, scratch);
  std::vector<float> v;
  clothVolumes(m, p.x, p.radius, p.phase, nb, v);
  ASSERT_EQ(scratch.volume.size(), size_t(m.numCloth));
  std::vector<float> sat;
  computeSaturation(m, s.state, scratch, sat);
  int pinned = 0;
  for (int i = 0; i < m.numCloth; ++i) {
    ASSERT_EQ(scratch.volume[i], v[i]) << i;
    EXPECT_EQ(s.state.clothSaturation[i], sat[i]) << i;
    EXPECT_NEAR(s.state.clothSaturation[i], 1e-3 * s.state.clothWater[i] / v[i], 1e-6 * (1.0 + s.state.clothSaturation[i]));
    EXPECT_FLOAT_EQ(p.mass[i], m.clothDryMass[i] + float(s.state.clothWater[i] + s.state.clothBuffer[i])) << i;
    if (m.clothPinned[i]) {
      EXPECT_EQ(p.invMass[i], 0.0f) << i;
      ++pinned;
    } else {
      EXPECT_EQ(p.invMass[i], 1.0f / p.mass[i]) << i;
    }
  }
  EXPECT_EQ(pinned, 2);
  EXPECT_TRUE(scratch.pairsValid);
  // wetting off: nothing is touched
  Model off = m;
  off.wetting.enabled = false;
  const std::vector<float> before = s.state.clothSaturation;
  s.state.clothWater.assign(s.state.clothWater.size(), 0.0);
  WettingScratch fresh;
  updatePorosity(off, s.state, nb, fresh);
  EXPECT_EQ(s.state.clothSaturation, before);
  EXPECT_TRUE(fresh.volume.empty());
}

// the per-pair values the wetting stages read are, bit for bit, the scalar kernels at (x_i - x_j,
// pairRadius(h_i, h_j)): poly6, the viscosity Laplacian, the spiky gradient's factor and cos theta_ij,
// here on a rippled sheet with mixed radii; ensurePairGeometry recomputes them only for other lists
TEST(WettingPorosity, PairGeometryIsTheScalarKernelsBitForBit) {
  Scene s = sceneFromJson(kHanging);
  const Model& m = s.model;
  Particles& p = s.state.particles;
  for (int i = 0; i < m.numCloth; ++i) {
    p.x[i] += Vec3(0.0f, 0.0f, 0.01f * std::sin(0.9f * i));
    if (i % 5 == 0) p.radius[i] = 0.03f;
  }
  NeighborGrid grid;
  NeighborLists nb;
  lists(p, p.x, grid, nb);
  WettingScratch w;
  pairGeometry(m, p, nb, w);
  const Vec3 g = gravityDirection(m);
  const uint32_t nc = uint32_t(m.numCloth);
  size_t pairs = 0, inside = 0;
  for (uint32_t i = 0; i < nc; ++i)
    for (uint32_t e = nb.start[i]; e < nb.clothEnd(i, nc); ++e) {
      const uint32_t j = nb.index[e];
      const Vec3 d = p.x[i] - p.x[j];
      const float h = pairRadius(p.radius[i], p.radius[j]);
      ASSERT_EQ(w.pairPoly6[e], poly6(d.squaredNorm(), h)) << i << " " << j;
      ASSERT_EQ(w.pairLap[e], viscosityLaplacian(d.norm(), h)) << i << " " << j;
      ASSERT_EQ(w.pairCos[e], cosGravity(p.x[i], p.x[j], g)) << i << " " << j;
      ASSERT_EQ(w.pairSpiky[e] * d, spikyGrad(d, h)) << i << " " << j;
      ++pairs;
      inside += w.pairPoly6[e] > 0.0f;
    }
  EXPECT_GT(pairs, size_t(6 * m.numCloth));
  EXPECT_GT(inside, pairs / 2);
  // the same lists: kept (a marker survives); other lists: computed again
  w.pairPoly6[nb.start[5]] = -1.0f;
  ensurePairGeometry(m, p, nb, w);
  EXPECT_EQ(w.pairPoly6[nb.start[5]], -1.0f);
  NeighborLists other;
  lists(p, p.x, grid, other);
  ensurePairGeometry(m, p, other, w);
  EXPECT_EQ(w.pairPoly6[other.start[5]], poly6((p.x[5] - p.x[other.index[other.start[5]]]).squaredNorm(),
                                                pairRadius(p.radius[5], p.radius[other.index[other.start[5]]])));
}

// the wetting state at load: held water S V / c per particle, empty buffers and drips, the ledger's held
// total equal to what was put in, and S_i = the initial saturation everywhere
TEST(WettingPorosity, InitialStateClearsBuffersAndDrips) {
  Scene s = sceneFromJson(kHanging, {"wetting.saturation.initial=0.2"});
  State& st = s.state;
  st.dripId = {5, 6};
  st.dripSource = {1, 2};
  st.clothBuffer.assign(st.clothBuffer.size(), 0.01);
  const double emittedBefore = st.ledger.emitted;
  const std::vector<float> v = restVolumes(s.model, st.particles.radius);
  initWettingState(s.model, v, st);
  EXPECT_TRUE(st.dripId.empty());
  EXPECT_TRUE(st.dripSource.empty());
  double held = 0.0;
  for (int i = 0; i < s.model.numCloth; ++i) {
    EXPECT_EQ(st.clothBuffer[i], 0.0);
    EXPECT_EQ(st.clothSaturation[i], 0.2f);
    EXPECT_NEAR(st.clothWater[i], double(0.2f) * v[i] / double(1e-3f), 1e-12 * st.clothWater[i]);  // S V / c
    held += st.clothWater[i];
  }
  EXPECT_NEAR(st.ledger.heldInCloth, held, 1e-12 * held);
  EXPECT_EQ(st.ledger.inBuffers, 0.0);
  EXPECT_NEAR(st.ledger.emitted - emittedBefore, held, 1e-12 * held);  // counted as emitted again
}
