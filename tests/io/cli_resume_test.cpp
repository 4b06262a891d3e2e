// soak run --checkpoint-every, soak resume, and SIGINT / SIGTERM end to end: a run continued from its
// checkpoint writes the same frames byte for byte as the unbroken run, and a stopped run says so in
// run.json with the true frame count
#include <gtest/gtest.h>

#include "io/cli_support.hpp"

#include <fmt/format.h>

#include <chrono>
#include <csignal>
#include <fcntl.h>
#include <thread>

namespace soak {
namespace {

using namespace soak::testing;

std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

nlohmann::json runJson(const fs::path& out) { return nlohmann::json::parse(readTextFile((out / "run.json").string())); }

// every frame file of frames 0..last in a and b is equal, byte for byte
void expectSameFrames(const fs::path& a, const fs::path& b, int last) {
  for (int f = 0; f <= last; ++f)
    for (const char* prefix : {"cloth_%04d.obj", "cloth_%04d.ply", "water_%04d.ply"}) {
      char name[32];
      std::snprintf(name, sizeof name, prefix, f);
      ASSERT_TRUE(fs::exists(a / name) && fs::exists(b / name)) << name;
      EXPECT_EQ(readTextFile((a / name).string()), readTextFile((b / name).string())) << name;
    }
}

// starts SOAK_BINARY with `args` in the background, its output into `log`
pid_t spawn(const std::vector<std::string>& args, const fs::path& log) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    std::vector<char*> argv{const_cast<char*>(SOAK_BINARY)};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(SOAK_BINARY, argv.data());
    ::_exit(127);
  }
  return pid;
}

int framesWritten(const fs::path& out) {
  try {
    return runJson(out).value("framesWritten", 0);
  } catch (const std::exception&) {
    return 0;  // not written yet
  }
}

TEST(CliResume, FortyFramesEqualTwentyAResumeAndTwentyMore) {
  const Cli cli("resume");
  const std::string scene = cli.writeScene("tiny.json", kTinyScene);
  const fs::path whole = cli.dir() / "whole", parts = cli.dir() / "parts";
  Result r = cli.run("run '" + scene + "' -o " + q(whole) + " --frames 40 --threads 2 -q");
  ASSERT_EQ(r.code, 0) << r.err;
  r = cli.run("run '" + scene + "' -o " + q(parts) + " --frames 20 --checkpoint-every 20 --threads 1 -q");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(runJson(parts)["checkpoint"]["frame"], 20);
  r = cli.run("resume " + q(parts) + " --frames 40 --threads 2");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("wrote frames 21..40"), std::string::npos) << r.out;

  expectSameFrames(whole, parts, 40);
  const nlohmann::json a = runJson(whole), b = runJson(parts);
  EXPECT_EQ(b["status"], "ok");
  EXPECT_EQ(b["framesWritten"], 41);
  EXPECT_EQ(b["stateHash"], a["stateHash"]);
  EXPECT_EQ(b["water"], a["water"]);
  ASSERT_EQ(b["resumes"].size(), 1u);
  EXPECT_EQ(b["resumes"][0]["fromFrame"], 20);
  EXPECT_EQ(b["checkpoint"]["frame"], 40);  // the run's checkpointEvery carries over
  const auto lines = readJsonLines(parts / "stats.jsonl");
  ASSERT_EQ(lines.size(), 41u);
  for (size_t f = 0; f < lines.size(); ++f) EXPECT_EQ(lines[f]["frame"], f);

  // a complete run has nothing to resume; a changed scene.json is refused
  r = cli.run("resume " + q(parts));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("complete to frame 40"), std::string::npos) << r.out;
  writeTextFile((parts / "scene.json").string(), readTextFile((parts / "scene.json").string()) + " ");
  r = cli.run("resume " + q(parts) + " --frames 50");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("another scene"), std::string::npos) << r.err;
  r = cli.run("resume " + q(whole));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("no checkpoint.soak"), std::string::npos) << r.err;
}

// SIGTERM in the middle of a frame (20 steps each): the step under way finishes, the checkpoint holds
// the steps taken into the next frame, run.json says "interrupted" with the frames really on disk,
// and the resumed run ends as the unbroken one, each frame's stats line counting all its steps
TEST(CliResume, SigtermWritesACheckpointAndTheTrueFrameCount) {
  const Cli cli("sigterm");
  const std::string scene = cli.writeScene("tiny.json", kTinyScene);
  const fs::path out = cli.dir() / "out", whole = cli.dir() / "whole";
  const pid_t pid = spawn({"run", scene, "-o", out.string(), "--frames", "100000", "--threads", "1",
                           "--set", "output.stepsPerFrame=20"},
                          cli.dir() / "log.txt");
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (framesWritten(out) < 4 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_EQ(::kill(pid, SIGTERM), 0);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status)) << readTextFile((cli.dir() / "log.txt").string());
  EXPECT_EQ(WEXITSTATUS(status), 128 + SIGTERM);
  EXPECT_NE(readTextFile((cli.dir() / "log.txt").string()).find("soak resume"), std::string::npos);

  const nlohmann::json run = runJson(out);
  EXPECT_EQ(run["status"], "interrupted");
  EXPECT_EQ(run["signal"], "SIGTERM");
  const int written = run["framesWritten"];
  ASSERT_GE(written, 4);
  EXPECT_TRUE(fs::exists(out / ("water_" + fmt::format("{:04d}", written - 1) + ".ply")));
  EXPECT_FALSE(fs::exists(out / ("water_" + fmt::format("{:04d}", written) + ".ply")));
  EXPECT_EQ(readJsonLines(out / "stats.jsonl").size(), static_cast<size_t>(written));
  EXPECT_EQ(run["checkpoint"]["frame"], written - 1);
  EXPECT_LT(run["checkpoint"]["stepsIntoFrame"].get<int>(), 20);

  const std::string last = std::to_string(written + 2);
  Result r = cli.run("resume " + q(out) + " --frames " + last + " -q");
  ASSERT_EQ(r.code, 0) << r.err;
  r = cli.run("run '" + scene + "' -o " + q(whole) + " --frames " + last + " --set output.stepsPerFrame=20 -q");
  ASSERT_EQ(r.code, 0) << r.err;
  expectSameFrames(whole, out, written + 2);
  EXPECT_EQ(runJson(out)["stateHash"], runJson(whole)["stateHash"]);
  const auto lines = readJsonLines(out / "stats.jsonl");
  ASSERT_EQ(lines.size(), static_cast<size_t>(written + 3));
  for (size_t f = 1; f < lines.size(); ++f) EXPECT_EQ(lines[f]["steps"], 20) << "frame " << f;
}

}  // namespace
}  // namespace soak
