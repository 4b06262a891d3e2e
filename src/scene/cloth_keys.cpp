// a "cloth" entry of the scene file: mesh, material, pins and the Chen 2012 keys (cloth_keys.hpp)
#include "scene/cloth_keys.hpp"

#include <soak/error.hpp>

#include "scene/common.hpp"
#include "scene/pattern_keys.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace soak {

namespace {

namespace fs = std::filesystem;

ClothMaterial readMaterial(ObjectReader r, ClothSolver solver) {
  const ClothMaterial d;
  ClothMaterial m;
  if (solver == ClothSolver::Implicit) {  // the KES laws, Rayleigh damping and wet friction replace these
    for (const char* key : {"stretchCompliance", "bendCompliance", "bendRigidity", "damping", "friction",
                            "staticFriction", "tetherSlack"})
      if (r.has(key))
        r.log().error(r.pathOf(key), fmt::format("expected no {} on a piece with \"solver\": \"implicit\" (a PBD "
                                                 "key; set the garment section instead, docs/scene-format.md)",
                                                 key));
  }
  if (r.has("particleMass") && r.has("arealDensity"))
    r.log().error(r.pathOf("arealDensity"), "expected either particleMass (kg a particle) or arealDensity (kg/m^2), "
                                            "got both");
  // one of the two sets the dry mass: particleMass when given, else arealDensity (default)
  m.particleMass = r.has("particleMass") ? r.number("particleMass", std::nullopt, Range::positive()) : 0.0f;
  m.arealDensity = r.has("particleMass") ? 0.0f : r.number("arealDensity", d.arealDensity, Range::positive());
  m.restDensity = r.number("restDensity", d.restDensity, Range::positive());
  m.stretchCompliance = r.number("stretchCompliance", d.stretchCompliance, Range::nonNegative());
  if (r.has("bendCompliance") && r.has("bendRigidity"))
    r.log().error(r.pathOf("bendRigidity"), "expected either bendCompliance (1/(N m) a hinge) or bendRigidity (N m), "
                                            "got both");
  // one of the two sets Eq. 9's stiffness: bendCompliance when given, else bendRigidity (default)
  m.bendCompliance = r.has("bendCompliance") ? r.number("bendCompliance", std::nullopt, Range::nonNegative()) : -1.0f;
  m.bendRigidity = r.has("bendCompliance") ? 0.0f : r.number("bendRigidity", d.bendRigidity, Range::positive());
  m.damping = r.number("damping", d.damping, Range::nonNegative());
  m.thickness = r.number("thickness", d.thickness, Range::positive());
  readFriction(r, d.friction, m.friction, m.staticFriction);
  m.selfCollision = r.boolean("selfCollision", d.selfCollision);
  m.tetherSlack = r.number("tetherSlack", d.tetherSlack, Range::nonNegative());
  r.finish();
  return m;
}

// the corners of a rectangle, in the order of docs/scene-format.md: 0 = (-u,-v), 1 = (+u,-v),
// 2 = (-u,+v), 3 = (+u,+v)
struct RectangleInfo {
  Vec3 corner[4];
};

int nearestVertex(const TriangleMesh& mesh, const Vec3& p) {
  int best = 0;
  for (int i = 1; i < int(mesh.vertices.size()); ++i)
    if ((mesh.vertices[i] - p).squaredNorm() < (mesh.vertices[best] - p).squaredNorm()) best = i;
  return best;
}

const std::vector<std::string> kRectangleKeys = {"center", "size", "resolution", "axisU", "axisV"};
const std::vector<std::string> kObjKeys = {"path", "scale", "translate", "rotate"};

// true when the mesh has at most limit.count vertices, else logs at `path` why not
bool withinLimit(ErrorLog& log, const std::string& path, const TriangleMesh& mesh, const ParticleLimit& limit) {
  if (int64_t(mesh.vertices.size()) <= limit.count) return true;
  log.error(path, fmt::format("expected at most {} vertices ({}), got {}", limit.count, limit.why, mesh.vertices.size()));
  return false;
}

// a sewn garment (world/pattern.hpp): its panels and seams into spec; only the implicit solver sews
std::optional<TriangleMesh> readPatternPiece(ObjectReader& m, const std::string& baseDir, const ParticleLimit& limit,
                                             const Bodies& bodies, ClothSolver solver, ClothSpec& spec) {
  std::optional<SewnGarment> g = readPatternMesh(m, baseDir, bodies, limit);
  m.finish(concat(concat(kRectangleKeys, kObjKeys), kGarmentMeshKeys), "a pattern mesh");
  if (solver != ClothSolver::Implicit)
    m.log().error(m.path(), "expected \"solver\": \"implicit\" on the piece (a pattern's seams are springs of the "
                            "implicit solver), got a pattern mesh on a PBD piece");
  if (!g || !withinLimit(m.log(), m.path(), g->mesh, limit)) return std::nullopt;
  spec.panelOfVertex = std::move(g->panelOfVertex);
  spec.seams = std::move(g->seamPairs);
  return std::move(g->mesh);
}

// reads "mesh" and builds the triangle mesh (a garment's panels and seams into spec); nullopt when
// it is invalid (errors logged)
std::optional<TriangleMesh> readMesh(ObjectReader m, const std::string& baseDir, const ParticleLimit& limit,
                                     std::optional<RectangleInfo>& rect, const Bodies& bodies, ClothSolver solver,
                                     ClothSpec& spec) {
  ErrorLog& log = m.log();
  const size_t errorsBefore = log.messages().size();
  const int type = m.choice("type", {"rectangle", "obj", "garment", "pattern"}, std::nullopt);
  if (type == 3) return readPatternPiece(m, baseDir, limit, bodies, solver, spec);
  if (type == 2) {
    std::optional<TriangleMesh> mesh = readGarmentMesh(m, bodies, spec.panelOfVertex);
    m.finish(concat(concat(kRectangleKeys, kObjKeys), {"pattern"}), "a garment mesh");
    if (mesh && !withinLimit(log, m.path(), *mesh, limit)) return std::nullopt;
    return mesh;
  }
  if (type == 0) {
    const Vec3 center = m.vec3("center", Vec3::Zero());
    const std::vector<float> size = m.numbers("size", 2, std::nullopt, Range::positive());
    const std::vector<int> res = m.integers("resolution", 2, std::nullopt, Range::atLeast(2));
    const Vec3 u = m.unitVec3("axisU", Vec3::UnitX());
    const Vec3 v = m.unitVec3("axisV", Vec3::UnitZ());
    m.finish(concat(concat(kObjKeys, kGarmentMeshKeys), {"pattern"}), "a rectangle mesh");
    if (std::abs(u.dot(v)) > 1e-3f)
      log.error(m.pathOf("axisV"), fmt::format("expected a direction perpendicular to axisU {}, got {}", fmtVec(u),
                                               fmtVec(v)));
    if (log.messages().size() != errorsBefore) return std::nullopt;
    if (int64_t(res[0]) * res[1] > limit.count) {
      log.error(m.pathOf("resolution"), fmt::format("expected at most {} vertices ({}), got {} x {}", limit.count,
                                                    limit.why, res[0], res[1]));
      return std::nullopt;
    }
    RectangleInfo info;
    for (int c = 0; c < 4; ++c)
      info.corner[c] = center + ((c & 1) ? 0.5f : -0.5f) * size[0] * u + ((c & 2) ? 0.5f : -0.5f) * size[1] * v;
    rect = info;
    return makeRectangle(center, u, v, size[0], size[1], res[0], res[1]);
  }
  if (type == 1) {
    const std::string file = m.string("path", std::nullopt);
    const float scale = m.number("scale", 1.0f, Range::positive());
    const Vec3 translate = m.vec3("translate", Vec3::Zero());
    const Quat rotate = readRotation(m.object("rotate"));
    m.finish(concat(concat(kRectangleKeys, kGarmentMeshKeys), {"pattern"}), "an obj mesh");
    if (log.messages().size() != errorsBefore) return std::nullopt;
    const fs::path resolved(resolvePath(file, baseDir));
    std::error_code ec;
    if (!fs::is_regular_file(resolved, ec)) {
      log.error(m.pathOf("path"), fmt::format("expected the path of an existing OBJ file, got \"{}\" (tried \"{}\")",
                                              file, resolved.string()));
      return std::nullopt;
    }
    try {
      TriangleMesh mesh = loadObjMesh(resolved.string());
      // scale, then rotate, then translate
      for (Vec3& x : mesh.vertices) x = rotate * (scale * x) + translate;
      if (!withinLimit(log, m.pathOf("path"), mesh, limit)) return std::nullopt;
      return mesh;
    } catch (const Error& e) {
      log.error(m.pathOf("path"), e.what());
      return std::nullopt;
    }
  }
  return std::nullopt;
}

// "pin": vertices, corners (rectangles), region; returns sorted unique mesh vertex indices
std::vector<int> readPins(ObjectReader p, const TriangleMesh* mesh, const std::optional<RectangleInfo>& rect) {
  ErrorLog& log = p.log();
  std::vector<int> pinned;
  const int nv = mesh ? int(mesh->vertices.size()) : 0;
  if (const Json* vs = p.array("vertices")) {
    const Range range = mesh ? Range::between(0, nv - 1) : Range::atLeast(0);
    for (size_t i = 0; i < vs->size(); ++i)
      if (const auto d = readNumber(log, (*vs)[i], indexPath(p.pathOf("vertices"), i), range, true))
        pinned.push_back(int(*d));
  }
  if (const Json* cs = p.array("corners")) {
    if (mesh && !rect) {
      log.error(p.pathOf("corners"), "expected no corners on an obj mesh (corners are for rectangle meshes; use "
                                     "vertices or region), got " + describeJson(*cs));
    } else {
      for (size_t i = 0; i < cs->size(); ++i)
        if (const auto d = readNumber(log, (*cs)[i], indexPath(p.pathOf("corners"), i), Range::between(0, 3), true))
          if (mesh) pinned.push_back(nearestVertex(*mesh, rect->corner[int(*d)]));
    }
  }
  ObjectReader region = p.object("region");
  if (region.present()) {
    const Vec3 lo = region.vec3("min", std::nullopt);
    const Vec3 hi = region.vec3("max", std::nullopt);
    region.finish();
    const bool ordered = checkOrdered(log, region.pathOf("max"), "region.min", lo, hi);
    if (mesh && ordered) {
      size_t inside = 0;
      for (int i = 0; i < nv; ++i) {
        const Vec3& x = mesh->vertices[i];
        if ((x.array() >= lo.array()).all() && (x.array() <= hi.array()).all()) {
          pinned.push_back(i);
          ++inside;
        }
      }
      if (inside == 0)
        log.error(region.path(), fmt::format("expected a box containing at least one vertex of the mesh, got min "
                                             "{} max {} (no vertex inside)", fmtVec(lo), fmtVec(hi)));
    }
  }
  p.finish();
  std::sort(pinned.begin(), pinned.end());
  pinned.erase(std::unique(pinned.begin(), pinned.end()), pinned.end());
  return pinned;
}

}  // namespace

