// the soak program end to end: run, validate, bench and --version on small scenes in a temp dir
#include <gtest/gtest.h>

#include "io/cli_support.hpp"
#include "io/file.hpp"
#include "io/ply.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <filesystem>

namespace soak {
namespace {

using namespace soak::testing;

TEST(CliRun, TinySceneWritesEveryFrameAndAccountsWater) {
  const Cli cli("tiny");
  const std::string scene = cli.writeScene("tiny.json", kTinyScene);
  const fs::path out = cli.dir() / "out";
  const Result r = cli.run("run '" + scene + "' -o '" + out.string() + "' --threads 2");
  ASSERT_EQ(r.code, 0) << r.err;
  for (int f = 0; f <= 3; ++f)
    for (const char* name : {"cloth_%04d.obj", "cloth_%04d.ply", "water_%04d.ply"}) {
      char file[32];
      std::snprintf(file, sizeof file, name, f);
      EXPECT_TRUE(fs::exists(out / file)) << file;
    }
  EXPECT_FALSE(fs::exists(out / "water_0004.ply"));
  EXPECT_TRUE(fs::exists(out / "scene.json"));
  const nlohmann::json run = nlohmann::json::parse(readTextFile((out / "run.json").string()));
  EXPECT_EQ(run["status"], "ok");
  EXPECT_EQ(run["framesWritten"], 4);
  EXPECT_EQ(run["threads"], 2);

  const auto lines = readJsonLines(out / "stats.jsonl");
  ASSERT_EQ(lines.size(), 4u);  // frame 0 and 3 frames
  for (size_t f = 0; f < lines.size(); ++f) {
    const nlohmann::json& l = lines[f];
    EXPECT_EQ(l["frame"], f);
    EXPECT_EQ(l["step"], 2 * f);
    EXPECT_FALSE(l.contains("error"));
    EXPECT_EQ(l["counts"]["cloth"], 100);
    const double emitted = l["waterMass"]["emitted"];
    const double accounted = l["waterMass"]["free"].get<double>() + l["waterMass"]["removedAtBounds"].get<double>();
    EXPECT_NEAR(accounted, emitted, 1e-5 * std::max(emitted, 1e-3)) << "frame " << f;
  }
  // the block is emitted in the first step and nothing leaves the domain in 0.06 s
  EXPECT_EQ(lines[3]["counts"]["water"], kTinyWater);
  EXPECT_NEAR(lines[3]["waterMass"]["emitted"].get<double>(), kTinyWater * 0.0082, 1e-6);
  EXPECT_GT(lines[3]["ms"]["total"].get<double>(), 0.0);

  // the frame files agree with the stats
  const PlyData water = readPly((out / "water_0003.ply").string());
  EXPECT_EQ(water.element("vertex").count, static_cast<size_t>(kTinyWater));
  const PlyData cloth = readPly((out / "cloth_0003.ply").string());
  EXPECT_EQ(cloth.element("vertex").count, 100u);
  EXPECT_EQ(cloth.element("face").count, 2u * 9 * 9);
  // scene.json is the scene as run: it validates on its own
  const Result again = cli.run("validate '" + (out / "scene.json").string() + "'");
  EXPECT_EQ(again.code, 0) << again.err;
}

TEST(CliRun, RefusesNonEmptyOutputDirWithoutOverwrite) {
  const Cli cli("nonempty");
  const std::string scene = cli.writeScene("tiny.json", kTinyScene);
  const fs::path out = cli.dir() / "out";
  fs::create_directories(out);
  writeTextFile((out / "notes.txt").string(), "mine");
  const Result r = cli.run("run '" + scene + "' -o '" + out.string() + "' --frames 1");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("not empty"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--overwrite"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "stats.jsonl"));

  const Result o = cli.run("run '" + scene + "' -o '" + out.string() + "' --frames 1 --overwrite --quiet");
  EXPECT_EQ(o.code, 0) << o.err;
  EXPECT_TRUE(fs::exists(out / "water_0001.ply"));
  EXPECT_EQ(readTextFile((out / "notes.txt").string()), "mine");  // --overwrite leaves other files alone
  EXPECT_EQ(readJsonLines(out / "stats.jsonl").size(), 2u);
}

TEST(CliRun, BadSceneFailsBeforeAnyOutputNamingTheFile) {
  const Cli cli("bad");
  const std::string broken = cli.writeScene("broken.json", R"({"solver": {"substeps": "many"}})");
  const fs::path out = cli.dir() / "out";
  Result r = cli.run("run '" + broken + "' -o '" + out.string() + "'");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(broken), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("solver.substeps"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));

  const std::string missing = (cli.dir() / "missing.json").string();
  r = cli.run("run '" + missing + "' -o '" + out.string() + "'");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(missing), std::string::npos) << r.err;

