// cloth that starts inside a collider is refused by the loader (scene/clearance.cpp), naming the
// piece, the collider and how many particles
#include "scene/clearance.hpp"

#include <gtest/gtest.h>

#include "scene/scene_support.hpp"

#include <string>

namespace soak {
namespace {

using namespace soak::testing;

// kSmall's sheet: 0.3 x 0.2 m at y = 1, 4 x 3 vertices
std::string withCollider(const std::string& collider) {
  return R"({"cloth": [{"name": "sheet", "mesh": {"type": "rectangle", "center": [0, 1, 0], "size": [0.3, 0.2],
                                                  "resolution": [4, 3]}}],
             "colliders": [)" + collider + R"(]})";
}

TEST(SceneClearance, ClothInsideAColliderIsNamedWithItsCount) {
  // a ball of radius 0.1 at the sheet's centre holds the two middle vertices of the middle row
  const std::string msg = loadError(withCollider(R"({"name": "ball", "type": "sphere", "radius": 0.1,
                                                     "position": [0, 1, 0]})"));
  EXPECT_HAS(msg, "test.json: at cloth[0].mesh: expected cloth 'sheet' to start outside collider 'ball', got 2 of "
                  "its 12 particles inside it at t = 0");
  EXPECT_HAS(msg, "the cloth would fall through it");
  // below a floor plane, every particle
  EXPECT_HAS(loadError(withCollider(R"({"name": "floor", "type": "plane", "position": [0, 1.5, 0]})")),
             "collider 'floor', got 12 of its 12 particles inside it");
  // a keyframed collider counts where it is at t = 0
  EXPECT_HAS(loadError(withCollider(R"({"name": "lift", "type": "box", "halfExtents": [1, 0.1, 1],
                                        "keyframes": [{"time": 0, "position": [0, 1, 0]},
                                                      {"time": 1, "position": [0, 3, 0]}]})")),
             "collider 'lift', got 12 of its 12 particles inside it");
}

TEST(SceneClearance, ClothOnASurfaceOrInsideAContainerIsFine) {
  // lying exactly on a box's top face
  EXPECT_EQ(loadError(withCollider(R"({"type": "box", "halfExtents": [1, 0.5, 1], "position": [0, 0.5, 0]})")), "");
  // inside an open container's hollow, away from its walls
  EXPECT_EQ(loadError(withCollider(R"({"type": "container", "halfExtents": [1, 1, 1], "wallThickness": 0.05,
                                       "position": [0, 1, 0]})")),
            "");
  EXPECT_EQ(loadError(withCollider(R"({"type": "plane", "position": [0, 1, 0]})")), "");
}

}  // namespace
}  // namespace soak
