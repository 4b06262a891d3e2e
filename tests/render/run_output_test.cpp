// a run's output folder read back for the renderer (render/run_output.cpp): the scene, the frames present
// and their times, frame ranges, and each frame's cloth (PLY with saturation or wetness, else OBJ with
// colours) and water; every malformed folder, range or file is an error naming it. No external tools
#include "render/run_output.hpp"

#include <soak/error.hpp>
#include <soak/output.hpp>
#include <soak/scene.hpp>

#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "io/file.hpp"
#include "io/output.hpp"
#include "io/ply.hpp"

namespace soak {
namespace {

namespace fs = std::filesystem;

// a 3 x 3 sheet; frames every 4 steps of 5 ms; water of 5 g with a 3 cm support radius
const char* kScene = R"({
  "solver": {"dt": 0.005},
  "output": {"stepsPerFrame": 4},
  "water": {"particleMass": 0.005, "spacing": 0.015, "supportRadius": 0.03},
  "cloth": [{"name": "sheet", "mesh": {"type": "rectangle", "center": [0, 1, 0], "size": [0.2, 0.2], "resolution": [3, 3]}}]
})";

// an output folder with scene.json and the files of frames 0 and 2 (cloth and water) and 5 (water only),
// stats.jsonl with the times of frames 0 and 2 and a half-written last line
struct RunFolder {
  fs::path dir;
  Scene scene;
  explicit RunFolder(const std::string& name)
      : dir(fs::temp_directory_path() / ("soak_run_output_test_" + name + "_" + std::to_string(::getpid()))),
        scene(loadSceneFromString(kScene, "scene.json", ".")) {
    fs::remove_all(dir);
    fs::create_directories(dir);
    writeTextFile((dir / "scene.json").string(), kScene);
    Particles& p = scene.state.particles;
    for (int k = 0; k < 3; ++k)
      p.add(kWaterPhase, 100 + k, 0.004f + 0.001f * k, 0.02f + 0.005f * k, Vec3(0.1f * k, 2, 0), Vec3::Zero());
    OutputSettings all;
    writeFrameFiles(dir.string(), scene.model, scene.state, all, 0);
    writeFrameFiles(dir.string(), scene.model, scene.state, all, 2);
    OutputSettings water;
    water.clothObj = water.clothPly = false;
    writeFrameFiles(dir.string(), scene.model, scene.state, water, 5);
    writeTextFile((dir / "stats.jsonl").string(),
                  "{\"frame\": 0, \"time\": 0.0}\n{\"frame\": 2, \"time\": 0.0425}\n{\"frame\": 5, \"ti");
    writeTextFile((dir / "notes.txt").string(), "cloth_0009.ply is not a frame of this run\n");
    writeTextFile((dir / "cloth_12.ply").string(), "three digits: not a frame file");
  }
  ~RunFolder() { fs::remove_all(dir); }
  std::string str() const { return dir.string(); }
};

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// the frames are those with a frame file (4 or more digits), ascending; a frame's time is stats.jsonl's,
// else frame x stepsPerFrame x dt
TEST(RenderRunOutput, FramesAndTheirTimes) {
  const RunFolder f("frames");
  const RunOutput run = openRunOutput(f.str());
  EXPECT_EQ(run.frames, (std::vector<int>{0, 2, 5}));
  EXPECT_EQ(run.statsTime.size(), 2u);  // the broken last line is skipped
  EXPECT_DOUBLE_EQ(run.timeOf(2), 0.0425);
  EXPECT_DOUBLE_EQ(run.timeOf(5), 5 * 4 * double(0.005f));  // dt is a float
  EXPECT_DOUBLE_EQ(run.timeOf(7), 7 * 4 * double(0.005f));
  EXPECT_EQ(run.framePath("water", 5, "ply"), (f.dir / "water_0005.ply").string());
  EXPECT_FLOAT_EQ(run.scene.model.water.particleMass, 0.005f);
}

// run.json's framesWritten bounds the frames (a run in progress, or killed between two files, or a
// resume that has not yet replaced a later frame); a run.json without it, or broken, does not
TEST(RenderRunOutput, OnlyTheFramesRunJsonCountsAsWritten) {
  const RunFolder f("counted");
  writeTextFile((f.dir / "run.json").string(), R"({"status": "running", "framesWritten": 3})");
  EXPECT_EQ(openRunOutput(f.str()).frames, (std::vector<int>{0, 2}));
  writeTextFile((f.dir / "run.json").string(), R"({"status": "ok", "framesWritten": 6})");
  EXPECT_EQ(openRunOutput(f.str()).frames, (std::vector<int>{0, 2, 5}));
  writeTextFile((f.dir / "run.json").string(), R"({"status": "running", "frame)");
  EXPECT_EQ(openRunOutput(f.str()).frames, (std::vector<int>{0, 2, 5}));
  writeTextFile((f.dir / "run.json").string(), R"({"status": "running", "framesWritten": 0})");
  EXPECT_NE(errorOf([&] { openRunOutput(f.str()); }).find("no complete frame yet"), std::string::npos);
}