  r = cli.run("validate '" + broken + "'");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(broken), std::string::npos) << r.err;

  const std::string tiny = cli.writeScene("tiny.json", kTinyScene);
  r = cli.run("run '" + tiny + "' -o '" + out.string() + "' --set solver.dt=-1");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("solver.dt"), std::string::npos) << r.err;
}

TEST(CliRun, DivergenceWritesTheBadFrameAndExitsTwo) {
  const Cli cli("diverge");
  const std::string scene = cli.writeScene("tiny.json", kTinyScene);
  const fs::path out = cli.dir() / "out";
  // anything falling for 0.02 s moves faster than 0.05 m/s
  const Result r = cli.run("run '" + scene + "' -o '" + out.string() + "' --set solver.maxSpeed=0.05");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("frame 1"), std::string::npos) << r.err;
  const auto lines = readJsonLines(out / "stats.jsonl");
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_FALSE(lines[0].contains("error"));
  ASSERT_TRUE(lines[1].contains("error"));
  EXPECT_NE(lines[1]["error"].get<std::string>().find("maxSpeed"), std::string::npos);
  EXPECT_TRUE(fs::exists(out / "cloth_0001.obj"));
  EXPECT_FALSE(fs::exists(out / "cloth_0002.obj"));
  EXPECT_EQ(nlohmann::json::parse(readTextFile((out / "run.json").string()))["status"], "diverged");
}

// an implicit 5 x 5 sheet hung by two corners, 3 frames of one step
constexpr const char* kHungGarment = R"({
  "solver": {"dt": 0.01, "domain": {"min": [-1, 0, -1], "max": [1, 2, 1]}},
  "output": {"frames": 3, "stepsPerFrame": 1},
  "cloth": [{"name": "sheet", "solver": "implicit", "fabric": "cotton",
             "mesh": {"type": "rectangle", "center": [0, 1, 0], "size": [0.2, 0.2], "resolution": [5, 5]},
             "material": {"particleMass": 2e-4}, "pin": {"corners": [0, 1]}}]
})";

// the summary counts the implicit steps, their iterations, the capped and the halved ones; a run that
// diverges after halving its garment steps says so
TEST(CliRun, GarmentRunsSummariseTheirSolvesAndHalvings) {
  const Cli cli("garment");
  const std::string scene = cli.writeScene("hung.json", kHungGarment);
  Result r = cli.run("run '" + scene + "' -o '" + (cli.dir() / "ok").string() + "' --threads 1");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("soak: garments: 3 implicit steps"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("0 stopped at the iteration cap, 0 redone in shorter steps"), std::string::npos) << r.out;

  // falling from rest, every try of the first step passes 5 cm/s: halved three times, then stopped
  const fs::path out = cli.dir() / "fast";
  r = cli.run("run '" + scene + "' -o '" + out.string() + "' --threads 1 --set solver.maxSpeed=0.05");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("redone in shorter steps 3 times first"), std::string::npos) << r.err;
  const auto lines = readJsonLines(out / "stats.jsonl");
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[1]["garment"]["halvedSteps"], 3);
  EXPECT_EQ(lines[1]["garment"]["solves"], 8);
}

TEST(CliValidate, EveryShippedSceneIsValid) {
  const Cli cli("validate");
  int scenes = 0;
  for (const char* folder : {"scenes", "bench"}) {
    const fs::path dir = fs::path(SOAK_SOURCE_DIR) / folder;
    if (!fs::exists(dir)) continue;
    for (const auto& e : fs::directory_iterator(dir)) {
      if (e.path().extension() != ".json" || e.path().filename() == "benchmarks.json") continue;
      const Result r = cli.run("validate '" + e.path().string() + "'");
      EXPECT_EQ(r.code, 0) << e.path() << "\n" << r.err;
      EXPECT_NE(r.out.find("valid"), std::string::npos) << r.out;
      ++scenes;
    }
  }
  EXPECT_GE(scenes, 4);
}

