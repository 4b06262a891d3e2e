// the scene as a run writes it (sceneAsRun, src/scene/as_run.cpp): overrides applied, relative mesh
// paths made absolute, and the result loads to the same scene from another folder
#include <soak/error.hpp>
#include <soak/scene.hpp>
#include <soak/step.hpp>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;
using namespace soak;

TEST(SceneAsRun, OverridesAppliedAndMeshPathsMadeAbsolute) {
  const fs::path dir = fs::temp_directory_path() / ("soak_as_run_" + std::to_string(::getpid()));
  fs::create_directories(dir / "meshes");
  std::ofstream(dir / "meshes" / "tri.obj") << "v 0 1 0\nv 0.1 1 0\nv 0 1 0.1\nv 0.1 1 0.1\nf 1 2 3\nf 2 4 3\n";
  std::ofstream(dir / "scene.json") << R"({"solver": {"substeps": 2},
    "cloth": [{"mesh": {"type": "obj", "path": "meshes/tri.obj"}}]})";
  const std::string text = sceneAsRun((dir / "scene.json").string(), {"solver.substeps=3"});
  const nlohmann::json doc = nlohmann::json::parse(text);
  EXPECT_EQ(doc["solver"]["substeps"], 3);
  const fs::path mesh = doc["cloth"][0]["mesh"]["path"].get<std::string>();
  EXPECT_TRUE(mesh.is_absolute()) << mesh;
  EXPECT_TRUE(fs::equivalent(mesh, dir / "meshes" / "tri.obj"));
  // written elsewhere, it is the same scene
  const fs::path other = dir / "elsewhere";
  fs::create_directories(other);
  std::ofstream(other / "scene.json") << text;
  const Scene a = loadScene((dir / "scene.json").string(), {"solver.substeps=3"});
  const Scene b = loadScene((other / "scene.json").string());
  EXPECT_EQ(b.model.solver.substeps, 3);
  EXPECT_EQ(stateHash(a.state), stateHash(b.state));
  EXPECT_THROW(sceneAsRun((dir / "missing.json").string()), Error);
  fs::remove_all(dir);
}

// a mesh sequence's file pattern is made absolute too (render and resume read the run's scene.json)
TEST(SceneAsRun, AMeshSequencePatternIsMadeAbsolute) {
  const fs::path dir = fs::temp_directory_path() / ("soak_as_run_seq_" + std::to_string(::getpid()));
  fs::create_directories(dir / "frames");
  std::ofstream(dir / "scene.json") << R"({"colliders": [{"type": "meshSequence", "path": "frames/body_####.obj",
    "fps": 30}], "cloth": []})";
  const nlohmann::json doc = nlohmann::json::parse(sceneAsRun((dir / "scene.json").string()));
  EXPECT_EQ(doc["colliders"][0]["path"].get<std::string>(), (dir / "frames" / "body_####.obj").string());
  fs::remove_all(dir);
}
