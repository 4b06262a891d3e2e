// soak render and soak surface end to end (the soak binary, POV-Ray, ffmpeg): pictures of the requested
// size, saturation colours, clear errors, no hang (the POV-Ray scene text and the camera: pov_test.cpp)
#include <soak/render.hpp>

#include "render/pov.hpp"
#include "render/run_output.hpp"
#include "render/surface.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <soak/error.hpp>
#include <soak/scene.hpp>

#include "io/file.hpp"
#include "io/ply.hpp"
#include "render/pov.hpp"
#include "render/process.hpp"
#include "render/run_output.hpp"
#include "render/render_support.hpp"
#include "world/colliders.hpp"

namespace soak {
namespace {

using soak::testing::kTinyScene;

namespace fs = std::filesystem;

// a wet cloth alone, for pictures of known saturation
constexpr const char* kClothScene = R"({
  "name": "cloth_only",
  "solver": {"dt": 0.01, "gravity": [0, 0, 0]},
  "output": {"frames": 1, "stepsPerFrame": 1, "water": false},
  "wetting": {},
  "cloth": [{"name": "sheet", "mesh": {"type": "rectangle", "center": [0, 0.5, 0], "size": [0.4, 0.4],
             "resolution": [8, 8], "axisU": [1, 0, 0], "axisV": [0, 0, 1]}}]
})";

struct Result {
  int code = -1;
  std::string out, err;
  double seconds = 0.0;
};

