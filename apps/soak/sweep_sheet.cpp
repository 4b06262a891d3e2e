// soak sweep's contact sheet: each variant's chosen frame rendered by soak render with one camera,
// labelled with its values, in one PNG (docs/sweeps.md)
#include "sweep_summary.hpp"

#include <soak/error.hpp>
#include <soak/render.hpp>
#include <soak/run_summary.hpp>

#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>

namespace soak::cli {

namespace {

namespace fs = std::filesystem;

// the scene's view (as soak render takes it) for the first picture; the camera it chose for the rest
CameraRequest firstCamera(const std::string& runDir) {
  CameraRequest c;
  const ViewSettings view = runView(runDir);
  c.position = view.camera;
  c.lookAt = view.lookAt;
  if (view.fov) c.fovDegrees = *view.fov;
  if (view.azimuth) c.azimuthDegrees = *view.azimuth;
  if (view.elevation) c.elevationDegrees = *view.elevation;
  if (view.zoom) c.zoom = *view.zoom;
  return c;
}

}  // namespace

std::string writeSweepSheet(const SweepSpec& spec, const std::string& dir, bool quiet) {
  const SweepSheet& sh = spec.sheet;
  std::vector<ContactTile> tiles;
  std::optional<CameraRequest> camera;
  for (const SweepVariant& v : spec.variants) {
    const std::string runDir = (fs::path(dir) / v.folder).string();
    ContactTile tile;
    tile.caption.push_back(v.folder);
    for (const std::string& o : v.overrides()) tile.caption.push_back(o);
    const RunSummary s = runStatus(runDir);
    const int last = s.framesWritten - 1;
    const int frame = sh.frame >= 0 ? sh.frame : last;
    const bool complete = runComplete(s, spec.frames);
    if (!complete || frame > last) {
      const std::string why = !complete ? (s.status == "ok" ? "fewer frames" : s.status) : "no such frame";
      tile.caption.front() += fmt::format(" ({}: not drawn)", why);
      tiles.push_back(tile);
      continue;
    }
    RenderOptions r;
    r.runDir = runDir;
    r.outDir = (fs::path(runDir) / "sheet").string();
    r.width = sh.width;
    r.height = sh.height;
    r.frames = fmt::format("{}:{}", frame, frame);
    r.water = sh.particles ? WaterStyle::Particles : WaterStyle::Surface;
    r.video = false;
    r.camera = camera ? *camera : firstCamera(runDir);
    const RenderResult res = renderRun(r);
    if (!camera) camera = CameraRequest{res.camera.position, res.camera.lookAt, res.camera.fovDegrees};
    tile.image = res.images.front();
    tile.caption.front() += fmt::format(" (frame {})", frame);
    tiles.push_back(tile);
    if (!quiet) std::printf("soak sweep: drew %s\n", v.folder.c_str());
  }
  const int columns = sh.columns > 0 ? sh.columns : int(std::ceil(std::sqrt(double(tiles.size()))));
  const std::string out = (fs::path(dir) / "contact_sheet.png").string();
  writeContactSheet(tiles, columns, sh.width, sh.height, out);
  return out;
}

}  // namespace soak::cli
