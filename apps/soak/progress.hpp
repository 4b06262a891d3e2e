// progress of a run on stderr: a redrawn bar on a terminal, a plain line every ~10% otherwise
#pragma once
#include <chrono>
#include <string>

namespace soak::cli {

class Progress {
 public:
  // frames firstFrame + 1 .. frames are to come (a resumed run starts past 0)
  Progress(int frames, bool enabled, int firstFrame = 0);
  // after frame `frame` (firstFrame + 1 .. frames) at simulated time t (s) with the frame's mean ms per step
  void update(int frame, double simTime, double msPerStep);
  // after `done` of `total` items of any kind: "<what> done/total  ELAPSED elapsed  ETA ..."
  void updateItems(const char* what, int done, int total);
  // wall time since the bar was made, s
  double seconds() const;
  // ends the bar's line (a terminal needs the newline)
  void finish();
  // "1:02:03", "4:05" or "6.7 s"
  static std::string formatDuration(double seconds);

 private:
  int frames_, firstFrame_;
  bool enabled_, tty_;
  int lastDecile_ = 0;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point start_;
  // draws `info` with a bar at done / total: redrawn on a terminal, a line at each new tenth otherwise
  void show(int done, int total, const std::string& info);
};

// a one-line hint when the machine is busy (1-minute load average at least the number of cores) and
// OpenMP threads spin while waiting (OMP_WAIT_POLICY unset or ACTIVE): each of the step's many
// barriers then waits for a descheduled thread (docs/performance.md). Empty otherwise.
std::string busyMachineHint(int threads);

}  // namespace soak::cli