class Folder {
 public:
  explicit Folder(const std::string& name)
      : dir_(fs::temp_directory_path() / ("soak_render_test_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  ~Folder() { fs::remove_all(dir_); }
  fs::path operator/(const std::string& p) const { return dir_ / p; }
  std::string str() const { return dir_.string(); }

  // runs `env` SOAK_BINARY args under a 60 s guard (`timeout`), so a hang fails instead of blocking
  Result soak(const std::string& args, const std::string& env = "") const {
    const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string cmd = env + " /usr/bin/timeout -k 5 60 '" + SOAK_BINARY + "' " + args + " < /dev/null > '" +
                            out.string() + "' 2> '" + err.string() + "'";
    const auto t0 = std::chrono::steady_clock::now();
    const int status = std::system(cmd.c_str());
    Result r;
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = readTextFile(out.string());
    r.err = readTextFile(err.string());
    return r;
  }

  // a run of the tiny scene into DIR/run
  std::string tinyRun() const {
    writeTextFile((dir_ / "tiny.json").string(), kTinyScene);
    const Result r = soak("run '" + (dir_ / "tiny.json").string() + "' -o '" + (dir_ / "run").string() + "' -q");
    EXPECT_EQ(r.code, 0) << r.err;
    return (dir_ / "run").string();
  }

 private:
  fs::path dir_;
};

// the RGB (0..255) of pixel (x, y) of a PNG, decoded by ffmpeg to raw rgb24
std::array<int, 3> pixel(const std::string& png, int x, int y, const Folder& tmp) {
  const auto [w, h] = pngSize(png);
  const std::string raw = (tmp / "pixels.rgb").string();
  const std::string cmd =
      "ffmpeg -nostdin -loglevel error -y -i '" + png + "' -f rawvideo -pix_fmt rgb24 '" + raw + "' < /dev/null";
  EXPECT_EQ(std::system(cmd.c_str()), 0);
  const std::string bytes = readTextFile(raw);
  EXPECT_EQ(bytes.size(), size_t(3 * w * h));
  const size_t at = 3 * (size_t(y) * size_t(w) + size_t(x));
  return {static_cast<unsigned char>(bytes[at]), static_cast<unsigned char>(bytes[at + 1]),
          static_cast<unsigned char>(bytes[at + 2])};
}

TEST(RenderRun, TinySceneGivesPngsOfTheRequestedSizeAndAVideo) {
  const Folder tmp("tiny");
  const std::string run = tmp.tinyRun();
  const std::string out = (tmp / "pictures").string();
  const Result r = tmp.soak("render '" + run + "' -o '" + out + "' --width 96 --height 64 --jobs 2");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_LT(r.seconds, 30.0);
  for (int f = 0; f <= 3; ++f) {
    const std::string png = (fs::path(out) / frameFileName("frame", f, "png")).string();
    ASSERT_TRUE(fs::exists(png)) << png;
    EXPECT_GT(fs::file_size(png), 500u);
    EXPECT_EQ(pngSize(png), std::make_pair(96, 64));
  }
  EXPECT_GT(fs::file_size(fs::path(out) / "movie.mp4"), 500u);
  EXPECT_FALSE(fs::exists(fs::path(out) / "pov"));  // the scene files are removed without --keep-pov
  EXPECT_NE(r.out.find("rendered frames 0..3"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("movie.mp4 (4 frames at 50 fps)"), std::string::npos) << r.out;  // 1 / (2 * 0.01 s)
}

TEST(RenderRun, OddSizesAndParticlesAndAFrameRange) {
  const Folder tmp("odd");
  const std::string run = tmp.tinyRun();
  const std::string out = (tmp / "odd").string();
  const Result r =
      tmp.soak("render '" + run + "' -o '" + out + "' --width 51 --height 37 --particles --frames 2:3 --keep-pov -q");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(r.out.empty());
  EXPECT_FALSE(fs::exists(fs::path(out) / "frame_0001.png"));
  EXPECT_EQ(pngSize((fs::path(out) / "frame_0002.png").string()), std::make_pair(51, 37));
  EXPECT_EQ(pngSize((fs::path(out) / "frame_0003.png").string()), std::make_pair(51, 37));
  // libx264 / yuv420p needs even sizes: the video is padded, not refused
  EXPECT_GT(fs::file_size(fs::path(out) / "movie.mp4"), 200u);
  // particles: one sphere per water particle (64), no surface mesh
  const std::string pov = readTextFile((fs::path(out) / "pov" / "frame_0003.pov").string());
  const size_t water = pov.find("// water particles");
  ASSERT_NE(water, std::string::npos);
  size_t spheres = 0;
  for (size_t at = pov.find("sphere { <", water); at != std::string::npos; at = pov.find("sphere { <", at + 1))
    ++spheres;
  EXPECT_EQ(spheres, 64u);
  EXPECT_EQ(pov.find("WaterSurface }"), std::string::npos);
}

TEST(RenderRun, ClothColourFollowsSaturation) {
  // three frames of the same flat cloth: dry (S = 0), half (S^MAX / 2) and full (S = S^MAX)
  const Folder tmp("ramp");
  const fs::path dir = tmp / "run";
  fs::create_directories(dir);
  writeTextFile((dir / "scene.json").string(), kClothScene);
  Scene scene = loadSceneFromString(kClothScene, "scene.json", tmp.str());
  const float sMax = scene.model.wetting.saturationMax;
  for (int f = 0; f < 3; ++f) {
    const std::vector<float> s(size_t(scene.model.numCloth), 0.5f * float(f) * sMax);
    const PlyFloatAttribute sat{"saturation", s};
    writeClothPly((dir / frameFileName("cloth", f, "ply")).string(), scene.model, scene.state, {}, {&sat, 1});
  }
  for (const char* ramp : {"red", "green"}) {
    const std::string out = (tmp / ramp).string();
    const Result r =
        tmp.soak("render '" + dir.string() + "' -o '" + out + "' --ramp " + ramp +
                 " --width 40 --height 30 --camera 0,1.4,0.3 --look-at 0,0.5,0 --fov 20 --no-video --no-floor -q");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto dry = pixel(out + "/frame_0000.png", 20, 15, tmp);
    const auto half = pixel(out + "/frame_0001.png", 20, 15, tmp);
    const auto wet = pixel(out + "/frame_0002.png", 20, 15, tmp);
    const int c = std::string(ramp) == "red" ? 0 : 1;  // the channel of the dry colour
    EXPECT_GT(dry[c], 120) << ramp;
    EXPECT_GT(dry[c], 2 * dry[1 - c] + 20) << ramp;
    EXPECT_GT(dry[c], 2 * dry[2] + 20) << ramp;
    EXPECT_LT(wet[c], dry[c] / 3) << ramp;  // red/green -> black (Fig. 3, Fig. 4)
    // the ramp is linear in S / S^MAX in display values: half way is about half as bright
    EXPECT_NEAR(half[c], 0.5 * dry[c], 0.15 * dry[c]) << ramp;
  }
}

TEST(RenderRun, MissingOrBrokenFolderIsAClearError) {
  const Folder tmp("broken");
  Result r = tmp.soak("render '" + (tmp / "nowhere").string() + "'");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("nowhere: no such output folder"), std::string::npos) << r.err;

  fs::create_directories(tmp / "empty");
  r = tmp.soak("render '" + (tmp / "empty").string() + "'");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("not a soak output folder: scene.json is missing"), std::string::npos) << r.err;

  fs::create_directories(tmp / "noframes");
  writeTextFile((tmp / "noframes" / "scene.json").string(), kClothScene);
  r = tmp.soak("render '" + (tmp / "noframes").string() + "'");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("no frame files"), std::string::npos) << r.err;

