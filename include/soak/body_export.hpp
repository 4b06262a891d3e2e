// a scene's mannequin as an OBJ sequence (`soak export-body`, soak_render): the skin meshed once and
// skinned through the scene's motion, one OBJ per frame of one topology, as a character
// animation is exported from Blender, Houdini or Maya. It takes the mannequin into other tools, and
// gives the "meshSequence" collider a body to play (docs/mannequin.md, "Animated bodies")
#pragma once
#include <soak/math.hpp>
#include <soak/model.hpp>

#include <functional>
#include <string>
#include <vector>

namespace soak {

struct TriangleMesh;

// the skin of the Body collider `body` at each of `times` (s), one topology: meshed (OpenVDB) on a
// grid of cellSize m at times[0]'s pose, each vertex then moved by linear blend skinning (each part's
// rigid motion since times[0], weighted by the part's share of the smooth union at the vertex's rest
// position, bodyPartWeights) and put back on that frame's skin by kSkinProjections steps along the
// normal. Throws soak::Error when `body` is not a Body, the grid would be too large or the meshed
// skin is not a closed surface
constexpr int kSkinProjections = 8;
std::vector<TriangleMesh> skinnedBodyFrames(const Collider& body, const std::vector<double>& times, float cellSize);

struct BodyExportOptions {
  std::string scene;
  std::vector<std::string> overrides;  // --set key=value, as `soak run`
  std::string collider;                // a Body collider's name; empty: the scene's first
  std::string outDir;
  int frames = -1;                     // -1: the scene's output.frames + 1 (its frames 0 .. N)
  double fps = 0.0;                    // 0: the scene's frame rate, 1 / (stepsPerFrame dt)
  float cellSize = 0.01f;              // m
  bool overwrite = false;              // replace body_*.obj already in outDir
};

struct BodyExport {
  std::string pattern;     // outDir/body_####.obj (the run of '#' as wide as the frame numbers)
  int frames = 0;          // numbered 1 .. frames
  double fps = 0.0;
  size_t vertices = 0, triangles = 0;
};

// writes the frames of the scene's body; `progress(done, total)` after each file. Throws soak::Error
// naming the scene, the collider or the file
BodyExport exportBody(const BodyExportOptions& o, const std::function<void(int, int)>& progress = {});

}  // namespace soak
