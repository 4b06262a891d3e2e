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

// the neighbours of i in the lists, sorted (the lists' own order is the grid's)
std::vector<uint32_t> sortedNeighbours(const NeighborLists& lists, size_t i) {
  std::vector<uint32_t> got(lists.index.begin() + lists.start[i], lists.index.begin() + lists.start[i + 1]);
  std::sort(got.begin(), got.end());
  return got;
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

// (mixed radii, seed, a far cluster): with the far cluster the bounding box has too many cells and the
// lists come from the hashed grid's buckets; without, from the dense grid's rows
class GridVsBruteForce : public ::testing::TestWithParam<std::tuple<bool, unsigned, bool>> {};

TEST_P(GridVsBruteForce, SameNeighbours) {
  const auto [mixed, seed, far] = GetParam();
  std::vector<Vec3> x;
  std::vector<float> r;
  randomSet(3000, 0.25f, mixed, seed, x, r);
  // negative coordinates and a far cluster exercise the hash
  if (far)
    for (int k = 0; k < 200; ++k) x[k] += Vec3(37.0f, -12.0f, 5.0f);
  NeighborGrid grid;
  NeighborLists lists;
  buildGrid(x, *std::max_element(r.begin(), r.end()), grid);
  buildNeighborLists(x, r, grid, lists);
  EXPECT_EQ(lists.dense, !far);  // the path the case means to test
  const auto ref = bruteForce(x, r);
  size_t total = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    ASSERT_EQ(sortedNeighbours(lists, i), ref[i]) << "particle " << i;
    total += ref[i].size();
  }
  EXPECT_GT(total, 1000u);  // the sets are dense enough for the comparison to mean something
}

INSTANTIATE_TEST_SUITE_P(Grid, GridVsBruteForce,
                         ::testing::Combine(::testing::Bool(), ::testing::Values(1u, 2u, 3u), ::testing::Bool()));

// particles wider than the grid's cells (drips that grew while they hung: neighborCellSize keeps the
// cells at the common radius) are found by their own wider search and handed to the others' lists:
// the same neighbours as brute force, on the dense and the hashed grid, cloth part first, for any
// thread count, even with big particles touching each other and sitting in the cloth part
class GridWithBigParticles : public ::testing::TestWithParam<bool> {};

TEST_P(GridWithBigParticles, SameNeighboursAsBruteForce) {
  const bool far = GetParam();
  std::vector<Vec3> x;
  std::vector<float> r;
  randomSet(4000, 0.25f, true, 23, x, r);
  if (far)
    for (int k = 0; k < 200; ++k) x[k] += Vec3(37.0f, -12.0f, 5.0f);
  const float cell = 0.04f;
  std::vector<uint32_t> big;
  for (uint32_t k : {5u, 17u, 1200u, 1201u, 2500u, 2501u, 3999u}) {  // 5 and 17: in the cloth part
    r[k] = k % 2 ? 0.13f : 0.07f;
    big.push_back(k);
  }
  x[2501] = x[2500] + Vec3(0.095f, 0.0f, 0.0f);  // two big ones apart by more than a cell, less than (h + h) / 2
  if (far) r[3999] = 1.0f;  // reach beyond every bucket of the hashed table: the whole table is searched
  const uint32_t firstWater = 1000;
  const auto ref = bruteForce(x, r);
  NeighborLists l[2];
  for (int t = 0; t < 2; ++t) {
    NeighborGrid grid;
    setThreadCount(t + 1);
    buildGrid(x, cell, grid);
    buildNeighborLists(x, r, grid, l[t], firstWater);
    setThreadCount(2);
    EXPECT_EQ(l[t].dense, !far);
    EXPECT_EQ(l[t].big, big);
  }
  EXPECT_EQ(l[0].start, l[1].start);
  EXPECT_EQ(l[0].mid, l[1].mid);
  EXPECT_EQ(l[0].index, l[1].index);
  size_t withBig = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    ASSERT_EQ(sortedNeighbours(l[0], i), ref[i]) << "particle " << i;
    for (uint32_t k = l[0].start[i]; k < l[0].mid[i]; ++k) ASSERT_LT(l[0].index[k], firstWater);
    for (uint32_t k = l[0].mid[i]; k < l[0].start[i + 1]; ++k) ASSERT_GE(l[0].index[k], firstWater);
    for (uint32_t j : ref[i]) withBig += r[j] > cell;
  }
  EXPECT_GT(withBig, 100u);  // the big ones have many neighbours the common cells would miss
}

INSTANTIATE_TEST_SUITE_P(Grid, GridWithBigParticles, ::testing::Bool());