std::optional<ClothSpec> readCloth(ErrorLog& log, const Json& v, const std::string& path, int index,
                                   const std::string& baseDir, const ParticleLimit& limit, bool shaoWetting, const Bodies& bodies,
                                   const std::vector<Collider>& colliders) {
  if (!v.is_object()) {
    log.expected(path, "an object (a cloth piece)", v);
    return std::nullopt;
  }
  ObjectReader r(log, &v, path);
  ClothSpec spec;
  spec.path = path;
  spec.name = r.name("name", fmt::format("cloth{}", index));
  const ClothSolver solver = readClothSolver(r);
  std::optional<RectangleInfo> rect;
  std::optional<TriangleMesh> mesh =
      readMesh(r.object("mesh", true), baseDir, limit, rect, bodies, solver, spec);
  spec.material = readMaterial(r.object("material"), solver);
  spec.pinned = readPins(r.object("pin"), mesh ? &*mesh : nullptr, rect);
  spec.chen = readChenCloth(r, solver, shaoWetting);
  r.finish();
  if (!mesh) return std::nullopt;
  if (spec.chen.bodyMargin < 0.0f) spec.chen.bodyMargin = 0.5f * spec.material.thickness;
  checkOutsideBody(log, path, spec.chen, bodies, colliders, *mesh);
  spec.mesh = std::move(*mesh);
  return spec;
}

}  // namespace soak