// `soak export-body` writes the scene's mannequin as body_NNNN.obj for its frames 0 .. N at its frame
// rate, says how to use them, refuses to overwrite unasked and names a missing collider; the files
// play back as a meshSequence collider
TEST(CliExportBody, WritesTheMannequinAsAnObjSequence) {
  const Cli cli("export_body");
  const std::string scene = cli.writeScene("body.json", R"({
    "name": "body", "description": "cli test: a small mannequin under a small cloth",
    "solver": {"dt": 0.01, "substeps": 1, "domain": {"min": [-1, -0.5, -1], "max": [1, 2, 1]}},
    "output": {"frames": 3, "stepsPerFrame": 2},
    "colliders": [{"name": "bob", "type": "mannequin", "height": 1.0}],
    "cloth": [{"name": "sheet", "mesh": {"type": "rectangle", "center": [0, 1.5, 0], "size": [0.2, 0.2],
               "resolution": [5, 5], "axisU": [1, 0, 0], "axisV": [0, 0, 1]}}]})");
  const fs::path out = cli.dir() / "seq";
  const Result r = cli.run("export-body '" + scene + "' -o '" + out.string() + "' --cell 0.03");
  ASSERT_EQ(r.code, 0) << r.err;
  for (int f = 1; f <= 4; ++f) EXPECT_TRUE(fs::exists(out / fmt::format("body_{:04d}.obj", f))) << f;
  EXPECT_FALSE(fs::exists(out / "body_0005.obj"));
  EXPECT_NE(r.out.find("wrote 4 frames"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(R"("type": "meshSequence", "path": ")" + (out / "body_####.obj").string() + R"(", "fps": 50})"),
            std::string::npos)
      << r.out;
  const Result again = cli.run("export-body '" + scene + "' -o '" + out.string() + "' --cell 0.03");
  EXPECT_EQ(again.code, 1);
  EXPECT_NE(again.err.find("body_0001.obj: at export-body: the file exists; pass --overwrite"), std::string::npos)
      << again.err;
  EXPECT_EQ(cli.run("export-body '" + scene + "' -o '" + out.string() + "' --cell 0.03 --overwrite -q").code, 0);
  const Result nobody = cli.run("export-body '" + scene + "' -o '" + out.string() + "' --collider alice");
  EXPECT_NE(nobody.err.find("expected a mannequin collider named 'alice'"), std::string::npos) << nobody.err;
  const std::string played = cli.writeScene("played.json", R"({
    "name": "played", "description": "cli test: the exported body as a mesh sequence",
    "solver": {"dt": 0.01, "substeps": 1, "domain": {"min": [-1, -0.5, -1], "max": [1, 2, 1]}},
    "output": {"frames": 3, "stepsPerFrame": 2},
    "colliders": [{"name": "bob", "type": "meshSequence", "path": "seq/body_####.obj", "fps": 50}],
    "cloth": [{"name": "sheet", "mesh": {"type": "rectangle", "center": [0, 1.5, 0], "size": [0.2, 0.2],
               "resolution": [5, 5], "axisU": [1, 0, 0], "axisV": [0, 0, 1]}}]})");
  const Result valid = cli.run("validate '" + played + "'");
  EXPECT_EQ(valid.code, 0) << valid.err;
  // the shipped OBJ-body scene (its frames are generated, so no other test loads it) is valid on them
  const Result shipped = cli.run("validate '" + std::string(SOAK_SOURCE_DIR) +
                                 "/scenes/obj_body/garment_tshirt_obj_body.json' --set 'colliders.0.path=" +
                                 (out / "body_####.obj").string() + "'");
  EXPECT_EQ(shipped.code, 0) << shipped.err;
}

