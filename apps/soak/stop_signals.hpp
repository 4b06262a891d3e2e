// SIGINT and SIGTERM as a request to stop cleanly, for the commands that run long (run, resume, sweep)
#pragma once
#include <csignal>

namespace soak::cli {

// the signal that asked the command to stop (0: none); the handler only sets it
extern volatile std::sig_atomic_t gStopSignal;

// while one lives, SIGINT and SIGTERM set gStopSignal (reset to 0 when it is made) instead of ending
// the process; a second signal ends it at once. No SA_RESTART, so a blocking wait returns EINTR. The
// previous handlers come back when it goes.
class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

 private:
  struct sigaction oldInt_ {}, oldTerm_ {};
};

}  // namespace soak::cli
