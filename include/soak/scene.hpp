// scene files: JSON, SI units, every key validated before anything runs (docs/scene-format.md)
#pragma once
#include <soak/model.hpp>
#include <soak/state.hpp>

#include <optional>
#include <string>
#include <vector>

namespace soak {

struct OutputSettings {
  int frames = 100;          // frames to simulate and write
  int stepsPerFrame = 2;     // steps of solver.dt between two written frames
  bool clothObj = true;      // cloth_NNNN.obj
  bool clothPly = true;      // cloth_NNNN.ply (per-vertex attributes)
  bool water = true;         // water_NNNN.ply (binary particles)
  std::string colorRamp = "red";  // cloth OBJ vertex colours by saturation: "red" (Fig. 3), "green" (Fig. 4), "none"
};

// how `soak render` looks at the scene's runs ("view"); an absent value is chosen automatically or
// taken from the command line, which wins over the scene (docs/rendering.md)
struct ViewSettings {
  std::optional<Vec3> camera, lookAt;  // m
  std::optional<float> fov;            // deg, horizontal
  std::optional<float> azimuth;        // deg around +y from +z towards +x (automatic camera)
  std::optional<float> elevation;      // deg above the horizontal (automatic camera)
  std::optional<float> zoom;           // automatic camera distance divided by this
};

struct Scene {
  std::string path;          // file it came from ("<string>" when parsed from memory)
  std::string name;
  std::string description;
  Model model;
  State state;               // initial state (cloth particles placed, blocks not yet emitted)
  OutputSettings output;
  ViewSettings view;
};

// loads and validates a scene file. overrides are "json.path=value" strings applied before
// validation (value parsed as JSON, else taken as a string), e.g. "solver.substeps=3" or
// "cloth.0.material.thickness=0.02". Throws soak::Error naming the file, the JSON path and what was
// expected.
Scene loadScene(const std::string& path, const std::vector<std::string>& overrides = {});

// the scene file's JSON text as a run uses it: the overrides applied and relative file paths made
// absolute against the scene's folder, so it runs from anywhere (soak run's scene.json). Throws
// soak::Error as loadScene does for an unreadable file or a bad override
std::string sceneAsRun(const std::string& path, const std::vector<std::string>& overrides = {});

// the water particles the model's block emitters will create
size_t blockParticleCount(const Model& model);

// the same from JSON text; relative mesh paths resolve against baseDir
Scene loadSceneFromString(const std::string& text, const std::string& sourceName, const std::string& baseDir,
                          const std::vector<std::string>& overrides = {});

}  // namespace soak
