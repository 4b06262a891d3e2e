// parallel loops: static OpenMP schedule over contiguous ranges. Every loop gathers (writes only its
// own index), so results do not depend on the thread count.
#pragma once
#include <omp.h>
#include <soak/threads.hpp>

#include <cstddef>
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

// Ordered chunks: items cut into chunks whose results vary in length (neighbour lists, contacts).
// The chunks go to whichever thread is free (dynamic schedule), each filling its own buffer; the
// buffers are then read in chunk order, so the result does not depend on the thread count.
//   local(): the per-thread state of the fill (caches, marks), made once per thread
//   fill(local, c, buffer): appends chunk c's results to its (cleared) buffer
// fillChunks stops there (the caller joins the buffers). orderedChunks goes on: offset[c] becomes
// the place of chunk c's first result when the buffers follow each other from `base`
// (offset[chunks] is the end), then size(offset) runs once and place(c) runs for every chunk, in
// parallel, to copy chunk c into its place. buffers and offset are kept by the caller's scratch.
template <class T, class Local, class Fill>
inline void fillChunksOnThisTeam(int64_t chunks, std::vector<std::vector<T>>& buffers, Local&& local, Fill&& fill) {
  auto state = local();
#pragma omp for schedule(dynamic, 1)
  for (int64_t c = 0; c < chunks; ++c) {
    // the buffer held here while it grows: the buffers' vector headers share cache lines, and each
    // insert into a header in the shared array would take the line from the other cores
    std::vector<T> out = std::move(buffers[static_cast<size_t>(c)]);
    out.clear();
    fill(state, c, out);
    buffers[static_cast<size_t>(c)] = std::move(out);
  }
}

template <class T, class Local, class Fill>
inline void fillChunks(int64_t chunks, std::vector<std::vector<T>>& buffers, int threads, Local&& local, Fill&& fill) {
  if (buffers.size() < static_cast<size_t>(chunks)) buffers.resize(static_cast<size_t>(chunks));
#pragma omp parallel num_threads(threads)
  fillChunksOnThisTeam(chunks, buffers, local, fill);
}

template <class T, class Local, class Fill, class Size, class Place>
inline void orderedChunks(int64_t chunks, std::vector<std::vector<T>>& buffers, std::vector<size_t>& offset,
                          size_t base, bool parallel, Local&& local, Fill&& fill, Size&& size, Place&& place) {
  if (buffers.size() < static_cast<size_t>(chunks)) buffers.resize(static_cast<size_t>(chunks));
  offset.resize(static_cast<size_t>(chunks) + 1);
#pragma omp parallel if (parallel)
  {
    fillChunksOnThisTeam(chunks, buffers, local, fill);
#pragma omp single
    {
      offset[0] = base;
      for (int64_t c = 0; c < chunks; ++c)
        offset[static_cast<size_t>(c) + 1] = offset[static_cast<size_t>(c)] + buffers[static_cast<size_t>(c)].size();
      size(offset);
    }
#pragma omp for schedule(static)
    for (int64_t c = 0; c < chunks; ++c) place(c);
  }
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


}  // namespace soak
