// the parallel helpers (src/core/parallel.hpp): ordered chunks give the serial result for any thread
// count; ranges visit each index once; per-thread buffers are per thread
#include "core/parallel.hpp"

#include <gtest/gtest.h>

#include <numeric>
#include <set>

namespace soak {
namespace {

// item i of chunk c yields i % 5 copies of i: lists of uneven length, as neighbour lists are
std::vector<uint32_t> chunked(int threads, int64_t items, int64_t chunk) {
  const int before = threadCount();
  setThreadCount(threads);
  const int64_t chunks = (items + chunk - 1) / chunk;
  std::vector<std::vector<uint32_t>> buffers;
  std::vector<size_t> offset;
  std::vector<uint32_t> out;
  std::set<int> threadsSeen;
  orderedChunks(
      chunks, buffers, offset, 0, true, [] { return 0; },
      [&](int&, int64_t c, std::vector<uint32_t>& buf) {
        for (int64_t i = c * chunk; i < std::min(items, (c + 1) * chunk); ++i)
          buf.insert(buf.end(), static_cast<size_t>(i % 5), static_cast<uint32_t>(i));
      },
      [&](const std::vector<size_t>& off) { out.resize(off.back()); },
      [&](int64_t c) {
        std::copy(buffers[size_t(c)].begin(), buffers[size_t(c)].end(), out.begin() + std::ptrdiff_t(offset[size_t(c)]));
      });
  setThreadCount(before);
  return out;
}

TEST(Parallel, OrderedChunksGiveTheSerialResultForAnyThreadCount) {
  std::vector<uint32_t> serial;
  for (uint32_t i = 0; i < 10000; ++i) serial.insert(serial.end(), i % 5, i);
  EXPECT_EQ(chunked(1, 10000, 64), serial);
  EXPECT_EQ(chunked(2, 10000, 64), serial);
  EXPECT_EQ(chunked(3, 10000, 7), serial);
}

TEST(Parallel, RangesVisitEachIndexOnce) {
  std::vector<int> visits(20000, 0);
  parallelForRanges({{10, 5000}, {5000, 5001}, {7000, 20000}, {3, 3}}, [&](int64_t i) { ++visits[size_t(i)]; });
  for (size_t i = 0; i < visits.size(); ++i)
    EXPECT_EQ(visits[i], (i >= 10 && i < 5001) || i >= 7000 ? 1 : 0) << i;
}

TEST(Parallel, ThreadBuffersArePerThreadAndGrow) {
  ThreadBuffers<int> buffers;
  buffers.prepare();
  std::vector<int*> mine(size_t(threadCount()), nullptr);
#pragma omp parallel
  {
    int* b = buffers.get(100 + size_t(omp_get_thread_num()));
    for (int k = 0; k < 100; ++k) b[k] = omp_get_thread_num();
    mine[size_t(omp_get_thread_num())] = b;
  }
  std::set<int*> distinct(mine.begin(), mine.end());
  EXPECT_EQ(distinct.size(), mine.size());
  for (size_t t = 0; t < mine.size(); ++t)
    if (mine[t]) EXPECT_EQ(mine[t][99], int(t));
}

}  // namespace
}  // namespace soak
