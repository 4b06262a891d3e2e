// the PBD cloth constraints' colouring and schedule (src/pbd/cloth_constraints.cpp)
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "support/mesh_checks.hpp"
#include "pbd/cloth.hpp"
#include "scene/cloth_piece.hpp"

namespace soak {
namespace {

using testing::edgeUse;
using testing::errorOf;
using testing::TempFile;

// every constraint in exactly one block; no particle twice in a block; the groups of one parallel
// phase (the slabs, the even interfaces, the odd interfaces) share no particle
template <size_t N>
void expectValidSchedule(const std::vector<std::array<int, N>>& ids, const ConstraintSchedule& s, int n) {
  const int slabs = s.numSlabs;
  ASSERT_GE(slabs, 1);
  ASSERT_EQ(s.groupBlock.size(), static_cast<size_t>(2 * slabs) + 1);
  ASSERT_FALSE(s.blockStart.empty());
  EXPECT_EQ(s.blockStart.front(), 0);
  EXPECT_EQ(s.blockStart.back(), static_cast<int>(ids.size()));
  EXPECT_EQ(s.groupBlock.front(), 0);
  EXPECT_EQ(s.groupBlock.back(), static_cast<int>(s.blockStart.size()) - 1);
  for (size_t b = 0; b + 1 < s.blockStart.size(); ++b) {
    EXPECT_LT(s.blockStart[b], s.blockStart[b + 1]) << "empty block " << b;
    std::vector<int> seen(n, 0);
    for (int k = s.blockStart[b]; k < s.blockStart[b + 1]; ++k)
      for (int v : ids[k]) {
        ASSERT_GE(v, 0);
        ASSERT_LT(v, n);
        EXPECT_EQ(seen[v]++, 0) << "particle " << v << " twice in block " << b;
      }
  }
  const auto phaseIsDisjoint = [&](const std::vector<int>& groups) {
    std::vector<int> owner(n, -1);
    for (int g : groups)
      for (int b = s.groupBlock[g]; b < s.groupBlock[g + 1]; ++b)
        for (int k = s.blockStart[b]; k < s.blockStart[b + 1]; ++k)
          for (int v : ids[k]) {
            EXPECT_TRUE(owner[v] == -1 || owner[v] == g) << "particle " << v << " in groups " << owner[v] << " and " << g;
            owner[v] = g;
          }
  };
  std::vector<int> inside, even, odd;
  for (int g = 0; g < slabs; ++g) inside.push_back(g);
  for (int k = 0; k + 1 < slabs; ++k) (k % 2 ? odd : even).push_back(slabs + k);
  phaseIsDisjoint(inside);
  phaseIsDisjoint(even);
  phaseIsDisjoint(odd);
}

TEST(MeshColoring, ValidCoveringAndDeterministic) {
  Model model;
  addClothPiece(model, "big", makeRectangle(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 1.0f, 1.0f, 17, 13),
                ClothMaterial{}, {}, "test");
  addClothPiece(model, "small", makeRectangle(Vec3(0, 0, 1), Vec3::UnitX(), Vec3::UnitY(), 0.3f, 0.3f, 4, 4),
                ClothMaterial{}, {}, "test");
  expectValidSchedule(model.stretch.ids, model.stretch.schedule, model.numCloth);
  expectValidSchedule(model.bend.ids, model.bend.schedule, model.numCloth);
  // vertices have 4 or 8 edges: at least 8 colours, and greedy needs at most 7 + 7 + 1
  EXPECT_LE(model.stretch.schedule.numColors, 15);
  EXPECT_GE(model.stretch.schedule.numColors, 8);
  EXPECT_LE(model.bend.schedule.numColors, 40);

  Model again;
  addClothPiece(again, "big", makeRectangle(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 1.0f, 1.0f, 17, 13),
                ClothMaterial{}, {}, "test");
  addClothPiece(again, "small", makeRectangle(Vec3(0, 0, 1), Vec3::UnitX(), Vec3::UnitY(), 0.3f, 0.3f, 4, 4),
                ClothMaterial{}, {}, "test");
  EXPECT_EQ(again.stretch.ids, model.stretch.ids);
  EXPECT_EQ(again.bend.ids, model.bend.ids);
  EXPECT_EQ(again.bend.schedule.blockStart, model.bend.schedule.blockStart);
}

TEST(MeshColoring, LargeSheetsAreCutIntoSlabsWhoseGroupsShareNoParticle) {
  // 100 x 100 particles: 6 slabs of the solver's parallel phases; a second piece beside it
  Model model;
  addClothPiece(model, "big", makeRectangle(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), 1.0f, 1.0f, 100, 100),
                ClothMaterial{}, {}, "test");
  addClothPiece(model, "small", makeRectangle(Vec3(0, 1, 0), Vec3::UnitX(), Vec3::UnitZ(), 0.3f, 0.3f, 10, 10),
                ClothMaterial{}, {}, "test");
  EXPECT_EQ(model.stretch.schedule.numSlabs, 6);
  expectValidSchedule(model.stretch.ids, model.stretch.schedule, model.numCloth);
  expectValidSchedule(model.bend.ids, model.bend.schedule, model.numCloth);
  // nearly every constraint lies inside one slab; the interfaces are thin
  const ConstraintSchedule& s = model.stretch.schedule;
  const int inside = s.blockStart[s.groupBlock[s.numSlabs]];
  EXPECT_GT(inside, static_cast<int>(0.9 * model.stretch.ids.size()));
}

}  // namespace
}  // namespace soak
