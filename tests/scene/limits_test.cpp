// hostile scene files (scene/limits.cpp and the bounds of the scene loader): each class of bad input
// ends in an error naming the file, the place and what was expected, before any large allocation or
// long loop
#include "scene/limits.hpp"

#include <gtest/gtest.h>

#include <soak/threads.hpp>

#include "scene/scene_support.hpp"

#include <chrono>
#include <string>

namespace soak {
namespace {

using namespace soak::testing;

TEST(SceneLimits, DeeplyNestedJsonIsRefusedBeforeParsing) {
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  const std::string msg = loadError(deep);
  EXPECT_HAS(msg, "test.json: at line 1, column 65");
  EXPECT_HAS(msg, "expected arrays and objects nested at most 64 deep");
  // brackets inside strings and comments do not count
  EXPECT_NO_THROW(checkJsonText("{\"a\": \"" + std::string(1000, '[') + "\" /* [[[[ */}", "x.json"));
  // nor in an override's value
  const std::string over = errorWith("cloth.0.name=" + std::string(200, '['));
  EXPECT_HAS(over, "override 'cloth.0.name=[[[");
  EXPECT_HAS(over, "nested at most 64 deep");
}

TEST(SceneLimits, NumberBeyondDoubleRangeNamesTheKey) {
  const std::string msg = loadError(R"({"solver": {"dt": 1e400}, "emitters": [{"type": "block"}]})");
  EXPECT_HAS(msg, "test.json: at solver.dt: expected a number within double range");
  EXPECT_HAS(msg, "1e400");
  EXPECT_HAS(loadError(R"({"emitters": [1, 1e999]})"), "at emitters[1]: expected a number within double");
  const std::string over = errorWith("solver.dt=1e400");
  EXPECT_HAS(over, "test.json: at override 'solver.dt=1e400': expected a number within double range");
}

TEST(SceneLimits, OversizedOrEndlessFilesAreReadOnlyUpToTheBound) {
  const auto t0 = std::chrono::steady_clock::now();
  std::string msg;
  try {
    loadScene("/dev/zero");
  } catch (const Error& e) {
    msg = e.what();
  }
  EXPECT_HAS(msg, "/dev/zero: expected a scene file of at most 64 MiB");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 30.0);
  EXPECT_HAS(loadError(std::string(kMaxSceneBytes + 1, ' ')), "test.json: expected a scene of at most 64 MiB");
}

TEST(SceneLimits, SupportRadiusIsBoundedBySpacing) {
  // a spacing of 1e-6 m once made the lattice density sum loop over (2n+1)^3 sites with n = 40000
  const auto t0 = std::chrono::steady_clock::now();
  const std::string msg = errorWith("water.spacing=1e-6");
  EXPECT_HAS(msg, "test.json: at water.supportRadius: expected a number in (water.spacing, 10 x "
                             "water.spacing]");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  EXPECT_EQ(errorWith("water.spacing=0.004"), "");
}

TEST(SceneLimits, LoopCountsAreBounded) {
  for (const std::string key : {"solver.substeps", "solver.fluidIterations", "solver.clothSubsteps",
                                "solver.clothIterations", "solver.couplingIterations", "wetting.diffusion.iterations"}) {
    const std::string msg = errorWith(key + "=2147483647");
    EXPECT_HAS(msg, "test.json: at " + key + ": expected an integer in [") << key;
    EXPECT_HAS(msg, ", 1000], got 2147483647") << key;
  }
  EXPECT_HAS(errorWith("solver.fluidMaxIterations=5000"),
              "at solver.fluidMaxIterations: expected an integer in [4, 1000], got 5000");
  EXPECT_HAS(errorWith("output.stepsPerFrame=1000000"),
              "at output.stepsPerFrame: expected an integer in [1, 100000], got 1000000");
  EXPECT_EQ(errorWith("solver.substeps=1000"), "");
}

TEST(SceneLimits, JetRadiusAndRainRateAreBounded) {
  const std::string jet = R"({"emitters": [{"type": "jet", "origin": [0, 1, 0], "radius": 25}]})";
  EXPECT_HAS(loadError(jet), "test.json: at emitters[0].radius: expected a number <= 1000 x "
                                        "water.spacing = 20 m, got 25");
  const std::string rain = R"({"emitters": [{"type": "rain", "origin": [0, 1, 0], "halfExtents": [1, 1],
                                             "rate": 1e30}]})";
  EXPECT_HAS(loadError(rain), "test.json: at emitters[0].rate: expected at most 1e+09 drops a second");
}

