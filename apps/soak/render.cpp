// `soak render`, `soak surface` and `soak export-body`: options, a progress bar and a summary around src/render/
#include <soak/render.hpp>

#include <fmt/format.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <soak/error.hpp>
#include <sstream>

#include "commands.hpp"
#include "progress.hpp"

namespace soak::cli {

namespace {

// "X,Y,Z" -> a point; CLI11 check: "" when valid
std::string checkPoint(const std::string& s) {
  std::istringstream in(s);
  float v[3];
  char c1 = 0, c2 = 0;
  if (!(in >> v[0] >> c1 >> v[1] >> c2 >> v[2]) || c1 != ',' || c2 != ',' || !(in >> std::ws).eof())
    return "expected X,Y,Z in metres (e.g. 1.5,1.2,2.0), got '" + s + "'";
  return {};
}

std::optional<Vec3> parsePoint(const std::string& s) {
  if (s.empty()) return std::nullopt;
  std::istringstream in(s);
  float x, y, z;
  char c;
  in >> x >> c >> y >> c >> z;
  return Vec3(x, y, z);
}

std::string frameSpan(const std::vector<int>& frames) {
  return frames.size() == 1 ? fmt::format("frame {}", frames.front())
                            : fmt::format("frames {}..{}", frames.front(), frames.back());
}

}  // namespace

CLI::App* addRenderCommand(CLI::App& app, RenderCliOptions& o) {
  CLI::App* cmd = app.add_subcommand("render", "render a run's frames to PNG and MP4 with POV-Ray and ffmpeg");
  cmd->add_option("dir", o.options.runDir, "output folder of `soak run`")->required();
  cmd->add_option("-o,--out", o.options.outDir, "where the pictures go (default: DIR/render)");
  cmd->add_option("--width", o.options.width, "picture width in pixels (default 640)")->check(CLI::Range(2, 16384));
  cmd->add_option("--height", o.options.height, "picture height in pixels (default 480)")->check(CLI::Range(2, 16384));
  cmd->add_option("--frames", o.options.frames, "frames A:B (inclusive; A:, :B, A; default: all)");
  CLI::Option* surface = cmd->add_flag("--surface", o.surface, "water as its OpenVDB surface (the default)");
  CLI::Option* particles = cmd->add_flag("--particles", o.particles, "water as one sphere per particle");
  surface->excludes(particles);
  cmd->add_option("--ramp", o.options.ramp, "saturation colours: red (Fig. 3) or green (Fig. 4); default: the scene's")
      ->check(CLI::IsMember({"red", "green"}));
  cmd->add_option("--jobs", o.options.jobs, "frames rendered at once (default: one per core)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--camera", o.camera, "camera position X,Y,Z in metres (default: framed automatically)")
      ->check(checkPoint);
  cmd->add_option("--look-at", o.lookAt, "point the camera looks at, X,Y,Z (default: the centre of everything)")
      ->check(checkPoint);
  o.fovOpt = cmd->add_option("--fov", o.options.camera.fovDegrees, "horizontal field of view in degrees (default 40)");
  o.azimuthOpt = cmd->add_option("--azimuth", o.options.camera.azimuthDegrees,
                  "automatic camera: direction around y, degrees from +z towards +x (default 35)");
  o.elevationOpt = cmd->add_option("--elevation", o.options.camera.elevationDegrees,
                  "automatic camera: degrees above the horizontal (default 25)")
      ->check(CLI::Range(-89.0, 89.0));
  o.zoomOpt = cmd->add_option("--zoom", o.options.camera.zoom, "automatic camera: move closer by this factor (default 1)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--fps", o.options.fps, "video frame rate (default: real time, 1 / (stepsPerFrame dt))")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("!--no-video", o.options.video, "PNG frames only, no movie.mp4");
  cmd->add_flag("!--no-floor", o.options.floor, "no floor under a scene without a plane collider");
  cmd->add_option("--voxel", o.options.surface.voxelSize, "water surface voxel size in m (default: h/6)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--antialias", o.options.antialias, "POV-Ray anti-aliasing threshold, 0 = off (default 0.3)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--timeout", o.options.timeoutSeconds, "seconds allowed per frame (and for ffmpeg; default 300)")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--keep-pov", o.options.keepPov, "keep the POV-Ray scene files and logs in OUT/pov");
  cmd->add_flag("-q,--quiet", o.quiet, "no progress and no summary");
  return cmd;
}

CLI::App* addSurfaceCommand(CLI::App& app, SurfaceCliOptions& o) {
  CLI::App* cmd = app.add_subcommand("surface", "mesh the water of a run's frames (OpenVDB): OBJ, PLY, VDB");
  cmd->add_option("dir", o.options.runDir, "output folder of `soak run`")->required();
  cmd->add_option("-o,--out", o.options.outDir, "where the surfaces go (default: DIR)");
  cmd->add_option("--frames", o.options.frames, "frames A:B (inclusive; A:, :B, A; default: all)");
  cmd->add_option("--voxel", o.options.settings.voxelSize, "voxel size in m (default: h/6)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--radius", o.options.settings.radiusFraction,
                  "ball radius per particle, fraction of h (default 0.5)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--erosion", o.options.settings.erosionFraction,
                  "inward offset after smoothing, fraction of h (default 0.1875)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--smooth", o.options.settings.smoothingIterations, "Gaussian smoothing passes (default 1)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--ply", o.options.ply, "also write water_surface_NNNN.ply");
  cmd->add_flag("!--no-obj", o.options.obj, "no water_surface_NNNN.obj");
  cmd->add_flag("!--no-vdb", o.options.vdb, "no water_surface_NNNN.vdb");
  cmd->add_flag("-q,--quiet", o.quiet, "no progress and no summary");
  return cmd;
}

CLI::App* addExportBodyCommand(CLI::App& app, ExportBodyCliOptions& o) {
  BodyExportOptions& b = o.options;
  CLI::App* cmd = app.add_subcommand("export-body", "write a scene's mannequin, moving, as an OBJ sequence of one topology");
  cmd->add_option("scene", b.scene, "scene file (JSON) with a mannequin collider")->required();
  cmd->add_option("-o,--out", b.outDir, "folder for body_NNNN.obj")->required();
  cmd->add_option("--collider", b.collider, "the mannequin's name (default: the scene's first)");
  cmd->add_option("--frames", b.frames, "frames to write (default: the scene's output.frames + 1, its frames 0 .. N)")
      ->check(CLI::Range(1, 100000));
  cmd->add_option("--fps", b.fps, "frames per second (default: the scene's, 1 / (stepsPerFrame dt))")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--cell", b.cellSize, "cell size of the grid the skin is meshed on, m (default 0.01)")
      ->check(CLI::Range(0.001, 1.0));
  cmd->add_option("--set", b.overrides, "override a scene value, key=value (repeatable)")->allow_extra_args(false)->take_all();
  cmd->add_flag("--overwrite", b.overwrite, "replace a sequence already in the folder");
  cmd->add_flag("-q,--quiet", o.quiet, "no progress and no summary");
  return cmd;
}

int exportBodyCommand(const ExportBodyCliOptions& o) {
  Progress bar(0, !o.quiet);
  const BodyExport res = exportBody(o.options, [&bar](int done, int total) { bar.updateItems("frame", done, total); });
  bar.finish();
  if (!o.quiet) {
    std::printf("soak: wrote %d frames of %zu vertices, %zu triangles as %s in %s\n", res.frames, res.vertices,
                res.triangles, res.pattern.c_str(), Progress::formatDuration(bar.seconds()).c_str());
    std::printf("soak: as a collider: {\"type\": \"meshSequence\", \"path\": \"%s\", \"fps\": %.6g}\n",
                res.pattern.c_str(), res.fps);
  }
  return kExitOk;
}

int renderCommand(RenderCliOptions& o) {
  RenderOptions& r = o.options;
  if (o.particles) r.water = WaterStyle::Particles;
  if (o.surface) r.water = WaterStyle::Surface;
  r.camera.position = parsePoint(o.camera);
  r.camera.lookAt = parsePoint(o.lookAt);
  {  // the scene's "view" fills what the command line left out
    const ViewSettings view = runView(r.runDir);
    const auto given = [](const CLI::Option* opt) { return opt && opt->count() > 0; };
    if (!r.camera.position && view.camera) r.camera.position = view.camera;
    if (!r.camera.lookAt && view.lookAt) r.camera.lookAt = view.lookAt;
    if (!given(o.fovOpt) && view.fov) r.camera.fovDegrees = *view.fov;
    if (!given(o.azimuthOpt) && view.azimuth) r.camera.azimuthDegrees = *view.azimuth;
    if (!given(o.elevationOpt) && view.elevation) r.camera.elevationDegrees = *view.elevation;
    if (!given(o.zoomOpt) && view.zoom) r.camera.zoom = *view.zoom;
  }
  Progress bar(0, !o.quiet);
  const RenderResult res = renderRun(r, [&bar](int done, int total) { bar.updateItems("frame", done, total); });
  bar.finish();
  if (!o.quiet) {
    std::printf("soak: rendered %s to %s (frame_NNNN.png, %d x %d, %s water, %s ramp) in %s with %d jobs\n",
                frameSpan(res.frames).c_str(), res.outDir.c_str(), r.width, r.height,
                r.water == WaterStyle::Surface ? "surface" : "particle", res.ramp.c_str(),
                Progress::formatDuration(bar.seconds()).c_str(), res.jobs);
    std::printf("soak: camera at %.3f,%.3f,%.3f looking at %.3f,%.3f,%.3f, field of view %.1f degrees\n",
                res.camera.position.x(), res.camera.position.y(), res.camera.position.z(), res.camera.lookAt.x(),
                res.camera.lookAt.y(), res.camera.lookAt.z(), res.camera.fovDegrees);
    if (!res.video.empty())
      std::printf("soak: video %s (%zu frames at %.4g fps)\n", res.video.c_str(), res.images.size(), res.fps);
  }
  return kExitOk;
}

int surfaceCommand(SurfaceCliOptions& o) {
  Progress bar(0, !o.quiet);
  const SurfaceResult res =
      surfaceRun(o.options, [&bar](int done, int total) { bar.updateItems("frame", done, total); });
  bar.finish();
  if (!o.quiet) {
    std::string kinds;
    for (const auto& [ext, on] : {std::pair{"obj", o.options.obj}, {"ply", o.options.ply}, {"vdb", o.options.vdb}})
      if (on) kinds += std::string(kinds.empty() ? "water_surface_NNNN." : ", .") + ext;
    std::printf("soak: wrote the water surface of %s to %s (%s), voxel %.4g m, in %s\n", frameSpan(res.frames).c_str(),
                res.outDir.c_str(), kinds.c_str(), res.voxelSize, Progress::formatDuration(bar.seconds()).c_str());
  }
  return kExitOk;
}

}  // namespace soak::cli