// what is wrong with the folder, in words, with the folder's name
TEST(RenderRunOutput, FolderErrorsSayWhatIsMissing) {
  const RunFolder f("errors");
  const std::string nowhere = (f.dir / "nowhere").string();
  EXPECT_EQ(errorOf([&] { openRunOutput(nowhere); }),
            nowhere + ": no such output folder (make one with `soak run SCENE -o " + nowhere + "`)");
  const std::string file = (f.dir / "notes.txt").string();
  EXPECT_EQ(errorOf([&] { openRunOutput(file); }), file + ": not a folder (expected the output folder of `soak run`)");
  const fs::path empty = f.dir / "empty";
  fs::create_directories(empty);
  EXPECT_EQ(errorOf([&] { openRunOutput(empty.string()); }),
            empty.string() + ": not a soak output folder: scene.json is missing (make one with `soak run SCENE -o " +
                empty.string() + "`)");
  writeTextFile((empty / "scene.json").string(), kScene);
  EXPECT_EQ(errorOf([&] { openRunOutput(empty.string()); }),
            empty.string() + ": no frame files (cloth_NNNN.ply, cloth_NNNN.obj or water_NNNN.ply) in the output folder");
  writeTextFile((empty / "scene.json").string(), "{\"cloth\": 3");
  EXPECT_NE(errorOf([&] { openRunOutput(empty.string()); }).find((empty / "scene.json").string()), std::string::npos);
}

// "A:B" inclusive, "A:" and ":B" open at one end, "A" one frame, "" all; malformed ranges and ranges that
// hold no frame are refused
TEST(RenderRunOutput, FrameRanges) {
  const RunFolder f("ranges");
  const RunOutput run = openRunOutput(f.str());
  EXPECT_EQ(selectFrames(run, ""), (std::vector<int>{0, 2, 5}));
  EXPECT_EQ(selectFrames(run, "2"), (std::vector<int>{2}));
  EXPECT_EQ(selectFrames(run, "1:"), (std::vector<int>{2, 5}));
  EXPECT_EQ(selectFrames(run, ":2"), (std::vector<int>{0, 2}));
  EXPECT_EQ(selectFrames(run, "2:5"), (std::vector<int>{2, 5}));
  EXPECT_EQ(selectFrames(run, ":"), (std::vector<int>{0, 2, 5}));
  for (const char* bad : {"a:b", "-1", "1.5", "2:x", "1:2:3"})
    EXPECT_EQ(errorOf([&] { selectFrames(run, bad); }),
              std::string("--frames: expected A:B, A:, :B or A with frame numbers >= 0 (e.g. 0:100), got '") + bad + "'")
        << bad;
  EXPECT_EQ(errorOf([&] { selectFrames(run, "4:1"); }), "--frames: '4:1' ends before it starts");
  EXPECT_EQ(errorOf([&] { selectFrames(run, "3:4"); }), f.str() + ": no frames in 3:4 (the folder has frames 0..5)");
}

// the cloth of a frame from its PLY: positions, normals, triangles and the saturation attribute (drawn
// against the scene's S^MAX), or the Chen wetness (1 is fully wet); none for a frame without cloth files
TEST(RenderRunOutput, ClothFromThePlyWithSaturationOrWetness) {
  RunFolder f("clothply");
  const Model& m = f.scene.model;
  std::vector<float> s(9);
  for (int i = 0; i < 9; ++i) s[i] = 0.01f * i;
  const PlyFloatAttribute sat[] = {{"saturation", s}};
  writeClothPly((f.dir / "cloth_0002.ply").string(), m, f.scene.state, {}, sat);
  const RunOutput run = openRunOutput(f.str());
  const ClothFrame c = readClothFrame(run, 2);
  ASSERT_EQ(c.x.size(), 9u);
  EXPECT_EQ(c.triangles, m.triangles);
  for (int i = 0; i < 9; ++i) {
    EXPECT_EQ(c.x[i], f.scene.state.particles.x[i]);
    EXPECT_NEAR(c.normal[i].norm(), 1.0f, 1e-6f);
  }
  EXPECT_EQ(c.saturation, s);
  EXPECT_EQ(c.saturationMax, 0.0f);
  const PlyFloatAttribute wet[] = {{"wetness", s}};
  writeClothPly((f.dir / "cloth_0002.ply").string(), m, f.scene.state, {}, wet);
  const ClothFrame w = readClothFrame(run, 2);
  EXPECT_EQ(w.saturation, s);
  EXPECT_EQ(w.saturationMax, 1.0f);
  EXPECT_TRUE(readClothFrame(run, 5).x.empty());
  // a face that uses a vertex the file does not have is named
  writeTextFile((f.dir / "cloth_0002.ply").string(),
                "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  EXPECT_EQ(errorOf([&] { readClothFrame(run, 2); }),
            (f.dir / "cloth_0002.ply").string() + ": face 0 uses vertex 7, but there are 3 vertices");
}

