// soak sweep end to end: the variants of a grid run into their folders with their values, N at a
// time; the summary tables; a second run skips what is complete; a failing variant is marked and does
// not stop the others; --only, --collect, --dry-run; bad sweep files refused before anything runs
#include "io/cli_support.hpp"

#include <soak/render.hpp>

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <fcntl.h>
#include <sys/file.h>
#include <string>
#include <thread>

using namespace soak;
using namespace soak::testing;

namespace {

#define EXPECT_HAS(haystack, needle) EXPECT_NE(std::string(haystack).find(needle), std::string::npos) << (haystack)

// the tiny scene, and a sweep of it: 2 x 2 variants of 2 frames
struct SweepFixture {
  Cli cli;
  std::string scene, sweep, out;
  SweepFixture(const std::string& name, const std::string& body, int frames = 2)
      : cli(name), scene(cli.writeScene("tiny.json", kTinyScene)),
        sweep(cli.writeScene("sweep.json", R"({"scene": "tiny.json", "frames": )" + std::to_string(frames) + ", " + body + "}")),
        out((cli.dir() / "out").string()) {}
  // the contact sheet (POV-Ray, ffmpeg) only where a test asks for it
  Result run(const std::string& options = "", bool sheet = false) const {
    return cli.run("sweep '" + sweep + "' -o '" + out + "' " + options + (sheet ? "" : " --no-contact-sheet"));
  }
  nlohmann::json summary() const { return nlohmann::json::parse(readTextFile(out + "/summary.json")); }
  nlohmann::json runJson(const std::string& v) const { return nlohmann::json::parse(readTextFile(out + "/" + v + "/run.json")); }
};

const char* kGrid = R"("axes": {"solver.substeps": [1, 2], "cloth.0.material.arealDensity": {"from": 10, "to": 20, "count": 2}})";

}  // namespace

TEST(CliSweep, AGridRunsEveryVariantWithItsValuesAndSummarises) {
  const SweepFixture f("grid", kGrid);
  const Result r = f.run("--jobs 2 --threads 2");
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_HAS(r.out, "4 to run (0 complete), 2 at a time with 1 threads each");
  const nlohmann::json s = f.summary();
  ASSERT_EQ(s["variants"].size(), 4u);
  // the first key slowest: v001 is substeps 1 with the second density
  const nlohmann::json& v1 = s["variants"][1];
  EXPECT_EQ(v1["variant"], "v001");
  EXPECT_EQ(v1["params"]["solver.substeps"], 1);
  EXPECT_DOUBLE_EQ(v1["params"]["cloth.0.material.arealDensity"].get<double>(), 20.0);
  const nlohmann::json asRun = nlohmann::json::parse(readTextFile(f.out + "/v001/scene.json"));
  EXPECT_DOUBLE_EQ(asRun["cloth"][0]["material"]["arealDensity"].get<double>(), 20.0);
  EXPECT_EQ(asRun["solver"]["substeps"], 1);
  for (const auto& v : s["variants"]) {
    EXPECT_EQ(v["status"], "complete") << v.dump();
    EXPECT_EQ(v["framesWritten"], 3);
    EXPECT_GT(v["msPerStep"].get<double>(), 0.0);
    // the cloth is pinned at its corners and sags under the block: stretched a little, not torn
    EXPECT_GT(v["maxClothStrain"].get<double>(), 1e-3);
    EXPECT_LT(v["maxClothStrain"].get<double>(), 0.1);
    EXPECT_TRUE(v["wetAreaFraction"].is_null());  // no wetting in the scene
  }
  EXPECT_EQ(f.runJson("v003")["threads"], 1);
  const std::string csv = readTextFile(f.out + "/summary.csv");
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "variant,solver.substeps,cloth.0.material.arealDensity,status,error,framesWritten,frame,msPerStep,"
            "heldWaterKg,wetAreaFraction,maxClothStrain");
  EXPECT_HAS(csv, "\nv002,2,10.0,complete,,3,2,");

  // a second run finds every variant complete and runs nothing
  const std::string started = f.runJson("v000")["startTime"];
  const Result again = f.run();
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_HAS(again.out, "0 to run (4 complete)");
  EXPECT_EQ(f.runJson("v000")["startTime"], started);
  // more frames: every variant runs again (here from scratch: the sweep gives no checkpoint to extend)
  const Result more = f.run("--frames 3");
  ASSERT_EQ(more.code, 0) << more.err;
  EXPECT_HAS(more.out, "4 to run (0 complete)");
  EXPECT_EQ(f.runJson("v000")["framesWritten"], 4);
}

TEST(CliSweep, AFailingVariantIsMarkedAndTheOthersRun) {
  // the second variant's speed limit stops it at its first step (diverged); the third's scene is fine
  const SweepFixture f("fail", R"("variants": [{"solver.maxSpeed": 50}, {"solver.maxSpeed": 1e-4}, {"solver.maxSpeed": 20}])");
  const Result r = f.run("--jobs 1");
  EXPECT_EQ(r.code, 1) << r.out << r.err;
  EXPECT_HAS(r.out, "2 complete, 1 failed");
  const nlohmann::json s = f.summary();
  EXPECT_EQ(s["variants"][0]["status"], "complete");
  EXPECT_EQ(s["variants"][1]["status"], "diverged");
  EXPECT_HAS(s["variants"][1]["error"].get<std::string>(), "above solver.maxSpeed");
  EXPECT_EQ(s["variants"][2]["status"], "complete");
}

