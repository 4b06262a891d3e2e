#include "progress.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <unistd.h>

namespace soak::cli {

std::string busyMachineHint(int threads) {
  if (threads < 2) return "";
  const char* policy = std::getenv("OMP_WAIT_POLICY");
  if (policy && (std::string(policy) == "PASSIVE" || std::string(policy) == "passive")) return "";
  double load = 0.0;
  const long cores = sysconf(_SC_NPROCESSORS_ONLN);
  if (getloadavg(&load, 1) != 1 || cores < 1 || load < static_cast<double>(cores)) return "";
  char text[320];
  std::snprintf(text, sizeof text,
                "soak: note: this machine is busy (load %.1f on %ld cores); with OpenMP's default spinning "
                "waits soak can be several times slower here: OMP_WAIT_POLICY=PASSIVE helps "
                "(docs/performance.md)\n",
                load, cores);
  return text;
}

Progress::Progress(int frames, bool enabled, int firstFrame)
    : frames_(frames),
      firstFrame_(firstFrame),
      enabled_(enabled),
      tty_(::isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()) {}

std::string Progress::formatDuration(double s) {
  if (!std::isfinite(s) || s < 0) return "?";
  if (s < 60) return fmt::format("{:.1f} s", s);
  const long total = std::lround(s);
  if (total < 3600) return fmt::format("{}:{:02d}", total / 60, total % 60);
  return fmt::format("{}:{:02d}:{:02d}", total / 3600, (total / 60) % 60, total % 60);
}

double Progress::seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void Progress::update(int frame, double simTime, double msPerStep) {
  if (!enabled_ || frames_ <= 0) return;
  const double eta = seconds() / std::max(1, frame - firstFrame_) * (frames_ - frame);
  show(frame, frames_,
       fmt::format("frame {}/{}  t = {:.3f} s  {:.1f} ms/step  ETA {}", frame, frames_, simTime, msPerStep,
                   formatDuration(eta)));
}

void Progress::updateItems(const char* what, int done, int total) {
  if (!enabled_ || total <= 0 || done <= 0) return;
  const double elapsed = seconds();
  show(done, total, fmt::format("{} {}/{}  {} elapsed  ETA {}", what, done, total, formatDuration(elapsed),
                                formatDuration(elapsed / done * (total - done))));
}

void Progress::show(int done, int total, const std::string& info) {
  if (tty_) {
    constexpr int kWidth = 30;
    const int filled = done * kWidth / total;
    std::fprintf(stderr, "\r[%s%s] %s\033[K", std::string(filled, '#').c_str(),
                 std::string(kWidth - filled, '.').c_str(), info.c_str());
    std::fflush(stderr);
    drawn_ = true;
    return;
  }
  // a log file gets a line at each new tenth (and the last item)
  const int decile = done * 10 / total;
  if (decile > lastDecile_ || done == total) {
    lastDecile_ = decile;
    std::fprintf(stderr, "soak: %s\n", info.c_str());
  }
}

void Progress::finish() {
  if (drawn_) std::fputc('\n', stderr);
  drawn_ = false;
}

}  // namespace soak::cli
