// stop_signals.hpp
#include "stop_signals.hpp"

namespace soak::cli {

volatile std::sig_atomic_t gStopSignal = 0;

namespace {

extern "C" void onStopSignal(int sig) {
  gStopSignal = sig;
  std::signal(sig, SIG_DFL);  // a second signal stops at once
}

}  // namespace

StopSignals::StopSignals() {
  gStopSignal = 0;
  struct sigaction sa {};
  sa.sa_handler = onStopSignal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &oldInt_);
  sigaction(SIGTERM, &sa, &oldTerm_);
}

StopSignals::~StopSignals() {
  sigaction(SIGINT, &oldInt_, nullptr);
  sigaction(SIGTERM, &oldTerm_, nullptr);
}

}  // namespace soak::cli