TEST(CliSweep, OnlyCollectAndDryRun) {
  const SweepFixture f("only", kGrid);
  const Result dry = f.run("--dry-run");
  ASSERT_EQ(dry.code, 0) << dry.err;
  EXPECT_HAS(dry.out, "v002  solver.substeps=2, cloth.0.material.arealDensity=10.0");
  EXPECT_FALSE(fs::exists(f.out + "/sweep.json"));
  // one array task's worth, then the summary without running anything
  const Result one = f.run("--only 2 -q");
  ASSERT_EQ(one.code, 0) << one.err;  // its own variant is complete (the others are still pending)
  EXPECT_TRUE(fs::exists(f.out + "/v002/run.json"));
  EXPECT_FALSE(fs::exists(f.out + "/v000"));
  const Result collect = f.run("--collect");
  EXPECT_EQ(collect.code, 1);  // not every variant is complete
  EXPECT_HAS(collect.out, "1 complete, 0 failed, 0 interrupted, 3 pending");
  EXPECT_EQ(f.summary()["variants"][0]["status"], "pending");
  EXPECT_EQ(f.summary()["variants"][2]["status"], "complete");
  const Result beyond = f.run("--only 4");
  EXPECT_EQ(beyond.code, 1);
  EXPECT_HAS(beyond.err, "--only 4: the sweep has variants 0 to 3");
}

TEST(CliSweep, BadSweepFilesAreRefusedBeforeAnythingRuns) {
  const auto errorOf = [](const std::string& name, const std::string& body) {
    const SweepFixture f(name, body);
    const Result r = f.run();
    EXPECT_EQ(r.code, 1) << r.out;
    EXPECT_FALSE(fs::exists(f.out)) << body;
    return r.err;
  };
  EXPECT_HAS(errorOf("both", R"("axes": {"solver.substeps": [1]}, "variants": [{"solver.substeps": 1}])"),
             "sweep.json: expected either \"axes\" (every combination) or \"variants\" (a list), not both or neither");
  EXPECT_HAS(errorOf("count", R"("axes": {"solver.dt": {"from": 0.01, "to": 0.02, "count": 0}})"),
             "sweep.json: at axes.solver.dt.count: expected an integer in [1, 10000]");
  EXPECT_HAS(errorOf("keys", R"("variants": [{"solver.dt": 0.01}, {"solver.substeps": 2}])"),
             "sweep.json: at variants[1]: expected the keys of variants[0] (solver.dt), in that order");
  EXPECT_HAS(errorOf("unknown", R"("axis": {"solver.dt": [0.01]})"), "sweep.json: at axis: unknown key");
  // a value the scene refuses names the variant, before any variant runs
  EXPECT_HAS(errorOf("value", R"("axes": {"solver.substeps": [1, 0]})"),
             "sweep.json: variant v001 (solver.substeps=0): ");
  // a folder holding another sweep is not overwritten
  const SweepFixture f("other", kGrid);
  ASSERT_EQ(f.run("--only 0 -q").code, 0);
  writeTextFile(f.sweep, R"({"scene": "tiny.json", "frames": 2, "axes": {"solver.substeps": [3]}})");
  const Result r = f.run();
  EXPECT_EQ(r.code, 1);
  EXPECT_HAS(r.err, "holds another sweep");
}

