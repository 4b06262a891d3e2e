// the worker threads of the parallel loops (OpenMP). Results are bit-identical for any count.
#pragma once

namespace soak {

// the threads a parallel loop uses
int threadCount();
// sets it for the calling program; n <= 0 leaves it unchanged
void setThreadCount(int n);

}  // namespace soak
