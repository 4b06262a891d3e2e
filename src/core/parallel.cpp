// the thread count of the parallel loops (soak/threads.hpp)
#include "core/parallel.hpp"

namespace soak {

int threadCount() { return omp_get_max_threads(); }

void setThreadCount(int n) {
  if (n > 0) omp_set_num_threads(n);
}

}  // namespace soak