TEST(SceneLimits, HugeClothIsRefusedBeforeItsMeshIsBuilt) {
  // 46340^2 vertices pass a raised maxParticles, but not the memory they would take
  const std::string big = R"({"solver": {"maxParticles": 2147483647},
    "cloth": [{"mesh": {"type": "rectangle", "size": [1, 1], "resolution": [46340, 46340]}}]})";
  const auto t0 = std::chrono::steady_clock::now();
  const std::string msg = loadError(big);
  EXPECT_HAS(msg, "test.json: at cloth[0].mesh.resolution: expected at most");
  EXPECT_HAS(msg, "affords at 2048 bytes a particle");
  EXPECT_HAS(msg, "got 46340 x 46340");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  // an explicit budget names itself
  const std::string budget = loadError(kSmall, {"solver.maxMemoryGB=0.00001"});
  EXPECT_HAS(budget, "at cloth[0].mesh.resolution: expected at most 4 vertices (what solver.maxMemoryGB = "
                                "1e-05 affords at 2048 bytes a particle), got 4 x 3");
}

TEST(SceneLimits, EmittedWaterIsCheckedAgainstTheMemoryBudget) {
  // a 1 m block at 2 mm spacing: 1.25e8 sites, capped at maxParticles (2e6), about 4 GB
  const std::string scene = R"({"water": {"spacing": 0.002, "supportRadius": 0.004},
    "emitters": [{"type": "block", "min": [0, 0, 0], "max": [1, 1, 1]}]})";
  const std::string msg = loadError(scene, {"solver.maxMemoryGB=1"});
  EXPECT_HAS(msg, "test.json: at emitters: expected at most 488281 particles in all (what "
                             "solver.maxMemoryGB = 1 affords at 2048 bytes a particle), got up to 2000000");
  EXPECT_HAS(msg, "lower solver.maxParticles");
  // the budget raised, or the cap lowered: the scene loads (blocks are emitted by the first step)
  EXPECT_EQ(loadError(scene, {"solver.maxMemoryGB=5"}), "");
  EXPECT_EQ(loadError(scene, {"solver.maxMemoryGB=1", "solver.maxParticles=400000"}), "");
  // an endless jet is counted over the scene's own frames only
  const std::string jet = R"({"emitters": [{"type": "jet", "origin": [0, 1, 0]}], "output": {"frames": 10}})";
  EXPECT_EQ(loadError(jet, {"solver.maxMemoryGB=0.01"}), "");
}

TEST(SceneLimits, NamesArePrintableAscii) {
  EXPECT_HAS(loadError(kSmall, {"cloth.0.name=a\nv 0 0 0"}),
              "test.json: at cloth[0].name: expected a name of 1 to 256 printable ASCII characters (no "
                        "newline, tab or other control character), got a control character (byte 0x0a) at "
                        "position 1");
  EXPECT_HAS(loadError(kSmall, {"emitters.0.name=x\ty"}),
              "at emitters[0].name: expected a name of 1 to 256 printable ASCII characters");
  EXPECT_HAS(loadError(kSmall, {"name=scene\n#system"}), "at name: expected a name of 1 to 256");
  EXPECT_HAS(loadError(kSmall, {"cloth.0.name="}), "at cloth[0].name: expected a name of 1 to 256 "
                                                               "printable ASCII characters (no newline, tab or other "
                                                               "control character), got an empty name");
  const std::string collider = R"({"colliders": [{"type": "sphere", "name": "ball\r", "position": [0, -5, 0]}],
    "emitters": [{"type": "block", "min": [0, 0, 0], "max": [0.1, 0.1, 0.1]}]})";
  EXPECT_HAS(loadError(collider), "at colliders[0].name: expected a name of 1 to 256 printable ASCII "
                                             "characters (no newline, tab or other control character), got a "
                                             "control character (byte 0x0d) at position 4");
  EXPECT_HAS(loadError(kSmall, {"cloth.0.name=caf\xc3\xa9"}), "a non-ASCII byte (0xc3) at position 3");
  EXPECT_EQ(loadError(kSmall, {"cloth.0.name=sheet #1 (front)"}), "");
}

TEST(SceneLimits, ThreadCountIsBounded) {
  try {
    setThreadCount(100000);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_HAS(std::string(e.what()), "threads: expected at most 1024 worker threads, got 100000");
  }
}

}  // namespace
}  // namespace soak
