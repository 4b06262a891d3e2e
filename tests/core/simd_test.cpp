// The lane type's contract (core/simd.hpp): every lane computes what the scalar overload computes, bit
// for bit, masked lanes read nothing and hold 0, and the lane sum is one fixed tree.
#include "core/simd.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

using namespace soak;

namespace {
bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }
}  // namespace

TEST(Simd, ScalarMaxAndMinTakeTheSecondOperandWhenEqualOrUnordered) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_TRUE(sameBits(simd::max(-0.0f, 0.0f), 0.0f));
  EXPECT_TRUE(sameBits(simd::max(0.0f, -0.0f), -0.0f));
  EXPECT_EQ(simd::max(nan, 1.0f), 1.0f);
  EXPECT_TRUE(std::isnan(simd::max(1.0f, nan)));
  EXPECT_EQ(simd::min(nan, 1.0f), 1.0f);
  EXPECT_EQ(simd::max(2.0f, 3.0f), 3.0f);
  EXPECT_EQ(simd::min(2.0f, 3.0f), 2.0f);
  EXPECT_EQ(simd::select(false, 5.0f), 0.0f);
  EXPECT_EQ(simd::divideOrZero(false, 1.0f, 0.0f), 0.0f);
  EXPECT_EQ(simd::divideOrZero(true, 1.0f, 4.0f), 0.25f);
}

#if SOAK_SIMD_WIDE
using simd::FloatW;
using simd::kLanes;
using simd::MaskW;
using simd::UintW;

namespace {
FloatW fromLanes(const float* v) { return simd::load(v, simd::firstLanes(kLanes)); }
}  // namespace

TEST(Simd, FirstLanesCountsFromLaneZero) {
  EXPECT_EQ(simd::bits(simd::firstLanes(0)), 0u);
  EXPECT_EQ(simd::bits(simd::firstLanes(3)), 0x7u);
  EXPECT_EQ(simd::bits(simd::firstLanes(16)), 0xFFFFu);
  EXPECT_EQ(simd::bits(simd::firstLanes(40)), 0xFFFFu);
  EXPECT_EQ(simd::count(simd::firstLanes(5)), 5);
}

TEST(Simd, EveryLaneIsTheScalarOperationBitForBit) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-3.0f, 3.0f);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int round = 0; round < 50; ++round) {
    float a[kLanes], b[kLanes];
    for (uint32_t l = 0; l < kLanes; ++l) a[l] = u(rng), b[l] = u(rng);
    // the edge cases of max and min: signed zeros, equal values, NaN on either side
    a[0] = -0.0f, b[0] = 0.0f, a[1] = 0.0f, b[1] = -0.0f, a[2] = b[2], a[3] = nan, b[4] = nan;
    const FloatW A = fromLanes(a), B = fromLanes(b);
    const MaskW lt = A < B, gt = A > B, ne = A != B;
    for (uint32_t l = 0; l < kLanes; ++l) {
      SCOPED_TRACE(l);
      EXPECT_TRUE(sameBits(simd::lane(A + B, int(l)), a[l] + b[l]));
      EXPECT_TRUE(sameBits(simd::lane(A - B, int(l)), a[l] - b[l]));
      EXPECT_TRUE(sameBits(simd::lane(A * B, int(l)), a[l] * b[l]));
      EXPECT_TRUE(sameBits(simd::lane(A / B, int(l)), a[l] / b[l]));
      EXPECT_TRUE(sameBits(simd::lane(simd::max(A, B), int(l)), simd::max(a[l], b[l])));
      EXPECT_TRUE(sameBits(simd::lane(simd::min(A, B), int(l)), simd::min(a[l], b[l])));
      EXPECT_TRUE(sameBits(simd::lane(simd::sqrt(A * A), int(l)), simd::sqrt(a[l] * a[l])));
      EXPECT_EQ((simd::bits(lt) >> l) & 1u, uint32_t(a[l] < b[l]));
      EXPECT_EQ((simd::bits(gt) >> l) & 1u, uint32_t(a[l] > b[l]));
      EXPECT_EQ((simd::bits(ne) >> l) & 1u, uint32_t(a[l] != b[l]));
      const bool m = (simd::bits(gt) >> l) & 1u;
      EXPECT_TRUE(sameBits(simd::lane(simd::divideOrZero(gt, A, B), int(l)), simd::divideOrZero(m, a[l], b[l])));
      EXPECT_TRUE(sameBits(simd::lane(simd::select(gt, A), int(l)), simd::select(m, a[l])));
    }
  }
}

