// running the renderer's external tools (render/process.cpp): finding a program on PATH, the error that
// names the Debian package, and a child run without a terminal (stdin from /dev/null, output appended to
// a log) that reports its exit code or signal and is killed at its time limit. Only /bin/sh is needed
#include "render/process.hpp"

#include <soak/error.hpp>

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "io/file.hpp"

namespace soak {
namespace {

namespace fs = std::filesystem;

// a fresh folder, removed with the test
struct Folder {
  fs::path dir;
  explicit Folder(const std::string& name)
      : dir(fs::temp_directory_path() / ("soak_process_test_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  ~Folder() { fs::remove_all(dir); }
};

// sets PATH for the scope and puts the old value back
struct PathScope {
  std::string old;
  bool had;
  explicit PathScope(const std::string& path) : had(std::getenv("PATH") != nullptr) {
    if (had) old = std::getenv("PATH");
    ::setenv("PATH", path.c_str(), 1);
  }
  ~PathScope() {
    if (had)
      ::setenv("PATH", old.c_str(), 1);
    else
      ::unsetenv("PATH");
  }
};

// an executable regular file on PATH is found by its absolute path; a file without the execute bit, a
// folder of that name, or a name on no PATH entry is not; an empty entry is the current folder
TEST(RenderProcess, FindsExecutableRegularFilesOnThePath) {
  const Folder tmp("find");
  const fs::path a = tmp.dir / "a", b = tmp.dir / "b";
  fs::create_directories(a);
  fs::create_directories(b);
  writeTextFile((a / "tool").string(), "#!/bin/sh\n");         // not executable
  writeTextFile((b / "tool").string(), "#!/bin/sh\n");
  fs::permissions(b / "tool", fs::perms::owner_all);
  fs::create_directories(a / "dir");                           // a folder is not a program
  {
    const PathScope path(a.string() + ":" + b.string());
    EXPECT_EQ(findExecutable("tool"), (b / "tool").string());
    EXPECT_EQ(findExecutable("dir"), "");
    EXPECT_EQ(findExecutable("soak_no_such_tool"), "");
  }
  {
    const PathScope path(b.string() + ":" + a.string());
    fs::permissions(a / "tool", fs::perms::owner_all);
    EXPECT_EQ(findExecutable("tool"), (b / "tool").string());  // the first entry wins
  }
  {
    const fs::path cwd = fs::current_path();
    fs::current_path(b);
    {
      const PathScope path("/nonexistent::");
      const std::string found = findExecutable("tool");
      EXPECT_TRUE(fs::path(found).is_absolute()) << found;
      EXPECT_TRUE(!found.empty() && fs::equivalent(found, b / "tool")) << found;
    }
    {
      const PathScope path("");
      EXPECT_EQ(findExecutable("tool"), "") << "an empty PATH searches nothing";
    }
    fs::current_path(cwd);
  }
}

TEST(RenderProcess, AMissingToolNamesItsDebianPackage) {
  const PathScope path("/nonexistent");
  try {
    requireExecutable("povray", "povray", "or pass --pov-only");
    FAIL() << "found povray on an empty PATH";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              "povray was not found on PATH: install the Debian package povray (sudo apt-get install povray), "
              "or pass --pov-only");
  }
  try {
    requireExecutable("ffmpeg", "ffmpeg");
    FAIL() << "found ffmpeg on an empty PATH";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              "ffmpeg was not found on PATH: install the Debian package ffmpeg (sudo apt-get install ffmpeg)");
  }
}

// the child runs in the folder asked for, reads end of file at once from stdin, and its stdout and
// stderr are appended to the log; its exit code is reported
TEST(RenderProcess, RunsInItsFolderWithoutInputAndLogsBothStreams) {
  const Folder tmp("run");
  const std::string log = (tmp.dir / "tool.log").string();
  writeTextFile(log, "earlier\n");
  const auto t0 = std::chrono::steady_clock::now();
  const ProcessResult r =
      runProcess({"/bin/sh", "-c", "cat; echo to-stdout; echo to-stderr >&2; pwd; exit 3"}, tmp.dir.string(), log, 20.0);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  EXPECT_EQ(r.exitCode, 3);
  EXPECT_EQ(r.signal, 0);
  EXPECT_FALSE(r.timedOut);
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.describe(), "exit code 3");
  EXPECT_EQ(readTextFile(log), "earlier\nto-stdout\nto-stderr\n" + fs::canonical(tmp.dir).string() + "\n");
  const ProcessResult fine = runProcess({"/bin/sh", "-c", "exit 0"}, "", log, 20.0);
  EXPECT_TRUE(fine.ok());
  EXPECT_EQ(fine.describe(), "exit code 0");
}

// a child ended by a signal reports it by number and name; one still running at its limit is killed
// (by then, not after it would have finished) and reported as such
TEST(RenderProcess, ASignalOrTheTimeLimitIsReported) {
  const Folder tmp("signal");
  const std::string log = (tmp.dir / "tool.log").string();
  const ProcessResult killed = runProcess({"/bin/sh", "-c", "kill -TERM $$"}, "", log, 20.0);
  EXPECT_EQ(killed.signal, 15);
  EXPECT_FALSE(killed.ok());
  EXPECT_EQ(killed.describe(), "killed by signal 15 (Terminated)");
  const auto t0 = std::chrono::steady_clock::now();
  const ProcessResult slow = runProcess({"/bin/sh", "-c", "sleep 30"}, "", log, 0.3);
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_TRUE(slow.timedOut);
  EXPECT_FALSE(slow.ok());
  EXPECT_EQ(slow.describe(), "no result within the time limit (killed)");
  EXPECT_GE(took, 0.3);
  EXPECT_LT(took, 5.0);
}

TEST(RenderProcess, AProgramThatCannotStartIsAnError) {
  const Folder tmp("nostart");
  const std::string log = (tmp.dir / "tool.log").string();
  try {
    runProcess({"/nonexistent/soak_tool", "-x"}, "", log, 5.0);
    FAIL() << "started a program that does not exist";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "cannot start /nonexistent/soak_tool: No such file or directory");
  }
  try {
    runProcess({}, "", log, 5.0);
    FAIL() << "ran an empty command";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "runProcess: no program");
  }
}

// the last n lines of a log, each ending in a newline; all of a shorter file; "" for a missing one
TEST(RenderProcess, TailOfFileKeepsTheLastLines) {
  const Folder tmp("tail");
  const std::string path = (tmp.dir / "log.txt").string();
  writeTextFile(path, "one\ntwo\nthree\nfour\nfive");
  EXPECT_EQ(tailOfFile(path, 2), "four\nfive\n");
  EXPECT_EQ(tailOfFile(path, 10), "one\ntwo\nthree\nfour\nfive\n");
  EXPECT_EQ(tailOfFile(path, 0), "");
  EXPECT_EQ(tailOfFile((tmp.dir / "absent").string(), 3), "");
}

}  // namespace
}  // namespace soak
