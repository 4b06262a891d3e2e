// running the external tools of the renderer (povray, ffmpeg) without a terminal: stdin from
// /dev/null, output to a log file, a wall-clock limit after which the process is killed
#pragma once
#include <string>
#include <vector>

namespace soak {

// the full path of `name` found on $PATH (an executable regular file), or "" when there is none
std::string findExecutable(const std::string& name);

// throws soak::Error "<name> was not found on PATH: install the Debian package <package> (...)"
// when `name` is missing; returns its full path
std::string requireExecutable(const std::string& name, const std::string& package, const std::string& hint = "");

struct ProcessResult {
  int exitCode = -1;      // when it exited
  int signal = 0;         // when a signal ended it
  bool timedOut = false;  // it ran past the limit and was killed
  bool ok() const { return !timedOut && signal == 0 && exitCode == 0; }
  std::string describe() const;  // "exit code 2", "killed by signal 11", "no result within 30 s"
};

// runs argv (argv[0] a full path) in `cwd` (empty: the current folder) with stdin from /dev/null and
// stdout and stderr appended to logPath; kills it (SIGKILL, by its pid) once timeoutSeconds have
// passed. Throws soak::Error when the process cannot be started.
ProcessResult runProcess(const std::vector<std::string>& argv, const std::string& cwd, const std::string& logPath,
                         double timeoutSeconds);

// the last `lines` lines of a text file ("" when unreadable)
std::string tailOfFile(const std::string& path, int lines);

}  // namespace soak