TEST(Simd, MaskedLoadsAndGathersReadOnlyTheirLanes) {
  std::vector<float> a(40);
  for (size_t i = 0; i < a.size(); ++i) a[i] = 1.0f + float(i);
  // the last 5 floats of the array: the lanes past them must not be read (ASan would catch a read)
  const FloatW tail = simd::load(a.data() + 35, simd::firstLanes(5));
  for (int l = 0; l < 16; ++l) EXPECT_EQ(simd::lane(tail, l), l < 5 ? 36.0f + float(l) : 0.0f);
  alignas(64) uint32_t idx[16];
  for (uint32_t l = 0; l < 16; ++l) idx[l] = (7 * l) % 40;
  const MaskW m = simd::firstLanes(10);
  const UintW j = simd::load(idx, m);
  const FloatW g = simd::gather(a.data(), j, m, -1.0f);
  for (int l = 0; l < 16; ++l) EXPECT_EQ(simd::lane(g, l), l < 10 ? a[idx[l]] : -1.0f);
  std::vector<int32_t> phase(40);
  for (size_t i = 0; i < phase.size(); ++i) phase[i] = int32_t(i % 3);
  const UintW ph = simd::gather(phase.data(), j, m, simd::splat(9u));
  const uint32_t two = simd::bits(ph == simd::splat(2u)), fallback = simd::bits(ph == simd::splat(9u));
  for (uint32_t l = 0; l < 16; ++l) {
    EXPECT_EQ((two >> l) & 1u, uint32_t(l < 10 && phase[idx[l]] == 2));
    EXPECT_EQ((fallback >> l) & 1u, uint32_t(l >= 10));
  }
}

TEST(Simd, LoadXyzTransposesThreeFloatRecords) {
  std::vector<float> X(3 * 20);
  for (size_t i = 0; i < X.size(); ++i) X[i] = float(i) * 0.5f;
  uint32_t idx[16];
  for (uint32_t l = 0; l < 16; ++l) idx[l] = (l * 5 + 3) % 20;
  idx[15] = 19;  // the last record: its fourth float is past the array and must not be read
  FloatW x, y, z;
  simd::loadXyz(X.data(), idx, x, y, z);
  for (int l = 0; l < 16; ++l) {
    EXPECT_EQ(simd::lane(x, l), X[3 * idx[l]]);
    EXPECT_EQ(simd::lane(y, l), X[3 * idx[l] + 1]);
    EXPECT_EQ(simd::lane(z, l), X[3 * idx[l] + 2]);
  }
}

TEST(Simd, StoreCompressedPacksTheMaskedLanesInOrder) {
  alignas(64) uint32_t idx[16], out[16];
  for (uint32_t l = 0; l < 16; ++l) idx[l] = 100 + l;
  const UintW j = simd::load(idx, simd::firstLanes(16));
  const MaskW odd = MaskW{__mmask16(0xAAAA)};
  simd::storeCompressed(out, odd, j);
  for (int l = 0; l < 8; ++l) EXPECT_EQ(out[l], 101u + 2u * uint32_t(l));
  for (int l = 8; l < 16; ++l) EXPECT_EQ(out[l], 0u);
  EXPECT_EQ(simd::bits(j < simd::splat(104u)), 0xFu);  // unsigned compare
  EXPECT_EQ(simd::bits(simd::splat(0x80000000u) < simd::splat(1u)), 0u);
}

// the lane sum is the tree (l, l ^ 8), then (l, l ^ 4), (l, l ^ 2), (l, l ^ 1): not the sequential
// sum, whose rounding differs for these values
TEST(Simd, SumIsOneFixedTree) {
  float a[16];
  for (int l = 0; l < 16; ++l) a[l] = (l % 3 == 0 ? 1e8f : 1.0f) * (l % 2 ? -1.0f : 1.0f) + 0.37f * float(l);
  float t[16];
  std::memcpy(t, a, sizeof a);
  for (int step : {8, 4, 2, 1}) {
    float next[16];
    for (int l = 0; l < 16; ++l) next[l] = t[l] + t[l ^ step];
    std::memcpy(t, next, sizeof t);
  }
  float sequential = 0.0f;
  for (float v : a) sequential += v;
  const float s = simd::sum(fromLanes(a));
  EXPECT_TRUE(sameBits(s, t[0]));
  EXPECT_NE(s, sequential);  // the values are chosen so the order shows
}
#endif
