// the worker threads of the parallel loops (OpenMP). Results are bit-identical for any count.
#pragma once

namespace soak {

// the most worker threads a program may ask for (OpenMP's runtime fails past its own limits)
inline constexpr int kMaxThreads = 1024;

// the threads a parallel loop uses
int threadCount();
// sets it for the calling program; n <= 0 leaves it unchanged, n > kMaxThreads throws soak::Error
void setThreadCount(int n);

}  // namespace soak
