// long range attachments (src/pbd/tethers.cpp): their lengths against the rest shape, the slack key,
// and a sheet pinned at its corners that hangs without creasing
#include "support/run_scene.hpp"

#include "pbd/tethers.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

using namespace soak;
using namespace soak::testing;

namespace {

std::string cornerSheet(int resolution, float slack) {
  return R"({
    "solver": {"dt": 0.015, "substeps": 1, "domain": {"min": [-1.5, -1.5, -1.5], "max": [1.5, 2.5, 1.5]}},
    "cloth": [{"mesh": {"type": "rectangle", "center": [0, 1, 0], "size": [1.2, 1.2], "resolution": [)" +
         std::to_string(resolution) + ", " + std::to_string(resolution) + R"(],
                        "axisU": [1, 0, 0], "axisV": [0, 0, 1]},
               "material": {"tetherSlack": )" +
         std::to_string(slack) + R"(}, "pin": {"corners": [0, 1, 2, 3]}}]
  })";
}

// the largest and smallest ratio of a tether's length to the straight line to its anchor at rest
std::pair<float, float> lengthOverDistance(const Model& model) {
  float lo = 1e9f, hi = 0.0f;
  const Tethers& t = model.tethers;
  for (int i = 0; i < model.numCloth; ++i)
    for (int k = t.start[i]; k < t.start[i + 1]; ++k) {
      const float d = (model.clothRestPosition[i] - model.clothRestPosition[t.anchor[k]]).norm();
      lo = std::min(lo, t.length[k] / d);
      hi = std::max(hi, t.length[k] / d);
    }
  return {lo, hi};
}

}  // namespace

TEST(Tethers, LengthsFollowTheFlatRestShapeInEveryDirection) {
  // on a flat sheet the geodesic is the straight line. Paths along the edges alone were 41% longer
  // across the grid's missing diagonal than along it, so a corner-pinned sheet was held tight towards
  // two corners and slack towards the other two, and creased along its middles
  const Scene scene = sceneFromJson(cornerSheet(61, 0.0f));
  ASSERT_FALSE(scene.model.tethers.anchor.empty());
  const auto [lo, hi] = lengthOverDistance(scene.model);
  EXPECT_GE(lo, 1.0f - 1e-5f);  // never shorter than the straight line: a flat sheet is not pulled
  EXPECT_LT(hi, 1.06f);
}

TEST(Tethers, SlackLengthensEveryTetherByItsFraction) {
  const Scene tight = sceneFromJson(cornerSheet(21, 0.0f)), slack = sceneFromJson(cornerSheet(21, 0.1f));
  ASSERT_EQ(tight.model.tethers.length.size(), slack.model.tethers.length.size());
  for (size_t k = 0; k < tight.model.tethers.length.size(); ++k)
    EXPECT_NEAR(slack.model.tethers.length[k], 1.1f * tight.model.tethers.length[k], 1e-5f * tight.model.tethers.length[k]);
}

TEST(Tethers, SheetPinnedAtItsCornersHangsWithoutTurnedOverTriangles) {
  // the Fig. 3(a) sheet without its water: tethers projected after the cloth iterations left kinks the
  // next step carried on, and tens of triangles turned over along the sheet's middles (the creases the
  // water of Fig. 3(a) then passed through)
  Scene scene = sceneFromJson(cornerSheet(120, 0.0f));
  const Particles& p = scene.state.particles;
  const auto& tris = scene.model.triangles;
  const auto normal = [&](const std::array<int, 3>& f) { return Vec3((p.x[f[1]] - p.x[f[0]]).cross(p.x[f[2]] - p.x[f[0]])); };
  std::vector<Vec3> rest;
  for (const auto& f : tris) rest.push_back(normal(f));
  WorkspacePtr ws = makeWorkspace();
  StepStats stats;
  int worst = 0;
  for (int s = 0; s < 30; ++s) {
    step(scene.model, scene.state, *ws, scene.model.solver.dt, stats);
    int turned = 0;
    for (size_t t = 0; t < tris.size(); ++t) turned += normal(tris[t]).dot(rest[t]) < 0.0f;
    worst = std::max(worst, turned);
  }
  EXPECT_EQ(worst, 0);
  float lowest = 1e9f;
  for (int i = 0; i < scene.model.numCloth; ++i) lowest = std::min(lowest, p.x[i].y());
  EXPECT_LT(lowest, 0.99f);  // it did hang
}

// the small steps' form (solveTethersFrom, on x* = base + displacement) brings each particle onto its
// tether's sphere as solveTethers does on x*, and moves only the displacement
TEST(Tethers, OnADisplacementTheyPullAsOnThePositions) {
  const Scene scene = sceneFromJson(cornerSheet(21, 0.0f));
  const Model& model = scene.model;
  const int n = model.numCloth;
  std::vector<Vec3> base(static_cast<size_t>(n)), moved(static_cast<size_t>(n));
  Particles p = scene.state.particles;
  for (int i = 0; i < n; ++i) {
    base[i] = model.clothRestPosition[i];
    // every free particle pushed 5 cm away from the sheet's centre, outward and down: past its tethers
    const bool pinned = model.clothPinned[i] != 0;
    moved[i] = pinned ? Vec3::Zero() : Vec3(0.05f * base[i].x(), -0.05f, 0.05f * base[i].z());
    p.xPred[i] = base[i] + moved[i];
  }
  solveTethers(model, p);
  std::vector<Vec3> d = moved;
  solveTethersFrom(model, base.data(), d.data());
  int pulled = 0;
  for (int i = 0; i < n; ++i) {
    EXPECT_LT((base[i] + d[i] - p.xPred[i]).norm(), 1e-6f) << i;
    pulled += (d[i] - moved[i]).norm() > 1e-4f ? 1 : 0;
  }
  EXPECT_GT(pulled, n / 2);  // the push was past most tethers
}