// grid and lists of x built on `threads` threads, cloth before water at `split`
NeighborLists listsOn(int threads, const std::vector<Vec3>& x, const std::vector<float>& r, uint32_t split) {
  NeighborGrid g;
  NeighborLists l;
  setThreadCount(threads);
  buildGrid(x, 0.04f, g);
  buildNeighborLists(x, r, g, l, split);
  setThreadCount(2);
  return l;
}

TEST(Grid, ListsDoNotDependOnThreadCount) {
  std::vector<Vec3> x;
  std::vector<float> r;
  randomSet(5000, 0.3f, true, 7, x, r);
  const NeighborLists l1 = listsOn(1, x, r, 0), l2 = listsOn(2, x, r, 0);
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

TEST(Grid, ClothNeighboursComeFirst) {
  std::vector<Vec3> x;
  std::vector<float> r;
  randomSet(3000, 0.25f, true, 11, x, r);
  const uint32_t firstWater = 1200;  // particles [0, 1200) play the cloth
  NeighborGrid grid;
  NeighborLists lists;
  buildGrid(x, 0.04f, grid);
  buildNeighborLists(x, r, grid, lists, firstWater);
  const auto ref = bruteForce(x, r);
  size_t cloth = 0, water = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    ASSERT_LE(lists.start[i], lists.mid[i]);
    ASSERT_LE(lists.mid[i], lists.start[i + 1]);
    EXPECT_EQ(lists.clothEnd(i, firstWater), lists.mid[i]);
    EXPECT_EQ(lists.waterBegin(i, firstWater), lists.mid[i]);
    for (uint32_t k = lists.start[i]; k < lists.mid[i]; ++k) EXPECT_LT(lists.index[k], firstWater);
    for (uint32_t k = lists.mid[i]; k < lists.start[i + 1]; ++k) EXPECT_GE(lists.index[k], firstWater);
    cloth += lists.mid[i] - lists.start[i];
    water += lists.start[i + 1] - lists.mid[i];
    ASSERT_EQ(sortedNeighbours(lists, i), ref[i]) << "particle " << i;
  }
  EXPECT_GT(cloth, 100u);
  EXPECT_GT(water, 100u);
  // lists built for another split give the whole list to both kinds (callers stay correct)
  EXPECT_EQ(lists.clothEnd(5, 7), lists.start[6]);
  EXPECT_EQ(lists.waterBegin(5, 7), lists.start[5]);
}

TEST(Grid, SplitListsDoNotDependOnThreadCount) {
  std::vector<Vec3> x;
  std::vector<float> r;
  randomSet(20000, 0.4f, true, 13, x, r);  // more than one block of the fill pass
  const NeighborLists l1 = listsOn(1, x, r, 2500), l2 = listsOn(2, x, r, 2500);
  EXPECT_EQ(l1.start, l2.start);
  EXPECT_EQ(l1.mid, l2.mid);
  EXPECT_EQ(l1.index, l2.index);
}

TEST(Grid, DenseClustersOverflowTheFillBuffer) {
  // 600 particles in one cell: each has more neighbours than the gather buffers start with
  std::vector<Vec3> x;
  std::vector<float> r;
  randomSet(600, 0.01f, false, 17, x, r);
  NeighborGrid grid;
  NeighborLists lists;
  buildGrid(x, 0.04f, grid);
  buildNeighborLists(x, r, grid, lists, 250);
  const auto ref = bruteForce(x, r);
  for (size_t i = 0; i < x.size(); ++i) {
    ASSERT_EQ(sortedNeighbours(lists, i), ref[i]) << "particle " << i;
  }
}

TEST(Grid, RebuildWithMoreNeighboursThanLastTime) {
  // the second build needs more room than the first left: the index grows and stays right
  std::vector<Vec3> x;
  std::vector<float> r;
  randomSet(12000, 0.6f, false, 19, x, r);
  NeighborGrid grid;
  NeighborLists lists;
  buildGrid(x, 0.04f, grid);
  buildNeighborLists(x, r, grid, lists, 4000);
  for (Vec3& p : x) p *= 0.4f;  // the same particles, squeezed: about 15 times the neighbours
  buildGrid(x, 0.04f, grid);
  buildNeighborLists(x, r, grid, lists, 4000);
  const auto ref = bruteForce(x, r);
  for (size_t i = 0; i < x.size(); i += 7) {
    ASSERT_EQ(sortedNeighbours(lists, i), ref[i]) << "particle " << i;
  }
  EXPECT_EQ(lists.start.back(), lists.index.size());
}
