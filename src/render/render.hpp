// `soak render`: a run's output folder -> PNG frames (POV-Ray) -> an MP4 (ffmpeg). docs/rendering.md
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "render/pov.hpp"
#include "render/surface.hpp"

namespace soak {

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

}  // namespace soak
