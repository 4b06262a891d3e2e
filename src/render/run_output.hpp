// reading back the output folder of `soak run` (docs/output-format.md) for the renderer and the
// surface command: the scene as run, the frames present, and each frame's cloth and water
#pragma once
#include <array>
#include <map>
#include <soak/math.hpp>
#include <soak/scene.hpp>
#include <string>
#include <vector>

namespace soak {

struct RunOutput {
  std::string dir;
  Scene scene;                      // DIR/scene.json, loaded and validated
  std::vector<int> frames;          // frame numbers with at least one frame file that run.json counts
                                    // as written (all of them without a run.json), ascending
  std::map<int, double> statsTime;  // s, the "time" of each stats.jsonl line (when present)

  // simulated time of a frame: stats.jsonl's, else frame * stepsPerFrame * dt
  double timeOf(int frame) const;
  // DIR/prefix_NNNN.ext
  std::string framePath(const std::string& prefix, int frame, const std::string& ext) const;
};

// opens a run's output folder. Throws soak::Error when the folder is missing, is not a soak output
// folder (no scene.json), its scene.json does not load, or it holds no frame files.
RunOutput openRunOutput(const std::string& dir);

// the frames of `run` within "A:B" (inclusive; "A:" or ":B" leave an end open; "A" is one frame;
// empty is every frame). Throws soak::Error for a malformed range or one that selects no frame.
std::vector<int> selectFrames(const RunOutput& run, const std::string& range);

// the cloth of a frame: from cloth_NNNN.ply (with its "saturation" attribute when present, else its
// "wetness" in [0, 1] from the Chen 2012 saturation mass), else
// from cloth_NNNN.obj (with its vertex colours when present); empty when the frame has no cloth file
struct ClothFrame {
  std::vector<Vec3> x;                        // m
  std::vector<Vec3> normal;                   // unit, one per vertex (zero when the file had none)
  std::vector<std::array<int, 3>> triangles;  // 0-based
  std::vector<float> saturation;              // S_i (Eq. 10) per vertex, empty when absent
  float saturationMax = 0.0f;                 // the value drawn fully wet; 0: the scene's S^MAX
  std::vector<Vec3> color;                    // 0..1 per vertex from the OBJ, empty when absent
};

struct WaterFrame {
  std::vector<Vec3> x;        // m
  std::vector<float> mass;    // kg
  std::vector<float> radius;  // m, support radius h
};

// throw soak::Error naming the file when a file is malformed
ClothFrame readClothFrame(const RunOutput& run, int frame);
WaterFrame readWaterFrame(const RunOutput& run, int frame);

}  // namespace soak
