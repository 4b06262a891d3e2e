// rendering a run: frame bounds -> one camera -> a .pov per frame -> POV-Ray in parallel -> ffmpeg
#include <soak/render.hpp>

#include <fmt/format.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <soak/error.hpp>
#include <thread>

#include "io/file.hpp"
#include "render/pov.hpp"
#include "render/run_output.hpp"
#include "render/surface.hpp"
#include "render/process.hpp"
#include "world/colliders.hpp"
#include "world/mesh_sequence.hpp"

namespace soak {

namespace {

// a mesh sequence's surface at its pose, in the world frame (its normals from the faces, pov.cpp)
SurfaceMesh sequenceSurface(const MeshSnapshot& mesh, const ColliderPose& pose) {
  const TriangleMesh local = mesh.surface();
  SurfaceMesh m;
  m.vertices.reserve(local.vertices.size());
  for (const Vec3& x : local.vertices) m.vertices.push_back(pose.rotation * x + pose.translation);
  m.triangles = local.triangles;
  return m;
}

namespace fs = std::filesystem;

void checkOptions(const RenderOptions& o) {
  if (o.width < 2 || o.height < 2 || o.width > 16384 || o.height > 16384)
    throw Error(fmt::format("--width/--height: expected 2..16384 pixels, got {} x {}", o.width, o.height));
  if (!o.ramp.empty() && o.ramp != "red" && o.ramp != "green")
    throw Error("--ramp: expected red or green, got '" + o.ramp + "'");
  if (o.jobs < 0) throw Error(fmt::format("--jobs: expected 0 (one per core) or more, got {}", o.jobs));
  if (!(o.fps >= 0.0)) throw Error(fmt::format("--fps: expected a rate > 0 (or 0 for real time), got {}", o.fps));
  if (!(o.timeoutSeconds > 0.0)) throw Error(fmt::format("--timeout: expected seconds > 0, got {}", o.timeoutSeconds));
  if (!(o.antialias >= 0.0f)) throw Error(fmt::format("--antialias: expected a threshold >= 0, got {}", o.antialias));
  if (!(o.camera.zoom > 0.0f)) throw Error(fmt::format("--zoom: expected a factor > 0, got {}", o.camera.zoom));
  if (!(o.camera.fovDegrees > 1.0f && o.camera.fovDegrees < 179.0f))
    throw Error(fmt::format("--fov: expected 1..179 degrees, got {}", o.camera.fovDegrees));
  if (o.camera.position && o.camera.lookAt && (*o.camera.position - *o.camera.lookAt).norm() < 1e-6f)
    throw Error("--camera and --look-at are the same point");
}

std::vector<ColliderPose> posesAt(const Model& model, double t) {
  std::vector<ColliderPose> poses;
  for (const Collider& c : model.colliders) poses.push_back(colliderPose(c, t));
  return poses;
}

// radius of the sphere holding a particle's water (m / rho0)
float dropRadius(float mass, float restDensity) {
  return std::cbrt(3.0f * std::max(mass, 0.0f) / (4.0f * kPi * restDensity));
}

// everything that appears in any selected frame, so one camera shows the whole sequence
CameraFit fitSequence(const RunOutput& run, const std::vector<int>& frames, const RenderOptions& o) {
  CameraFit fit(o.camera, o.width, o.height);
  const Model& model = run.scene.model;
  for (int f : frames) {
    for (const Vec3& p : readClothFrame(run, f).x) fit.add(p);
    const WaterFrame w = readWaterFrame(run, f);
    for (size_t i = 0; i < w.x.size(); ++i) fit.add(w.x[i], dropRadius(w.mass[i], model.water.restDensity));
    const std::vector<ColliderPose> poses = posesAt(model, run.timeOf(f));
    for (size_t k = 0; k < model.colliders.size(); ++k) fit.add(colliderBounds(model.colliders[k], poses[k]));
  }
  return fit;
}

struct FrameJob {
  const RunOutput* run = nullptr;
  const RenderOptions* options = nullptr;
  std::string povray, workDir, outDir;
  CameraSpec camera;
  std::optional<float> floorY;
  float checker = 0.1f;
  int povThreads = 1;
  std::string ramp;
  std::vector<SurfaceMesh> colliderMeshes;  // per collider (empty for non-mesh shapes)
};

// the colliders' surfaces at a frame's poses: a mesh's, meshed once (`fixed`); a Body's skin, meshed
// at its pose with kBodyCells cells along its longest side; a mesh sequence's triangles at that time.
// `posed` holds the ones made for this frame
std::vector<const SurfaceMesh*> frameColliderMeshes(const Model& model, const std::vector<ColliderPose>& poses,
                                                    const std::vector<SurfaceMesh>& fixed,
                                                    std::vector<SurfaceMesh>& posed) {
  constexpr float kBodyCells = 300.0f;
  std::vector<const SurfaceMesh*> meshes;
  for (const SurfaceMesh& m : fixed) meshes.push_back(&m);
  posed.assign(meshes.size(), SurfaceMesh{});
  for (size_t k = 0; k < model.colliders.size() && k < meshes.size() && k < poses.size(); ++k) {
    const Collider& c = model.colliders[k];
    if (c.shape == ColliderShape::MeshSequence && poses[k].mesh) {
      posed[k] = sequenceSurface(*poses[k].mesh, poses[k]);
    } else if (c.shape == ColliderShape::Body) {
      const Bounds box = colliderBounds(c, poses[k]);
      if (box.empty()) continue;
      posed[k] = colliderSurfaceMesh(c, poses[k], box.lo, box.hi, (box.hi - box.lo).maxCoeff() / kBodyCells);
    } else {
      continue;
    }
    meshes[k] = &posed[k];
  }
  return meshes;
}

// renders one frame into OUT/frame_NNNN.png; throws soak::Error on failure
std::string renderFrame(const FrameJob& job, int frame) {
  const RunOutput& run = *job.run;
  const RenderOptions& o = *job.options;
  const Model& model = run.scene.model;
  const ClothFrame cloth = readClothFrame(run, frame);
  const WaterFrame water = readWaterFrame(run, frame);

  PovFrameInput in;
  in.model = &model;
  in.poses = posesAt(model, run.timeOf(frame));
  std::vector<SurfaceMesh> posed;
  in.colliderMesh = frameColliderMeshes(model, in.poses, job.colliderMeshes, posed);
  in.cloth = &cloth;
  in.clothColor = clothColors(cloth, job.ramp, cloth.saturationMax > 0.0f ? cloth.saturationMax
                                                                          : model.wetting.saturationMax);
  in.water = o.water;
  SurfaceMesh surface;
  if (o.water == WaterStyle::Surface && !water.x.empty()) {
    surface = levelSetMesh(waterLevelSet(water.x, water.radius, o.surface));
    in.surface = &surface;
  }
  if (o.water == WaterStyle::Particles) {
    in.dropCentre = water.x;
    for (float m : water.mass) in.dropRadius.push_back(dropRadius(m, model.water.restDensity));
  }
  in.camera = job.camera;
  in.width = o.width;
  in.height = o.height;
  in.floorY = job.floorY;
  in.checker = job.checker;
  in.title = fmt::format("{} frame {} t = {:.4f} s", run.scene.name, frame, run.timeOf(frame));

  const std::string pov = frameFileName("frame", frame, "pov");
  const std::string png = frameFileName("frame", frame, "png");
  const std::string log = frameFileName("frame", frame, "log");
  writeTextFile((fs::path(job.workDir) / pov).string(), povScene(in));
  std::error_code ec;
  fs::remove(fs::path(job.workDir) / log, ec);
  std::vector<std::string> args = {
      job.povray, "+I" + pov, "+O" + png, fmt::format("+W{}", o.width),        fmt::format("+H{}", o.height), "+FN",
      "-D",       "-P",       "-V",       fmt::format("+WT{}", job.povThreads)};
  if (o.antialias > 0.0f) args.push_back(fmt::format("+A{:.3g}", o.antialias));
  const ProcessResult r = runProcess(args, job.workDir, (fs::path(job.workDir) / log).string(), o.timeoutSeconds);
  const std::string where = (fs::path(job.workDir) / pov).string();
  if (r.timedOut)
    throw Error(
        fmt::format("povray did not finish frame {} within {} s and was stopped (raise --timeout, or lower "
                    "--width/--height); its scene is {}",
                    frame, o.timeoutSeconds, where));
  const fs::path made = fs::path(job.workDir) / png;
  if (!r.ok() || !fs::exists(made, ec))
    throw Error(fmt::format("povray failed on frame {} ({}); its scene is {}; the end of its log:\n{}", frame,
                            r.describe(), where, tailOfFile((fs::path(job.workDir) / log).string(), 12)));
  const fs::path target = fs::path(job.outDir) / png;
  fs::rename(made, target, ec);
  if (ec) {
    // another file system: copy instead
    fs::copy_file(made, target, fs::copy_options::overwrite_existing, ec);
    if (ec) throw Error(target.string() + ": cannot write the frame: " + ec.message());
    fs::remove(made, ec);
  }
  if (!o.keepPov) {
    fs::remove(fs::path(job.workDir) / pov, ec);
    fs::remove(fs::path(job.workDir) / log, ec);
  }
  return target.string();
}

std::string encodeVideo(const std::string& ffmpeg, const RenderResult& res, const std::string& workDir,
                        double timeout) {
  // numbered links 0..N-1 to the frames, so a sequence with gaps (or not starting at 0) encodes
  const fs::path seq = fs::path(workDir) / "video";
  std::error_code ec;
  fs::remove_all(seq, ec);
  fs::create_directories(seq, ec);
  for (size_t i = 0; i < res.images.size(); ++i) {
    fs::create_symlink(fs::absolute(res.images[i]), seq / fmt::format("v_{:06d}.png", i), ec);
    if (ec) throw Error((seq / fmt::format("v_{:06d}.png", i)).string() + ": cannot link the frame: " + ec.message());
  }
  const std::string video = (fs::path(res.outDir) / "movie.mp4").string();
  const std::string log = (fs::path(workDir) / "ffmpeg.log").string();
  fs::remove(log, ec);
  // libx264 with yuv420p needs even sizes: pad by one pixel when odd
  const std::vector<std::string> args = {ffmpeg,
                                         "-nostdin",
                                         "-y",
                                         "-loglevel",
                                         "error",
                                         "-framerate",
                                         fmt::format("{:.6g}", res.fps),
                                         "-i",
                                         (seq / "v_%06d.png").string(),
                                         "-c:v",
                                         "libx264",
                                         "-pix_fmt",
                                         "yuv420p",
                                         "-vf",
                                         "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                                         "-movflags",
                                         "+faststart",
                                         fs::absolute(video).string()};
  const ProcessResult r = runProcess(args, "", log, timeout);
  fs::remove_all(seq, ec);
  if (r.timedOut) throw Error(fmt::format("ffmpeg did not finish the video within {} s and was stopped", timeout));
  if (!r.ok()) throw Error(fmt::format("ffmpeg failed ({}): {}", r.describe(), tailOfFile(log, 12)));
  fs::remove(log, ec);
  return video;
}

}  // namespace

SurfaceResult surfaceRun(const SurfaceOptions& o, const std::function<void(int, int)>& progress) {
  if (!o.obj && !o.ply && !o.vdb) throw Error("soak surface: nothing to write (--no-obj and --no-vdb without --ply)");
  const RunOutput run = openRunOutput(o.runDir);
  SurfaceResult res;
  res.frames = selectFrames(run, o.frames);
  res.outDir = o.outDir.empty() ? o.runDir : o.outDir;
  std::error_code ec;
  fs::create_directories(res.outDir, ec);
  if (!fs::is_directory(res.outDir, ec)) throw Error(res.outDir + ": cannot create the output folder");
  int done = 0;
  for (int f : res.frames) {
    const WaterFrame w = readWaterFrame(run, f);
    const WaterLevelSet ls = waterLevelSet(w.x, w.radius, o.settings);
    if (!w.x.empty()) res.voxelSize = ls.voxelSize();
    const fs::path base = fs::path(res.outDir);
    if (o.obj || o.ply) {
      const SurfaceMesh mesh = levelSetMesh(ls);
      if (o.obj) {
        res.files.push_back((base / frameFileName("water_surface", f, "obj")).string());
        writeSurfaceObj(res.files.back(), mesh);
      }
      if (o.ply) {
        res.files.push_back((base / frameFileName("water_surface", f, "ply")).string());
        writeSurfacePly(res.files.back(), mesh);
      }
    }
    if (o.vdb) {
      res.files.push_back((base / frameFileName("water_surface", f, "vdb")).string());
      writeLevelSetVdb(res.files.back(), ls, f, run.timeOf(f));
    }
    if (progress) progress(++done, static_cast<int>(res.frames.size()));
  }
  return res;
}

std::pair<int, int> pngSize(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char h[24] = {};
  if (!in.read(reinterpret_cast<char*>(h), sizeof h)) throw Error(path + ": too short for a PNG file");
  static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (!std::equal(sig, sig + 8, h) || std::string(reinterpret_cast<char*>(h + 12), 4) != "IHDR")
    throw Error(path + ": not a PNG file (no PNG signature and IHDR chunk)");
  auto be = [&](int at) { return int(h[at]) << 24 | int(h[at + 1]) << 16 | int(h[at + 2]) << 8 | int(h[at + 3]); };
  return {be(16), be(20)};
}

RenderResult renderRun(const RenderOptions& o, const std::function<void(int, int)>& progress) {
  checkOptions(o);
  const RunOutput run = openRunOutput(o.runDir);
  const std::vector<int> frames = selectFrames(run, o.frames);
  FrameJob job;
  job.povray = requireExecutable("povray", "povray");
  const std::string ffmpeg = o.video ? requireExecutable("ffmpeg", "ffmpeg", "or pass --no-video") : "";

  RenderResult res;
  res.outDir = o.outDir.empty() ? (fs::path(o.runDir) / "render").string() : o.outDir;
  res.frames = frames;
  std::error_code ec;
  fs::create_directories(res.outDir, ec);
  if (!fs::is_directory(res.outDir, ec)) throw Error(res.outDir + ": cannot create the render folder");
  job.outDir = res.outDir;
  job.workDir = (fs::path(res.outDir) / "pov").string();
  fs::create_directories(job.workDir, ec);
  if (ec) throw Error(job.workDir + ": cannot create the folder: " + ec.message());

  const Model& model = run.scene.model;
  const CameraFit fit = fitSequence(run, frames, o);
  const Bounds& bounds = fit.bounds();
  res.camera = fit.camera();
  job.run = &run;
  job.options = &o;
  const std::string& sceneRamp = run.scene.output.colorRamp;
  job.ramp = !o.ramp.empty() ? o.ramp : (sceneRamp == "green" ? "green" : "red");
  res.ramp = job.ramp;
  job.camera = res.camera;
  const bool hasPlane = std::any_of(model.colliders.begin(), model.colliders.end(),
                                    [](const Collider& c) { return c.shape == ColliderShape::Plane; });
  const float size = bounds.empty() ? 1.0f : (bounds.hi - bounds.lo).maxCoeff();
  if (o.floor && !hasPlane) job.floorY = (bounds.empty() ? 0.0f : bounds.lo.y()) - 0.01f * size;
  job.checker = std::pow(10.0f, std::round(std::log10(std::max(size, 1e-3f) / 10.0f)));
  for (const Collider& c : model.colliders)
    job.colliderMeshes.push_back(c.shape == ColliderShape::Mesh && c.sdf ? sdfGridMesh(*c.sdf) : SurfaceMesh{});

  const int cores = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  res.jobs = std::clamp(o.jobs > 0 ? o.jobs : cores, 1, static_cast<int>(frames.size()));
  job.povThreads = std::max(1, cores / res.jobs);
  res.images.assign(frames.size(), {});
  std::atomic<size_t> next{0};
  std::atomic<bool> failed{false};
  std::mutex mutex;
  std::string firstError;
  int done = 0;
  auto worker = [&] {
    for (;;) {
      const size_t k = next++;
      if (k >= frames.size() || failed) return;
      try {
        res.images[k] = renderFrame(job, frames[k]);
      } catch (const std::exception& e) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!failed) firstError = e.what();
        failed = true;
        return;
      }
      std::lock_guard<std::mutex> lock(mutex);
      ++done;
      if (progress) progress(done, static_cast<int>(frames.size()));
    }
  };
  std::vector<std::thread> threads;
  for (int t = 0; t < res.jobs; ++t) threads.emplace_back(worker);
  for (std::thread& t : threads) t.join();
  if (failed) throw Error(firstError);

  const double frameSeconds = run.scene.output.stepsPerFrame * static_cast<double>(model.solver.dt);
  res.fps = o.fps > 0.0 ? o.fps : (frameSeconds > 0.0 ? 1.0 / frameSeconds : 25.0);
  if (o.video) res.video = encodeVideo(ffmpeg, res, job.workDir, o.timeoutSeconds);
  if (!o.keepPov) fs::remove_all(job.workDir, ec);
  return res;
}

ViewSettings runView(const std::string& runDir) { return openRunOutput(runDir).scene.view; }

}  // namespace soak
