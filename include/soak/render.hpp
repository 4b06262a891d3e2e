// soak's renderer, a library of its own (soak_render; the engine does not link it): a run's output
// folder -> PNG frames (POV-Ray) -> an MP4 (ffmpeg), and the water surface of a run's frames as
// meshes and level sets (OpenVDB). docs/rendering.md
#pragma once
#include <soak/math.hpp>
#include <soak/scene.hpp>

#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace soak {

struct SurfaceSettings {
  // voxel edge (m); 0: a sixth of the median support radius h (a third of the Table 1 spacing)
  float voxelSize = 0.0f;
  // ball radius of a particle as a fraction of its support radius h_i: h/2 is the spacing r0 at
  // Table 1 values, so the balls of neighbours overlap and a block has no holes
  float radiusFraction = 0.5f;
  // distance the smoothed surface is moved inwards, as a fraction of the median h. The union of
  // balls of radius r0 reaches r0 past the outer particles (less in the dimples between them); a
  // lattice block's cells end r0/2 past them. 3/16 h was calibrated so resting blocks of 6^3 to
  // 24^3 particles enclose their lattice volume to within 5% (tests/render/surface_test.cpp)
  float erosionFraction = 0.1875f;
  // a particle whose centre ends up outside the smoothed, eroded surface or less than a quarter of
  // a drop radius inside it (a drip, a splash: the smoothing removes lone balls) is added back as a ball of
  // this fraction of its h; 5/16 h is the
  // radius of the sphere holding a Table 1 particle's volume (m / rho0)
  float dropFraction = 0.3125f;
  // Gaussian smoothing passes (width 1 voxel) of the level set before the erosion
  int smoothingIterations = 1;
  // narrow band half width in voxels
  float halfWidth = 3.0f;
};

struct CameraSpec {
  Vec3 position{0, 1, 3};
  Vec3 lookAt{0, 0, 0};
  float fovDegrees = 40.0f;  // horizontal
};

// what the user asked for; what is not given is chosen so that `bounds` fills the picture
struct CameraRequest {
  std::optional<Vec3> position, lookAt;
  float fovDegrees = 40.0f;        // horizontal field of view
  float azimuthDegrees = 35.0f;    // direction to the camera around y, from +z towards +x
  float elevationDegrees = 25.0f;  // above the horizontal
  float zoom = 1.0f;               // the automatic distance is divided by this
};

enum class WaterStyle { Surface, Particles };


struct RenderOptions {
  std::string runDir;             // the folder `soak run` wrote
  std::string outDir;             // "": runDir/render
  int width = 640, height = 480;  // pixels
  std::string frames;             // "A:B" (see selectFrames); "": every frame
  WaterStyle water = WaterStyle::Surface;
  std::string ramp;  // saturation ramp "red" (Fig. 3) or "green" (Fig. 4); "": the scene's
                     // output.colorRamp when it is one of them, else red
  int jobs = 0;      // frames rendered at once; 0: one per core
  CameraRequest camera;
  double fps = 0.0;               // video frame rate; 0: real time, 1 / (stepsPerFrame dt)
  bool video = true;              // make OUT/movie.mp4
  bool floor = true;              // a floor under everything when the scene has no plane collider
  double timeoutSeconds = 300.0;  // per POV-Ray frame (and for ffmpeg); past it the tool is killed
  float antialias = 0.3f;         // POV-Ray +A threshold; 0: no anti-aliasing
  bool keepPov = false;           // keep the .pov scene files and logs in OUT/pov
  SurfaceSettings surface;        // water surface (WaterStyle::Surface)
};

struct RenderResult {
  std::string outDir;
  std::vector<int> frames;          // rendered, ascending
  std::vector<std::string> images;  // OUT/frame_NNNN.png, one per frame
  std::string video;                // OUT/movie.mp4, or "" without video
  CameraSpec camera;                // the camera used for every frame
  int jobs = 1;
  double fps = 0.0;
  std::string ramp;  // the ramp used
};

// checks the options, the folder and the tools (povray, ffmpeg when video is on), then renders
// every selected frame in parallel and encodes the video. progress(done, total) is called after each
// frame (from the calling thread's workers, one call at a time). Throws soak::Error with a clear
// message: a missing or broken folder, a missing tool with the Debian package to install, a POV-Ray
// failure or timeout with the end of its log.
RenderResult renderRun(const RenderOptions& options, const std::function<void(int, int)>& progress = {});

// `soak surface`: the water surface of every selected frame written as OUT/water_surface_NNNN.obj,
// .ply and .vdb (as enabled)
struct SurfaceOptions {
  std::string runDir;
  std::string outDir;  // "": runDir
  std::string frames;  // "A:B"; "": every frame
  SurfaceSettings settings;
  bool obj = true, ply = false, vdb = true;
};

struct SurfaceResult {
  std::string outDir;
  std::vector<int> frames;
  std::vector<std::string> files;
  float voxelSize = 0.0f;  // m, of the last frame with water
};

// progress(done, total) after each frame. Throws soak::Error for a missing or broken folder or a
// file that cannot be written.
SurfaceResult surfaceRun(const SurfaceOptions& options, const std::function<void(int, int)>& progress = {});

// the picture size of a PNG file from its IHDR chunk; throws soak::Error when it is not a PNG
std::pair<int, int> pngSize(const std::string& path);

// the view settings of the scene a run folder was written from (DIR/scene.json); throws soak::Error
// as renderRun does for a missing or broken folder
ViewSettings runView(const std::string& runDir);

// one picture of a contact sheet: a PNG ("" for a blank tile) and the lines of text under it
struct ContactTile {
  std::string image;
  std::vector<std::string> caption;
};

// writes the tiles as one PNG, `columns` to a row, each with its caption under it in black on
// white (ffmpeg: pad, drawtext, xstack). Every image must have the size width x height. Throws
// soak::Error: ffmpeg missing (with the Debian package), an image of another size, ffmpeg failing
// (with the end of its log).
void writeContactSheet(const std::vector<ContactTile>& tiles, int columns, int width, int height,
                       const std::string& outPng, double timeoutSeconds = 300.0);

}  // namespace soak
