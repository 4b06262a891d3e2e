// the open container's walls (world/container.cpp): a floor slab and four side walls of the given
// thickness around the free cavity |x| <= halfExtents, open at the top, overlapping at the edges
#include "world/container.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace soak {
namespace {

struct Walls {
  Vec3 centers[kContainerWalls], halves[kContainerWalls];
  explicit Walls(const Collider& c) { containerWalls(c, centers, halves); }
  // how many wall boxes hold p (closed boxes, a 1e-6 m tolerance)
  int holding(const Vec3& p) const {
    int n = 0;
    for (int k = 0; k < kContainerWalls; ++k)
      n += ((p - centers[k]).cwiseAbs().array() <= halves[k].array() + 1e-6f).all() ? 1 : 0;
    return n;
  }
};

Collider container(const Vec3& half, float wall) {
  Collider c;
  c.shape = ColliderShape::Container;
  c.halfExtents = half;
  c.wallThickness = wall;
  return c;
}

// the faces of each box, from the cavity's half extents (a, b, c) and the wall thickness w: the floor
// spans y in [-b - w, -b]; the walls rise from the floor's underside to the rim y = b, their inner
// faces on the cavity (x = +-a, z = +-c), and reach w past the cavity on the other axes
TEST(WorldContainer, WallFacesFollowFromTheCavityAndTheThickness) {
  const float a = 0.3f, b = 0.2f, c = 0.25f, w = 0.05f;
  const Walls walls(container(Vec3(a, b, c), w));
  const auto lo = [&](int k) { return Vec3(walls.centers[k] - walls.halves[k]); };
  const auto hi = [&](int k) { return Vec3(walls.centers[k] + walls.halves[k]); };
  const auto expectBox = [&](int k, const Vec3& l, const Vec3& h) {
    EXPECT_LT((lo(k) - l).norm(), 1e-6f) << "wall " << k << " lo " << lo(k).transpose();
    EXPECT_LT((hi(k) - h).norm(), 1e-6f) << "wall " << k << " hi " << hi(k).transpose();
  };
  expectBox(0, Vec3(-a - w, -b - w, -c - w), Vec3(a + w, -b, c + w));  // floor
  expectBox(1, Vec3(a, -b - w, -c - w), Vec3(a + w, b, c + w));        // +x
  expectBox(2, Vec3(-a - w, -b - w, -c - w), Vec3(-a, b, c + w));      // -x
  expectBox(3, Vec3(-a - w, -b - w, c), Vec3(a + w, b, c + w));        // +z
  expectBox(4, Vec3(-a - w, -b - w, -c - w), Vec3(a + w, b, -c));      // -z
}

// on a lattice through and around the container: the open cavity (up to and above the rim) is in no
// wall; every point of the shell (within w outside the cavity, below the rim) is in at least one, and
// the edges where two walls meet are in two (the overlap that makes a corner's inner faces nearest)
TEST(WorldContainer, WallsCoverTheShellAndLeaveTheCavityAndTheTopOpen) {
  const Vec3 half(0.2f, 0.15f, 0.1f);
  const float w = 0.04f;
  const Walls walls(container(half, w));
  int shell = 0, edges = 0;
  const int n = 41;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        // a lattice over [-0.3, 0.3]^3 whose points avoid the faces themselves
        const Vec3 p(-0.3f + 0.6f * (i + 0.37f) / n, -0.3f + 0.6f * (j + 0.41f) / n, -0.3f + 0.6f * (k + 0.43f) / n);
        const Vec3 out = (p.cwiseAbs() - half).cwiseMax(0.0f);  // how far outside the cavity's box, per axis
        const bool inShell = p.y() < half.y() && out.maxCoeff() > 0.0f && out.maxCoeff() < w &&
                             p.y() > -half.y() - w;
        const int held = walls.holding(p);
        if (inShell) {
          EXPECT_GE(held, 1) << p.transpose();
          ++shell;
          edges += held >= 2;
        } else {
          EXPECT_EQ(held, 0) << p.transpose();
        }
      }
  EXPECT_GT(shell, 1000);
  EXPECT_GT(edges, 50);
}

}  // namespace
}  // namespace soak