TEST(CliValidate, SummaryCountsParticlesAndPieces) {
  const Cli cli("summary");
  const std::string scene = cli.writeScene("tiny.json", kTinyScene);
  const Result r = cli.run("validate '" + scene + "' --set solver.substeps=3 --set solver.clothPinPasses=3");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("100 cloth"), std::string::npos) << r.out;
  // the PBD cloth's convergence settings, as set
  EXPECT_NE(r.out.find("PBD cloth:   1 small steps a substep, 6 coarse levels, 3 passes within 5 edges of a pin\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("64 water from blocks"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1 pieces"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("3 substeps"), std::string::npos) << r.out;
  // the piece's area and dry weight: 0.2 x 0.2 m at the default 16.5 kg/m^2
  EXPECT_NE(r.out.find("0.04 m^2, 0.66 kg dry (16.5 kg/m^2)"), std::string::npos) << r.out;
}

TEST(CliValidate, EmittersAreNamedByKind) {
  const Cli cli("kinds");
  std::string text = kTinyScene;
  const std::string block = R"({"name": "cube", "type": "block")";
  text.replace(text.find(block), block.size(),
               R"({"name": "nozzle", "type": "jet", "origin": [0, 0.9, 0], "radius": 0.03, "end": 0.5},
                  {"name": "shower", "type": "rain", "origin": [0, 0.9, 0], "halfExtents": [0.1, 0.1], "start": 0.1},
                  {"name": "cube", "type": "block")");
  const Result r = cli.run("validate '" + cli.writeScene("kinds.json", text) + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("nozzle       jet of radius 0.03 m at 4 m/s, t = 0..0.5 s"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("shower       rain of 200 drops/(s m^2) over 0.2 x 0.2 m at 6.5 m/s, from t = 0.1 s"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("cube         block of [-0.04, 0.54, -0.04] to [0.04, 0.62, 0.04] m at t = 0 s"),
            std::string::npos)
      << r.out;
}

TEST(CliRun, ThreadCountIsBounded) {
  const Cli cli("threads");
  const std::string scene = cli.writeScene("tiny.json", kTinyScene);
  const Result r = cli.run("run '" + scene + "' -o '" + (cli.dir() / "out").string() + "' --threads 100000");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("--threads: Value 100000 not in range 1 to 1024"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(cli.dir() / "out"));
}

TEST(CliVersion, PrintsTheVersion) {
  const Cli cli("version");
  const Result r = cli.run("--version");
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find(std::string("soak ") + SOAK_VERSION + "\n"), std::string::npos) << r.out;  // CMake's project version
  EXPECT_EQ(cli.run("").code, 1);              // no subcommand
  EXPECT_EQ(cli.run("run --frames 2").code, 1);  // no scene, no -o
}

TEST(CliBench, TimesEachSceneInItsOwnProcess) {
  const Cli cli("bench");
  const std::string a = cli.writeScene("tiny_a.json", kTinyScene);
  const std::string b = cli.writeScene("tiny_b.json", kTinyScene);
  const fs::path json = cli.dir() / "bench.json";
  const Result r = cli.run("bench --scene '" + a + "' --scene '" + b + "' --steps 2 --warmup 1 --threads 1 --stages --json '" +
                           json.string() + "' --set solver.clothHierarchy=2");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("tiny_a"), std::string::npos) << r.out;
  // --stages: a second table of the stages' parts, a line a scene
  const size_t parts = r.out.find("parts (ms)");
  ASSERT_NE(parts, std::string::npos) << r.out;
  EXPECT_NE(r.out.find("selfCollision", parts), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("tiny_b", parts), std::string::npos) << r.out;
  const nlohmann::json doc = nlohmann::json::parse(readTextFile(json.string()));
  ASSERT_EQ(doc["results"].size(), 2u);
  for (const nlohmann::json& res : doc["results"]) {
    EXPECT_FALSE(res.contains("error")) << res.dump();
    EXPECT_EQ(res["particles"]["cloth"], 100);
    EXPECT_EQ(res["particles"]["water"], kTinyWater);
    EXPECT_EQ(res["steps"], 2);
    EXPECT_EQ(res["threads"], 1);
    EXPECT_EQ(res["clothSolve"]["hierarchy"], 2);  // as --set
    EXPECT_EQ(res["clothSolve"]["pinPasses"], 8);
    EXPECT_GT(res["msPerStepMedian"]["total"].get<double>(), 0.0);
    EXPECT_GT(res["msPerStepMedianParts"]["neighbors.lists"].get<double>(), 0.0);
    EXPECT_LE(res["msPerStepMeanParts"]["neighbors.lists"].get<double>(),
              res["msPerStepMeanStages"]["neighbors"].get<double>() * (1.0 + 1e-9));
    EXPECT_GT(res["peakRssBytes"].get<double>(), 1e6);
    EXPECT_NEAR(res["bytesPerParticle"].get<double>(), res["peakRssBytes"].get<double>() / 164.0, 1e-6);
  }
  // a scene that is neither a file nor a manifest entry is refused
  const Result bad = cli.run("bench --scene no_such_benchmark --steps 1");
  EXPECT_EQ(bad.code, 1);
  EXPECT_NE(bad.err.find("no_such_benchmark"), std::string::npos) << bad.err;
}

// --whole-run times every step of the scene's own duration (output.frames x stepsPerFrame: 3 x 2
// here) without warm-up, and compares a target with the mean step, as Table 2 of Shao 2017 averages
TEST(CliBench, WholeRunTimesEveryStepOfTheSceneAgainstTheMean) {
  const Cli cli("bench_whole");
  cli.writeScene("tiny.json", kTinyScene);
  const std::string manifest = cli.writeScene("manifest.json", R"({"benchmarks": [
    {"name": "fast", "scene": "tiny.json", "warmup": 4, "steps": 1, "targetMsPerStep": 100000},
    {"name": "slow", "scene": "tiny.json", "warmup": 4, "steps": 1, "targetMsPerStep": 0.000001}]})");
  const fs::path json = cli.dir() / "bench.json";
  const Result r = cli.run("bench --manifest '" + manifest + "' --whole-run --threads 1 --json '" + json.string() + "'");
  EXPECT_EQ(r.code, 0) << r.err;  // a missed target is reported, not an error
  EXPECT_NE(r.out.find("(mean)"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("steps 6/6"), std::string::npos) << r.err;  // progress of the long runs
  const nlohmann::json doc = nlohmann::json::parse(readTextFile(json.string()));
  ASSERT_EQ(doc["results"].size(), 2u);
  for (const nlohmann::json& res : doc["results"]) {
    ASSERT_FALSE(res.contains("error")) << res.dump();
    EXPECT_TRUE(res["wholeRun"].get<bool>());
    EXPECT_EQ(res["warmup"], 0);  // the manifest's warm-up and steps do not apply
    EXPECT_EQ(res["steps"], 6);
    EXPECT_NEAR(res["simulatedSeconds"].get<double>(), 0.06, 1e-6);
    EXPECT_EQ(res["particles"]["water"], kTinyWater);  // the block fired in the timed steps
    const double mean = res["msPerStepMean"].get<double>();
    EXPECT_GT(mean, 0.0);
    EXPECT_DOUBLE_EQ(res["msPerStepMeanStages"]["total"].get<double>(), mean);
    EXPECT_EQ(res["targets"]["msPerStepBasis"], "mean");
  }
  EXPECT_TRUE(doc["results"][0]["targets"]["msPerStepMet"].get<bool>());
  EXPECT_FALSE(doc["results"][1]["targets"]["msPerStepMet"].get<bool>());
  // a window of steps keeps the median as its basis; --whole-run with --steps or --warmup is refused
  const Result window = cli.run("bench --manifest '" + manifest + "' --scene fast --threads 1 -q --json '" + json.string() + "'");
  ASSERT_EQ(window.code, 0) << window.err;
  const nlohmann::json one = nlohmann::json::parse(readTextFile(json.string()));
  EXPECT_EQ(one["results"][0]["targets"]["msPerStepBasis"], "median");
  EXPECT_EQ(one["results"][0]["steps"], 1);
  EXPECT_FALSE(one["results"][0]["wholeRun"].get<bool>());
  EXPECT_EQ(cli.run("bench --manifest '" + manifest + "' --whole-run --steps 3").code, 1);
  EXPECT_EQ(cli.run("bench --manifest '" + manifest + "' --whole-run --warmup 3").code, 1);
}

}  // namespace
}  // namespace soak