// without a PLY the OBJ: "v x y z r g b" colours (kept only when every vertex has one), quads fanned into
// triangles, negative (relative) indices, normals when there is one per vertex
TEST(RenderRunOutput, ClothFromTheObjWithColoursAndRelativeIndices) {
  RunFolder f("clothobj");
  fs::remove(f.dir / "cloth_0002.ply");
  const std::string obj = (f.dir / "cloth_0002.obj").string();
  writeTextFile(obj, "o sheet\nv 0 0 0 1 0 0\nv 1 0 0 0.5 0 0\nv 1 1 0 0 0 0\nv 0 1 0 0.25 0 0\n"
                     "vn 0 0 1\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nf 1//1 2//2 3//3 4//4\nf -4 -2 -1\n");
  const RunOutput run = openRunOutput(f.str());
  const ClothFrame c = readClothFrame(run, 2);
  ASSERT_EQ(c.x.size(), 4u);
  EXPECT_EQ(c.triangles, (std::vector<std::array<int, 3>>{{0, 1, 2}, {0, 2, 3}, {0, 2, 3}}));
  ASSERT_EQ(c.color.size(), 4u);
  EXPECT_EQ(c.color[1], Vec3(0.5f, 0, 0));
  EXPECT_EQ(c.normal[3], Vec3(0, 0, 1));
  EXPECT_TRUE(c.saturation.empty());
  writeTextFile(obj, "v 0 0 0 1 0 0\nv 1 0 0\nv 1 1 0 0 0 0\nf 1 2 3\n");  // one vertex without a colour
  const ClothFrame plain = readClothFrame(run, 2);
  EXPECT_TRUE(plain.color.empty());
  EXPECT_EQ(plain.normal, std::vector<Vec3>(3, Vec3::Zero()));
}

// each malformed OBJ line is named by the file and its line number
TEST(RenderRunOutput, MalformedObjLinesAreNamed) {
  RunFolder f("badobj");
  fs::remove(f.dir / "cloth_0002.ply");
  const std::string obj = (f.dir / "cloth_0002.obj").string();
  const RunOutput run = openRunOutput(f.str());
  const auto errorWith = [&](const std::string& text) {
    writeTextFile(obj, text);
    return errorOf([&] { readClothFrame(run, 2); });
  };
  const std::string v3 = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  EXPECT_EQ(errorWith("v 0 0\n"), obj + ": at line 1: expected 'v x y z [r g b]'");
  EXPECT_EQ(errorWith(v3 + "vn 0 1\n"), obj + ": at line 4: expected 'vn nx ny nz'");
  EXPECT_EQ(errorWith(v3 + "f 1 2\n"), obj + ": at line 4: a face needs at least 3 vertices");
  EXPECT_EQ(errorWith(v3 + "f 1 2 4\n"), obj + ": at line 4: face vertex 4 does not exist yet");
  EXPECT_EQ(errorWith(v3 + "f 0 1 2\n"), obj + ": at line 4: expected 'f a b c' with 1-based vertex indices, got '0'");
  EXPECT_EQ(errorWith(v3 + "f 1 x 3\n"), obj + ": at line 4: expected 'f a b c' with 1-based vertex indices, got 'x'");
  EXPECT_EQ(errorWith(v3 + "f -4 1 2\n"), obj + ": at line 4: face vertex 0 does not exist yet");
}

// the water of a frame: positions, masses and radii from the PLY; a file without mass or radius takes
// the scene's particle mass and support radius; a frame without water is empty; a short file is named
TEST(RenderRunOutput, WaterFromThePlyWithTheScenesDefaults) {
  RunFolder f("water");
  const RunOutput run = openRunOutput(f.str());
  const WaterFrame w = readWaterFrame(run, 5);
  ASSERT_EQ(w.x.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(w.x[k], Vec3(0.1f * k, 2, 0));
    EXPECT_EQ(w.mass[k], 0.004f + 0.001f * k);
    EXPECT_EQ(w.radius[k], 0.02f + 0.005f * k);
  }
  writeTextFile((f.dir / "water_0005.ply").string(),
                "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
                "end_header\n0 1 2\n3 4 5\n");
  const WaterFrame bare = readWaterFrame(run, 5);
  EXPECT_EQ(bare.x[1], Vec3(3, 4, 5));
  EXPECT_EQ(bare.mass, std::vector<float>(2, 0.005f));
  EXPECT_EQ(bare.radius, std::vector<float>(2, 0.03f));
  EXPECT_TRUE(readWaterFrame(run, 7).x.empty());
  const std::string ply = (f.dir / "water_0002.ply").string();
  fs::resize_file(ply, fs::file_size(ply) - 6);
  EXPECT_NE(errorOf([&] { readWaterFrame(run, 2); }).find(ply + ": "), std::string::npos);
}

}  // namespace
}  // namespace soak
