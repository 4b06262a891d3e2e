// parallel loops: static OpenMP schedule over contiguous ranges. Every loop gathers (writes only its
// own index), so results do not depend on the thread count.
#pragma once
#include <omp.h>

#include <cstdint>

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

// the chunk of dynamically scheduled loops over cloth particles
constexpr int64_t kClothChunk = 256;

inline int threadCount() { return omp_get_max_threads(); }
inline void setThreadCount(int n) {
  if (n > 0) omp_set_num_threads(n);
}

}  // namespace soak
