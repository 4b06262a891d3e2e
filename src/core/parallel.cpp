// the thread count of the parallel loops (soak/threads.hpp)
#include "core/parallel.hpp"

#include <soak/error.hpp>
#include <soak/threads.hpp>

#include <string>

namespace soak {

int threadCount() { return omp_get_max_threads(); }

void setThreadCount(int n) {
  if (n > kMaxThreads)
    throw Error("threads: expected at most " + std::to_string(kMaxThreads) + " worker threads, got " + std::to_string(n));
  if (n > 0) omp_set_num_threads(n);
}

}  // namespace soak
