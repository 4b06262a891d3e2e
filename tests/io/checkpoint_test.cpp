// checkpoints (io/checkpoint.cpp): a state written and read back continues exactly as the unbroken run
// (a fresh Workspace, so nothing the step needs lives outside the State), and every damaged or
// foreign file is refused with an error naming it and what is wrong
#include <soak/checkpoint.hpp>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <soak/error.hpp>

#include "io/io_support.hpp"
#include "support/run_scene.hpp"

#include <cstring>
#include <string>

namespace soak {
namespace {

using namespace soak::testing;

CheckpointInfo infoAt(int frame, int steps) {
  CheckpointInfo info{"test-version", 0x1234abcdull, frame, steps, FrameStats{}};
  info.frameSoFar.steps = steps;
  info.frameSoFar.fluidIterations = 77;
  return info;
}

// expects `f` to throw a soak::Error whose message holds every one of `parts`
template <class F>
void expectError(F&& f, std::initializer_list<std::string> parts) {
  try {
    f();
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    for (const std::string& p : parts) EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what();
  }
}

struct Case {
  const char* scene;
  std::vector<std::string> overrides;
  int before, after;  // steps before the checkpoint and after it
};

// the unbroken run against a run that stops, writes its checkpoint, and continues from the file with
// a new Workspace: the same state hash. The scenes cover drips hanging from a pre-wetted cloth and
// let go (Fig. 6, 2 drips at step 3, 80 at step 4; again with the global stretch step, whose system a
// resumed run factors anew from the dry masses while the cloth is wet), a jet on a wetting cloth that starts absorbing
// (Fig. 1, steps 9-12), the water's sort (every 10 steps) and an implicit garment in the rain with
// its wet start times and its warm-started solve's last velocity changes (Chen Fig. 8); the cloths
// coarser than shipped, to keep the test short
TEST(Checkpoint, AResumedRunEqualsTheUnbrokenOne) {
  const fs::path dir = tempDir("checkpoint_resume");
  for (const Case& c : {Case{"scenes/fig6a_drip_uniform.json", {"cloth.0.mesh.resolution=[80,80]"}, 3, 4},
                        Case{"scenes/fig6a_drip_uniform.json",
                             {"cloth.0.mesh.resolution=[80,80]", "solver.clothGlobalStretch=true", "solver.clothSubsteps=4"}, 3, 4},
                        Case{"scenes/fig1_jet.json", {"cloth.0.mesh.resolution=[40,40]"}, 9, 3},
                        Case{"scenes/chen_fig8_silk_sphere_wet.json", {"cloth.0.garment.cg.warmStart=true"}, 4, 4}}) {
    SCOPED_TRACE(c.scene);
    Scene unbroken = sceneFromFile(c.scene, c.overrides);
    WorkspacePtr ws = makeWorkspace();
    StepStats st;
    for (int s = 0; s < c.before; ++s) step(unbroken.model, unbroken.state, *ws, unbroken.model.solver.dt, st);
    const std::string path = (dir / "checkpoint.soak").string();
    writeCheckpoint(path, infoAt(3, 1), unbroken.state);
    for (int s = 0; s < c.after; ++s) step(unbroken.model, unbroken.state, *ws, unbroken.model.solver.dt, st);

    Scene resumed = sceneFromFile(c.scene, c.overrides);
    const Checkpoint cp = readCheckpoint(path);
    checkCheckpointFits(path, cp, resumed.model);
    resumed.state = cp.state;
    EXPECT_EQ(resumed.state.stepCount, static_cast<uint64_t>(c.before));
    runSteps(resumed, c.after);
    EXPECT_EQ(stateHash(resumed.state), stateHash(unbroken.state));
    EXPECT_GT(cp.state.particles.size(), static_cast<size_t>(resumed.model.numCloth)) << "no water: a weak case";
    EXPECT_NE(cp.state.particles.size(), resumed.state.particles.size()) << "no water came or went after it: a weak case";
  }
}

TEST(Checkpoint, TheHeaderComesBackAsWritten) {
  const fs::path dir = tempDir("checkpoint_header");
  Scene scene = sceneFromFile("scenes/fig6a_drip_uniform.json");
  runSteps(scene, 2);
  const std::string path = (dir / "c.soak").string();
  writeCheckpoint(path, infoAt(12, 3), scene.state);
  EXPECT_FALSE(fs::exists(path + ".part"));
  const Checkpoint c = readCheckpoint(path);
  EXPECT_EQ(c.info.soakVersion, "test-version");
  EXPECT_EQ(c.info.sceneHash, 0x1234abcdull);
  EXPECT_EQ(c.info.frame, 12);
  EXPECT_EQ(c.info.stepsIntoFrame, 3);
  EXPECT_EQ(c.info.frameSoFar.steps, 3);
  EXPECT_EQ(c.info.frameSoFar.fluidIterations, 77u);
  EXPECT_EQ(stateHash(c.state), stateHash(scene.state));
}

TEST(Checkpoint, DamagedOrForeignFilesAreRefusedNamingTheFile) {
  const fs::path dir = tempDir("checkpoint_damaged");
  Scene scene = sceneFromFile("scenes/fig6a_drip_uniform.json");
  runSteps(scene, 1);
  const std::string good = (dir / "good.soak").string();
  writeCheckpoint(good, infoAt(0, 1), scene.state);
  const std::string bytes = readTextFile(good);
  const auto variant = [&](const std::string& name, const std::string& content) {
    const std::string p = (dir / name).string();
    writeTextFile(p, content);
    return p;
  };
  const std::string missing = (dir / "none.soak").string();
  expectError([&] { readCheckpoint(missing); }, {missing, "no checkpoint"});
  expectError([&] { readCheckpoint(dir.string()); }, {dir.string(), "not a regular file"});
  const std::string json = variant("scene.json", "{\"name\": \"not a checkpoint\"}");
  expectError([&] { readCheckpoint(json); }, {json, "not a soak checkpoint"});
  std::string other = bytes;
  other[8] = 99;  // the format number follows the 8-byte magic
  const std::string format = variant("format.soak", other);
  expectError([&] { readCheckpoint(format); }, {format, "format 99", fmt::format("format {}", kCheckpointFormat)});
  const std::string cut = variant("cut.soak", bytes.substr(0, bytes.size() / 2));
  expectError([&] { readCheckpoint(cut); }, {cut, "truncated"});
  std::string flipped = bytes;
  flipped[bytes.size() - 100] ^= 0x40;  // inside the last arrays: read fine, hashes differently
  const std::string corrupt = variant("flipped.soak", flipped);
  expectError([&] { readCheckpoint(corrupt); }, {corrupt, "corrupt checkpoint"});
  const std::string longer = variant("longer.soak", bytes + "x");
  expectError([&] { readCheckpoint(longer); }, {longer, "no end mark"});
}

// a count larger than the file is refused before anything is allocated
TEST(Checkpoint, AnArrayLongerThanTheFileIsRefusedBeforeAllocating) {
  const fs::path dir = tempDir("checkpoint_huge");
  Scene scene = sceneFromFile("scenes/fig6a_drip_uniform.json");
  const std::string good = (dir / "good.soak").string();
  writeCheckpoint(good, infoAt(0, 0), scene.state);
  std::string bytes = readTextFile(good);
  // the first array (phase) follows the fixed header, the frame statistics and 4 scalars
  const size_t phaseCount = 8 + 4 + 4 + 8 + std::string("test-version").size() + 8 + 4 + 4 + 8 + sizeof(FrameStats) +
                            8 + 8 + 4 + 4;
  uint64_t n = 0;
  std::memcpy(&n, bytes.data() + phaseCount, sizeof n);
  ASSERT_EQ(n, scene.state.particles.size());
  const uint64_t huge = uint64_t{1} << 60;
  std::memcpy(bytes.data() + phaseCount, &huge, sizeof huge);
  const std::string path = (dir / "huge.soak").string();
  writeTextFile(path, bytes);
  expectError([&] { readCheckpoint(path); }, {path, "phase claims 1152921504606846976 elements", "more than the"});
}

TEST(Checkpoint, AStateOfAnotherSceneDoesNotFit) {
  const fs::path dir = tempDir("checkpoint_fit");
  Scene a = sceneFromFile("scenes/fig6a_drip_uniform.json");
  const std::string path = (dir / "a.soak").string();
  writeCheckpoint(path, infoAt(0, 0), a.state);
  const Checkpoint c = readCheckpoint(path);
  EXPECT_NO_THROW(checkCheckpointFits(path, c, a.model));
  const Scene b = sceneFromFile("scenes/fig3a_cube_on_cloth.json");
  expectError([&] { checkCheckpointFits(path, c, b.model); }, {path, "does not belong to this scene"});
  const Scene chen = sceneFromFile("scenes/chen_fig8_silk_sphere_wet.json");
  expectError([&] { checkCheckpointFits(path, c, chen.model); }, {path, "does not belong to this scene"});
  // a Chen piece keeps its held water, saturation, wet times and the implicit solve's velocity
  // changes: a state without them does not fit
  const std::string chenPath = (dir / "chen.soak").string();
  writeCheckpoint(chenPath, infoAt(0, 0), chen.state);
  Checkpoint cc = readCheckpoint(chenPath);
  EXPECT_NO_THROW(checkCheckpointFits(chenPath, cc, chen.model));
  cc.state.clothWater.clear();
  cc.state.clothBuffer.clear();
  cc.state.clothSaturation.clear();
  expectError([&] { checkCheckpointFits(chenPath, cc, chen.model); }, {chenPath, "wetting arrays of 0 entries, expected 2601"});
  cc = readCheckpoint(chenPath);
  cc.state.clothWetStart.clear();
  expectError([&] { checkCheckpointFits(chenPath, cc, chen.model); }, {chenPath, "0 wet start times, expected 2601"});
  cc = readCheckpoint(chenPath);
  cc.state.clothVelocityChange.pop_back();
  expectError([&] { checkCheckpointFits(chenPath, cc, chen.model); },
              {chenPath, "2600 implicit velocity changes, expected 2601"});
}

}  // namespace
}  // namespace soak
