// parallel loops: static OpenMP schedule over contiguous ranges. Every loop gathers (writes only its
// own index), so results do not depend on the thread count.
#pragma once
#include <omp.h>

#include <cstdint>
#include <vector>

namespace soak {

// below this many items a loop runs on the calling thread: the fork costs more than it saves
constexpr int64_t kParallelGrain = 2048;

template <class F>
inline void parallelFor(int64_t n, F&& body) {
#pragma omp parallel for schedule(static) if (n >= kParallelGrain)
  for (int64_t i = 0; i < n; ++i) body(i);
}

// the same for loops whose items cost very different amounts (wet and dry cloth): chunks of `chunk`
// items go to whichever thread is free. Each item still writes only its own results, so the
// schedule changes no result.
template <class F>
inline void parallelForDynamic(int64_t n, int64_t chunk, F&& body) {
#pragma omp parallel for schedule(dynamic, chunk) if (n >= kParallelGrain)
  for (int64_t i = 0; i < n; ++i) body(i);
}

// a half-open range [begin, end) of particle indices
struct IndexRange {
  int64_t begin = 0, end = 0;
};

// parallelFor over each range in turn: body(i) for every i of every range
template <class F>
inline void parallelForRanges(const std::vector<IndexRange>& ranges, F&& body) {
  for (const IndexRange& r : ranges) parallelFor(r.end - r.begin, [&](int64_t k) { body(r.begin + k); });
}

// the chunk of dynamically scheduled loops over cloth particles
constexpr int64_t kClothChunk = 256;

// one growable buffer per OpenMP thread, kept in a Workspace's scratch (no thread-local state): a
// parallel loop's body takes its thread's buffer with get(n), after prepare() outside the loop
template <class T>
class ThreadBuffers {
 public:
  void prepare() {
    const size_t threads = static_cast<size_t>(omp_get_max_threads());
    if (buffers_.size() < threads) buffers_.resize(threads);
  }
  T* get(size_t n) {
    std::vector<T>& b = buffers_[static_cast<size_t>(omp_get_thread_num())];
    if (b.size() < n) b.resize(n);
    return b.data();
  }

 private:
  std::vector<std::vector<T>> buffers_;
};

inline int threadCount() { return omp_get_max_threads(); }
inline void setThreadCount(int n) {
  if (n > 0) omp_set_num_threads(n);
}

}  // namespace soak