// SIGTERM to the sweep: it passes the signal on once, each running variant writes its checkpoint and
// stops, the summary says "interrupted"; the same command (here with fewer frames) resumes them
TEST(CliSweep, SigtermInterruptsTheVariantsAndTheNextSweepResumesThem) {
  const SweepFixture f("sigterm", R"("axes": {"solver.substeps": [1, 2]})", 100000);
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int fd = ::open((f.cli.dir() / "log.txt").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    ::execl(SOAK_BINARY, SOAK_BINARY, "sweep", f.sweep.c_str(), "-o", f.out.c_str(), "--jobs", "2", "--threads", "2",
            static_cast<char*>(nullptr));
    ::_exit(127);
  }
  const auto written = [&](const std::string& v) {
    try {
      return f.runJson(v).value("framesWritten", 0);
    } catch (const std::exception&) {
      return 0;  // not written yet
    }
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while ((written("v000") < 3 || written("v001") < 3) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_EQ(::kill(pid, SIGTERM), 0);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 128 + SIGTERM) << readTextFile((f.cli.dir() / "log.txt").string());
  for (const auto& v : f.summary()["variants"]) {
    EXPECT_EQ(v["status"], "interrupted") << v.dump();
    EXPECT_HAS(v["error"].get<std::string>(), "SIGTERM");
  }
  const int last = std::max(written("v000"), written("v001")) + 1;
  const Result r = f.run("--frames " + std::to_string(last));
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_HAS(r.out, "2 to run (0 complete)");
  for (const char* v : {"v000", "v001"}) {
    EXPECT_EQ(f.runJson(v)["status"], "ok");
    EXPECT_EQ(f.runJson(v)["framesWritten"], last + 1);
    EXPECT_EQ(f.runJson(v)["resumes"].size(), 1u) << f.runJson(v).dump();
    EXPECT_HAS(readTextFile(f.out + "/" + v + ".log"), "--- soak sweep: resumed from the checkpoint ---");
  }
}

// --slurm --dry-run writes the job array script for the variants still to run, and submits nothing
TEST(CliSweep, SlurmScriptHasATaskPerVariantStillToRun) {
  const SweepFixture f("sbatch", kGrid);
  ASSERT_EQ(f.run("--only 1 -q").code, 0);
  const Result r = f.run("--slurm --dry-run --partition short --time 0:30:00 --cpus-per-task 2");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_HAS(r.out, "sweep.sbatch (3 tasks); submit it with: sbatch ");
  const std::string script = readTextFile(f.out + "/sweep.sbatch");
  EXPECT_EQ(script.substr(0, 12), "#!/bin/bash\n");
  EXPECT_HAS(script, "\n#SBATCH --array=0,2-3\n");
  EXPECT_HAS(script, "\n#SBATCH --cpus-per-task=2\n");
  EXPECT_HAS(script, "\n#SBATCH --time=0:30:00\n");
  EXPECT_HAS(script, "\n#SBATCH --partition=short\n");
  EXPECT_HAS(script, "\n#SBATCH --output=" + f.out + "/slurm-%A_%a.out\n");
  EXPECT_HAS(script, " sweep " + f.sweep + " -o " + f.out + " --frames 2 --only \"$SLURM_ARRAY_TASK_ID\" --threads \"${SLURM_CPUS_PER_TASK:-2}\" -q\n");
  // what cannot go on an #SBATCH line is refused
  const Result bad = f.run("--slurm --dry-run --partition 'a b'");
  EXPECT_EQ(bad.code, 1);
  EXPECT_HAS(bad.err, "expected no space, quote, backslash or control character");
  EXPECT_NE(f.run("--partition short").code, 0);  // a Slurm option without --slurm
}

// the contact sheet: each variant's last frame, 2 x 2 for 4 variants, each picture with its folder
// and values under it (3 lines); the variant that failed gets a blank tile
TEST(CliSweep, TheContactSheetHasAPicturePerVariant) {
  const SweepFixture f("sheet", R"("contactSheet": {"width": 64, "height": 48, "particles": true},
      "variants": [{"solver.maxSpeed": 50}, {"solver.maxSpeed": 1e-4}, {"solver.maxSpeed": 20}, {"solver.maxSpeed": 30}])");
  const Result r = f.run("--jobs 2", true);
  EXPECT_EQ(r.code, 1) << r.out << r.err;  // one diverged
  EXPECT_HAS(r.out, "contact sheet " + f.out + "/contact_sheet.png");
  for (const char* v : {"v000", "v002", "v003"}) EXPECT_TRUE(fs::exists(f.out + "/" + v + "/sheet/frame_0002.png")) << v;
  EXPECT_FALSE(fs::exists(f.out + "/v001/sheet"));
  // two columns of 64 pixels; two rows of 48 pixels and a caption band of 2 lines (18 px) + 2 x 6 px
  EXPECT_EQ(pngSize(f.out + "/contact_sheet.png"), (std::pair{128, 2 * (48 + 2 * 18 + 12)}));
  // one variant: one tile, no grid
  const SweepFixture one("sheet1", R"("contactSheet": {"width": 64, "height": 48, "particles": true},
      "variants": [{"solver.maxSpeed": 50}])");
  ASSERT_EQ(one.run("", true).code, 0);
  EXPECT_EQ(pngSize(one.out + "/contact_sheet.png"), (std::pair{64, 48 + 2 * 18 + 12}));
}

// a variant another sweep runs (its DIR/vNNN.lock held) is left alone; once the lock is free it runs
TEST(CliSweep, AVariantLockedByAnotherSweepIsLeftAlone) {
  const SweepFixture f("lock", kGrid);
  fs::create_directories(f.out);
  const int fd = ::open((f.out + "/v000.lock").c_str(), O_RDWR | O_CREAT, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
  const Result r = f.run("--jobs 2");
  EXPECT_EQ(r.code, 1) << r.out << r.err;  // not every variant is complete
  EXPECT_HAS(r.out, "v000 is being run by another sweep; left alone");
  EXPECT_HAS(r.out, "3 complete, 0 failed, 0 interrupted, 1 pending");
  EXPECT_FALSE(fs::exists(f.out + "/v000"));
  ::close(fd);
  const Result again = f.run();
  EXPECT_EQ(again.code, 0) << again.out << again.err;
  EXPECT_HAS(again.out, "1 to run (3 complete)");
}