  fs::create_directories(tmp / "badscene");
  writeTextFile((tmp / "badscene" / "scene.json").string(), "{\"cloth\": 3");
  r = tmp.soak("render '" + (tmp / "badscene").string() + "'");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("scene.json"), std::string::npos) << r.err;

  // a truncated frame file is named, and nothing is rendered
  const std::string run = tmp.tinyRun();
  const std::string ply = (fs::path(run) / "water_0002.ply").string();
  fs::resize_file(ply, fs::file_size(ply) / 2);
  r = tmp.soak("render '" + run + "' -o '" + (tmp / "pics").string() + "' --width 32 --height 24");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("water_0002.ply"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(tmp / "pics" / "frame_0000.png"));

  r = tmp.soak("render '" + run + "' --frames 5:9");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("no frames in 5:9 (the folder has frames 0..3)"), std::string::npos) << r.err;
}

TEST(RenderRun, MissingToolsNameTheDebianPackage) {
  const Folder tmp("tools");
  const std::string run = tmp.tinyRun();
  Result r = tmp.soak("render '" + run + "'", "PATH=");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("povray was not found on PATH: install the Debian package povray"), std::string::npos) << r.err;

  // povray present, ffmpeg not
  fs::create_directories(tmp / "bin");
  fs::create_symlink(findExecutable("povray"), tmp / "bin" / "povray");
  r = tmp.soak("render '" + run + "'", "PATH='" + (tmp / "bin").string() + "'");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("ffmpeg was not found on PATH: install the Debian package ffmpeg"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--no-video"), std::string::npos) << r.err;
}

TEST(RenderRun, AStuckOrFailingPovrayNeverHangs) {
  const Folder tmp("hang");
  const std::string run = tmp.tinyRun();
  fs::create_directories(tmp / "bin");
  const std::string stuck = (tmp / "bin" / "povray").string();
  writeTextFile(stuck, "#!/bin/sh\nexec sleep 50\n");
  fs::permissions(stuck, fs::perms::owner_all);
  const std::string path = "PATH='" + (tmp / "bin").string() + ":/usr/bin:/bin'";
  const Result r = tmp.soak("render '" + run + "' -o '" + (tmp / "a").string() + "' --timeout 1 --no-video", path);
  EXPECT_EQ(r.code, 1);
  EXPECT_LT(r.seconds, 15.0);
  EXPECT_NE(r.err.find("povray did not finish frame"), std::string::npos) << r.err;
}

// a tool that reads its input gets end of file at once (stdin is /dev/null); its failure carries the
// end of its log
TEST(RenderRun, FailingPovrayReportsItsLog) {
  const Folder tmp("fail");
  const std::string run = tmp.tinyRun();
  fs::create_directories(tmp / "bin");
  const std::string fake = (tmp / "bin" / "povray").string();
  writeTextFile(fake, "#!/bin/sh\ncat > /dev/null\necho 'Parse Error: fake povray' >&2\nexit 3\n");
  fs::permissions(fake, fs::perms::owner_all);
  const Result r = tmp.soak("render '" + run + "' -o '" + (tmp / "b").string() + "' --timeout 20 --no-video",
                            "PATH='" + (tmp / "bin").string() + ":/usr/bin:/bin'");
  EXPECT_EQ(r.code, 1);
  EXPECT_LT(r.seconds, 15.0);
  EXPECT_NE(r.err.find("povray failed on frame"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("exit code 3"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("Parse Error: fake povray"), std::string::npos) << r.err;
}

TEST(SurfaceRun, WritesObjPlyAndVdbPerFrame) {
  const Folder tmp("surface");
  const std::string run = tmp.tinyRun();
  const std::string out = (tmp / "surf").string();
  const Result r = tmp.soak("surface '" + run + "' -o '" + out + "' --frames 1:2 --ply");
  ASSERT_EQ(r.code, 0) << r.err;
  for (int f : {1, 2}) {
    const fs::path obj = fs::path(out) / frameFileName("water_surface", f, "obj");
    ASSERT_TRUE(fs::exists(obj));
    const PlyData ply = readPly((fs::path(out) / frameFileName("water_surface", f, "ply")).string());
    EXPECT_GT(ply.element("face").count, 100u);
    const VdbSummary vdb = readLevelSetVdb((fs::path(out) / frameFileName("water_surface", f, "vdb")).string());
    EXPECT_TRUE(vdb.levelSet);
    EXPECT_EQ(vdb.frame, f);
    EXPECT_NEAR(vdb.time, 0.02 * f, 1e-9);
    EXPECT_NEAR(vdb.voxelSize, 0.04f / 6.0f, 1e-6f);  // h / 6 at the default supportRadius
  }
  EXPECT_FALSE(fs::exists(fs::path(out) / "water_surface_0000.obj"));
  EXPECT_NE(r.out.find("wrote the water surface of frames 1..2"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace soak
