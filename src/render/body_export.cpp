// the mannequin's skin as an OBJ sequence of one topology (soak/body_export.hpp)
#include <soak/body_export.hpp>

#include <soak/error.hpp>
#include <soak/scene.hpp>

#include "io/file.hpp"
#include "render/surface.hpp"
#include "world/colliders.hpp"
#include "world/mesh.hpp"
#include "world/mesh_distance.hpp"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>

namespace soak {

namespace {

// the rigid motion of part k from pose a to pose b, applied to x
Vec3 partMotion(const ColliderPose& a, const ColliderPose& b, const Vec3& x) {
  return b.rotation * (a.rotation.conjugate() * (x - a.translation)) + b.translation;
}

// the vertices' rest positions, moved to `pose` by their parts' weights, then onto the skin
std::vector<Vec3> skinnedVertices(const Collider& body, const ColliderPose& rest, const ColliderPose& pose,
                                  const std::vector<Vec3>& x0, const std::vector<std::vector<float>>& weights) {
  std::vector<Vec3> x(x0.size());
  for (size_t v = 0; v < x0.size(); ++v) {
    Vec3 sum = Vec3::Zero();
    for (size_t k = 0; k < weights[v].size(); ++k)
      if (weights[v][k] > 0.0f) sum += weights[v][k] * partMotion(rest.parts[k], pose.parts[k], x0[v]);
    for (int step = 0; step < kSkinProjections; ++step) {
      Vec3 n;
      sum -= colliderDistance(body, pose, sum, &n) * n;
    }
    x[v] = sum;
  }
  return x;
}

// the skin meshed at rest, with each vertex's weights
struct RestSkin {
  ColliderPose pose;
  SurfaceMesh mesh;
  std::vector<std::vector<float>> weights;
};

RestSkin restSkin(const Collider& body, double t0, float cellSize) {
  if (body.shape != ColliderShape::Body || !body.parts)
    throw errorAt("", body.name, "expected a body collider (a mannequin with blend > 0) to skin");
  RestSkin s;
  s.pose = colliderPose(body, t0);
  Vec3 lo, hi;
  if (!colliderBox(body, s.pose, &lo, &hi)) throw errorAt("", body.name, "the body has no bounds");
  s.mesh = colliderSurfaceMesh(body, s.pose, lo, hi, cellSize);
  if (s.mesh.triangles.empty())
    throw errorAt("", body.name, fmt::format("cannot mesh the skin at a cell size of {} m (too many cells?)", cellSize));
  twinTriangles(s.mesh.triangles, body.name + " skin");  // closed and consistently oriented, or throws
  s.weights.resize(s.mesh.vertices.size());
  for (size_t v = 0; v < s.mesh.vertices.size(); ++v) bodyPartWeights(body, s.pose, s.mesh.vertices[v], s.weights[v]);
  return s;
}

TriangleMesh skinAt(const Collider& body, const RestSkin& s, double t) {
  TriangleMesh m;
  m.vertices = skinnedVertices(body, s.pose, colliderPose(body, t), s.mesh.vertices, s.weights);
  m.triangles = s.mesh.triangles;
  return m;
}

}  // namespace

std::vector<TriangleMesh> skinnedBodyFrames(const Collider& body, const std::vector<double>& times, float cellSize) {
  if (times.empty()) return {};
  const RestSkin s = restSkin(body, times[0], cellSize);
  std::vector<TriangleMesh> frames;
  for (double t : times) frames.push_back(skinAt(body, s, t));
  return frames;
}

namespace {

const Collider& chooseBody(const Scene& scene, const std::string& name, const std::string& source) {
  for (const Collider& c : scene.model.colliders)
    if (c.shape == ColliderShape::Body && (name.empty() || c.name == name)) return c;
  if (name.empty())
    throw errorAt(source, "colliders", "expected a mannequin collider (with blend > 0) to export, found none");
  throw errorAt(source, "colliders", fmt::format("expected a mannequin collider named '{}' (with blend > 0)", name));
}

void writeObjFrame(const std::string& path, const TriangleMesh& m, int frame, double time) {
  std::ofstream out = openForWrite(path);
  out << fmt::format("# soak export-body: frame {}, t = {:.6g} s\n", frame, time);
  for (const Vec3& x : m.vertices) out << fmt::format("v {:.6f} {:.6f} {:.6f}\n", x.x(), x.y(), x.z());
  for (const auto& t : m.triangles) out << fmt::format("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
  finishWrite(out, path);
}

}  // namespace

BodyExport exportBody(const BodyExportOptions& o, const std::function<void(int, int)>& progress) {
  const Scene scene = loadScene(o.scene, o.overrides);
  const Collider& body = chooseBody(scene, o.collider, o.scene);
  BodyExport res;
  res.fps = o.fps > 0.0 ? o.fps : 1.0 / (scene.output.stepsPerFrame * double(scene.model.solver.dt));
  res.frames = o.frames > 0 ? o.frames : scene.output.frames + 1;
  if (!(o.cellSize > 0.0f)) throw errorAt(o.scene, "export-body", "expected a cell size > 0 m");
  const int digits = std::max(4, int(std::to_string(res.frames).size()));
  res.pattern = (std::filesystem::path(o.outDir) / ("body_" + std::string(size_t(digits), '#') + ".obj")).string();
  std::error_code ec;
  std::filesystem::create_directories(o.outDir, ec);
  const auto pathOf = [&](int f) {
    return (std::filesystem::path(o.outDir) / fmt::format("body_{:0{}d}.obj", f, digits)).string();
  };
  if (!o.overwrite && std::filesystem::exists(pathOf(1), ec))
    throw errorAt(pathOf(1), "export-body", "the file exists; pass --overwrite to replace the sequence");
  std::vector<double> times(size_t(res.frames));
  for (int f = 0; f < res.frames; ++f) times[size_t(f)] = f / res.fps;  // frame f + 1 shows at f / fps
  const RestSkin skin = restSkin(body, times[0], o.cellSize);
  res.vertices = skin.mesh.vertices.size();
  res.triangles = skin.mesh.triangles.size();
  for (int f = 0; f < res.frames; ++f) {
    writeObjFrame(pathOf(f + 1), skinAt(body, skin, times[size_t(f)]), f + 1, times[size_t(f)]);
    if (progress) progress(f + 1, res.frames);
  }
  return res;
}

}  // namespace soak
