#include "grid/grid.hpp"

#include "core/parallel.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

using namespace soak;

namespace {
void randomSet(size_t n, float extent, bool mixed, unsigned seed, std::vector<Vec3>& x, std::vector<float>& r) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-extent, extent), rad(0.01f, 0.04f);
  x.resize(n);
  r.resize(n);
  for (size_t i = 0; i < n; ++i) {
    x[i] = Vec3(u(rng), u(rng), u(rng));
    r[i] = mixed ? rad(rng) : 0.04f;
  }
}

std::vector<std::vector<uint32_t>> bruteForce(const std::vector<Vec3>& x, const std::vector<float>& r) {
  std::vector<std::vector<uint32_t>> out(x.size());
  for (size_t i = 0; i < x.size(); ++i)
    for (size_t j = 0; j < x.size(); ++j) {
      const float h = 0.5f * (r[i] + r[j]);
      if (i != j && (x[i] - x[j]).squaredNorm() < h * h) out[i].push_back(static_cast<uint32_t>(j));
    }
  return out;
}
}  // namespace

class GridVsBruteForce : public ::testing::TestWithParam<std::tuple<bool, unsigned>> {};

TEST_P(GridVsBruteForce, SameNeighbours) {
  const auto [mixed, seed] = GetParam();
  std::vector<Vec3> x;
  std::vector<float> r;
  randomSet(3000, 0.25f, mixed, seed, x, r);
  // negative coordinates and a far cluster exercise the hash
  for (int k = 0; k < 200; ++k) x[k] += Vec3(37.0f, -12.0f, 5.0f);
  NeighborGrid grid;
  NeighborLists lists;
  buildGrid(x, *std::max_element(r.begin(), r.end()), grid);
  buildNeighborLists(x, r, grid, lists);
  const auto ref = bruteForce(x, r);
  size_t total = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    std::vector<uint32_t> got(lists.index.begin() + lists.start[i], lists.index.begin() + lists.start[i + 1]);
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, ref[i]) << "particle " << i;
    total += got.size();
  }
  EXPECT_GT(total, 1000u);  // the sets are dense enough for the comparison to mean something
}

INSTANTIATE_TEST_SUITE_P(Grid, GridVsBruteForce,
                         ::testing::Combine(::testing::Bool(), ::testing::Values(1u, 2u, 3u)));

TEST(Grid, ListsDoNotDependOnThreadCount) {
  std::vector<Vec3> x;
  std::vector<float> r;
  randomSet(5000, 0.3f, true, 7, x, r);
  NeighborGrid g1, g2;
  NeighborLists l1, l2;
  setThreadCount(1);
  buildGrid(x, 0.04f, g1);
  buildNeighborLists(x, r, g1, l1);
  setThreadCount(2);
  buildGrid(x, 0.04f, g2);
  buildNeighborLists(x, r, g2, l2);
  EXPECT_EQ(l1.start, l2.start);
  EXPECT_EQ(l1.index, l2.index);
}

TEST(Grid, RebuildWithFewerParticles) {
  std::vector<Vec3> x;
  std::vector<float> r;
  randomSet(2000, 0.2f, false, 9, x, r);
  NeighborGrid grid;
  NeighborLists lists;
  buildGrid(x, 0.04f, grid);
  buildNeighborLists(x, r, grid, lists);
  x.resize(500);
  r.resize(500);
  buildGrid(x, 0.04f, grid);
  buildNeighborLists(x, r, grid, lists);
  const auto ref = bruteForce(x, r);
  for (size_t i = 0; i < x.size(); ++i) EXPECT_EQ(lists.count(i), ref[i].size());
}
