// scene files: JSON -> validated Model + initial State (docs/scene-format.md). Every section is read
// by a checked reader that collects all errors; nothing is built until the whole file is valid.
#include <soak/error.hpp>
#include <soak/scene.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "garment/stage.hpp"
#include "pbd/tethers.hpp"
#include "scene/chen_keys.hpp"
#include "scene/cloth_piece.hpp"
#include "scene/common.hpp"
#include "scene/overrides.hpp"
#include "scene/reader.hpp"
#include "wetting/wetting.hpp"

namespace soak {

std::string fmtVec(const Vec3& v) { return fmt::format("[{}, {}, {}]", v.x(), v.y(), v.z()); }

Quat axisAngle(const Vec3& unitAxis, float degrees) {
  return Quat(Eigen::AngleAxisf(degrees * kPi / 180.0f, unitAxis)).normalized();
}

bool checkOrdered(ErrorLog& log, const std::string& maxPath, const std::string& minName, const Vec3& lo,
                  const Vec3& hi) {
  if ((hi.array() > lo.array()).all()) return true;
  log.error(maxPath, fmt::format("expected every component greater than {} {}, got {}", minName, fmtVec(lo), fmtVec(hi)));
  return false;
}

Quat readRotation(ObjectReader r) {
  const Vec3 axis = r.unitVec3("axis", Vec3::UnitY());
  const float degrees = r.number("degrees", 0.0f);
  r.finish();
  return axisAngle(axis, degrees);
}

std::vector<Keyframe> readPose(ObjectReader& r, bool isPlane) {
  ErrorLog& log = r.log();
  const bool hasKeys = r.has("keyframes"), hasPos = r.has("position"), hasRot = r.has("rotation");
  const bool hasNormal = isPlane && r.has("normal");
  if (hasKeys && (hasPos || hasRot))
    log.error(r.pathOf("keyframes"), "expected either position/rotation or keyframes, got both");
  if (hasNormal && (hasRot || hasKeys))
    log.error(r.pathOf("normal"), "expected normal alone, got it together with rotation or keyframes");
  Keyframe still;
  still.translation = r.vec3("position", Vec3::Zero());
  still.rotation = readRotation(r.object("rotation"));
  if (isPlane) {
    // the rotation taking local +y (the plane's normal) to the given normal
    const Vec3 normal = r.unitVec3("normal", Vec3::UnitY());
    if (hasNormal) still.rotation = Quat::FromTwoVectors(Vec3::UnitY(), normal).normalized();
  }
  std::vector<Keyframe> out = readKeyframes<Keyframe>(r, "a keyframe", [](ObjectReader& k, Keyframe& key) {
    key.translation = k.vec3("position", Vec3::Zero());
    key.rotation = readRotation(k.object("rotation"));
  });
  return out.empty() ? std::vector<Keyframe>{still} : out;
}

std::string resolvePath(const std::string& file, const std::string& baseDir) {
  std::filesystem::path resolved(file);
  if (resolved.is_relative()) resolved = std::filesystem::path(baseDir) / resolved;
  return resolved.string();
}

namespace {

namespace fs = std::filesystem;

// a validated cloth piece waiting to be appended to the model
struct ClothSpec {
  std::string name;
  std::string path;  // JSON path of the piece, for build-time errors
  TriangleMesh mesh;
  ClothMaterial material;
  std::vector<int> pinned;  // mesh vertex indices, sorted, unique
  ChenClothSpec chen;       // solver, saturation mass, garment settings (Chen 2012)
  std::vector<int> panelOfVertex;
};

void readSolver(ObjectReader r, SolverParams& s) {
  const SolverParams d;
  s.dt = r.number("dt", d.dt, Range::positive());
  s.substeps = r.integer("substeps", d.substeps, Range::atLeast(1));
  s.fluidIterations = r.integer("fluidIterations", d.fluidIterations, Range::atLeast(1));
  s.clothIterations = r.integer("clothIterations", d.clothIterations, Range::atLeast(0));
  s.couplingIterations = r.integer("couplingIterations", d.couplingIterations, Range::atLeast(0));
  s.gravity = r.vec3("gravity", d.gravity);
  ObjectReader dom = r.object("domain");
  s.domainMin = dom.vec3("min", d.domainMin);
  s.domainMax = dom.vec3("max", d.domainMax);
  dom.finish();
  checkOrdered(r.log(), dom.pathOf("max"), "solver.domain.min", s.domainMin, s.domainMax);
  s.maxParticles = r.integer("maxParticles", d.maxParticles, Range::atLeast(1));
  s.maxSpeed = r.number("maxSpeed", d.maxSpeed, Range::positive());
  r.finish();
}

void readWater(ObjectReader r, WaterParams& w) {
  const WaterParams d;
  w.restDensity = r.number("restDensity", d.restDensity, Range::positive());
  w.spacing = r.number("spacing", d.spacing, Range::positive());
  w.supportRadius = r.number("supportRadius", d.supportRadius, Range::positive());
  if (!(w.supportRadius > w.spacing))
    r.log().error(r.pathOf("supportRadius"),
                  fmt::format("expected a number > water.spacing ({}), got {}", w.spacing, w.supportRadius));
  w.particleMass = r.number("particleMass", d.particleMass, Range::positive());
  w.relaxation = r.number("relaxation", d.relaxation, Range::positive());
  w.viscosity = r.number("viscosity", d.viscosity, Range::unit());
  w.vorticity = r.number("vorticity", d.vorticity, Range::nonNegative());
  ObjectReader t = r.object("tensile");
  w.tensileK = t.number("k", d.tensileK, Range::nonNegative());
  w.tensileDq = t.number("dq", d.tensileDq, Range{0.0, 1.0, false, true});
  w.tensileN = t.integer("n", d.tensileN, Range::between(1, 32));  // the solver takes powers up to 63
  t.finish();
  w.boundaryFriction = r.number("boundaryFriction", d.boundaryFriction, Range::unit());
  r.finish();
}

void readOutput(ObjectReader r, OutputSettings& o) {
  const OutputSettings d;
  o.frames = r.integer("frames", d.frames, Range::atLeast(1));
  o.stepsPerFrame = r.integer("stepsPerFrame", d.stepsPerFrame, Range::atLeast(1));
  o.clothObj = r.boolean("clothObj", d.clothObj);
  o.clothPly = r.boolean("clothPly", d.clothPly);
  o.water = r.boolean("water", d.water);
  const std::vector<std::string> ramps = {"red", "green", "none"};
  const int ramp = r.choice("colorRamp", ramps, d.colorRamp);
  if (ramp >= 0) o.colorRamp = ramps[size_t(ramp)];
  r.finish();
}

// "view": the camera soak render uses unless its command line says otherwise
void readView(ObjectReader r, ViewSettings& v) {
  if (!r.present()) return;
  if (r.has("camera")) v.camera = r.vec3("camera", std::nullopt);
  if (r.has("lookAt")) v.lookAt = r.vec3("lookAt", std::nullopt);
  if (r.has("fov")) v.fov = r.number("fov", std::nullopt, Range{1.0, 179.0, true, true});
  if (r.has("azimuth")) v.azimuth = r.number("azimuth", std::nullopt);
  if (r.has("elevation")) v.elevation = r.number("elevation", std::nullopt, Range::between(-89.0, 89.0));
  if (r.has("zoom")) v.zoom = r.number("zoom", std::nullopt, Range::positive());
  r.finish();
  if (v.camera && v.lookAt && (*v.camera - *v.lookAt).norm() < 1e-6f)
    r.log().error(r.pathOf("lookAt"), fmt::format("expected a point other than view.camera, got {}", fmtVec(*v.lookAt)));
}

// "wetting" (Shao 2017 section 4): a present section is enabled unless "enabled": false
void readWetting(ObjectReader r, WettingParams& w) {
  const WettingParams d;
  ErrorLog& log = r.log();
  w.enabled = r.boolean("enabled", r.present());
  w.c = r.number("c", d.c, Range::positive());
  w.rateStep = r.number("rateStep", d.rateStep, Range::positive());
  w.everySubstep = r.boolean("everySubstep", d.everySubstep);
  ObjectReader s = r.object("saturation");
  const Range fraction{0.0, 1.0, true, false};  // (0, 1]
  w.saturationSticky = s.number("sticky", d.saturationSticky, fraction);
  w.saturationEmit = s.number("emit", d.saturationEmit, fraction);
  w.saturationMax = s.number("max", d.saturationMax, fraction);
  w.initialSaturation = s.number("initial", d.initialSaturation, Range::unit());
  s.finish();
  if (!(w.saturationSticky < w.saturationEmit))
    log.error(s.pathOf("sticky"), fmt::format("expected a number < wetting.saturation.emit ({}), got {}",
                                              w.saturationEmit, w.saturationSticky));
  if (w.saturationEmit > w.saturationMax)
    log.error(s.pathOf("emit"), fmt::format("expected a number <= wetting.saturation.max ({}), got {}",
                                            w.saturationMax, w.saturationEmit));
  if (w.initialSaturation > w.saturationMax)
    log.error(s.pathOf("initial"), fmt::format("expected a number <= wetting.saturation.max ({}), got {}",
                                               w.saturationMax, w.initialSaturation));
  ObjectReader a = r.object("absorption");
  w.absorption = a.boolean("enabled", d.absorption);
  w.absorptionRate = a.number("rate", d.absorptionRate, Range::unit());
  w.absorptionGravity = a.number("gravityInfluence", d.absorptionGravity, Range::unit());
  w.minMassFraction = a.number("minMassFraction", d.minMassFraction, Range{0.0, 1.0, false, true});
  a.finish();
  ObjectReader f = r.object("diffusion");
  w.diffusion = f.boolean("enabled", d.diffusion);
  w.diffusionGravity = f.boolean("gravity", d.diffusionGravity);
  w.diffusionRate = f.number("rate", d.diffusionRate, Range::nonNegative());
  w.diffusionGravityFactor = f.number("gravityInfluence", d.diffusionGravityFactor, Range::unit());
  w.smoothing = f.number("smoothing", d.smoothing, Range::unit());
  w.epsilon = f.number("epsilon", d.epsilon, Range::nonNegative());
  w.diffusionIterations = f.integer("iterations", d.diffusionIterations, Range::atLeast(1));
  f.finish();
  ObjectReader e = r.object("emission");
  w.emission = e.boolean("enabled", d.emission);
  w.beta = e.number("beta", d.beta, Range::nonNegative());
  w.massThreshold = e.number("massThreshold", d.massThreshold, Range::positive());
  w.maxDripMass = e.number("maxDripMass", d.maxDripMass, Range::positive());
  if (w.maxDripMass > 0.0f && w.maxDripMass < w.massThreshold)
    log.error(e.pathOf("maxDripMass"), fmt::format("expected a number >= wetting.emission.massThreshold ({}), got {}",
                                                  w.massThreshold, w.maxDripMass));
  w.attraction = e.number("attraction", d.attraction, Range::nonNegative());
  w.attractionSaturation = e.number("attractionSaturation", d.attractionSaturation, Range::nonNegative());
  e.finish();
  ObjectReader k = r.object("sticking");
  w.sticking = k.boolean("enabled", d.sticking);
  w.stickingRate = k.number("rate", d.stickingRate, Range::nonNegative());
  w.stickingStrength = k.number("strength", d.stickingStrength, Range::nonNegative());
  k.finish();
  ObjectReader m = r.object("permeability");
  w.permeability = m.boolean("enabled", d.permeability);
  m.finish();
  r.finish();
}

// a drip needs m^threshold in one buffer: refuse a threshold above what a typical (median) particle of
// some piece can hold at S^MAX (S^MAX V / c, Eq. 10)
void checkDripThreshold(ErrorLog& log, const Model& model, const std::vector<float>& volume) {
  const WettingParams& w = model.wetting;
  if (!w.enabled || !w.emission) return;
  for (size_t k = 0; k < model.pieces.size(); ++k) {
    const ClothPiece& piece = model.pieces[k];
    std::vector<float> v(volume.begin() + piece.firstParticle,
                         volume.begin() + piece.firstParticle + piece.particleCount);
    if (v.empty()) continue;
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
    const double hold = double(w.saturationMax) * v[v.size() / 2] / w.c;
    if (double(w.massThreshold) > hold)
      log.error("wetting.emission.massThreshold",
                fmt::format("expected at most the water a cloth particle of cloth[{}] ('{}') can hold, S^MAX V / c = "
                            "{:.4g} kg (median V = {:.4g} m^3), got {} (lower it, or lower wetting.c)",
                            k, piece.name, hold, v[v.size() / 2], w.massThreshold));
  }
}

ClothMaterial readMaterial(ObjectReader r, ClothSolver solver) {
  const ClothMaterial d;
  ClothMaterial m;
  if (solver == ClothSolver::Implicit) {  // the KES laws, Rayleigh damping and wet friction replace these
    for (const char* key : {"stretchCompliance", "bendCompliance", "damping", "friction", "tetherSlack"})
      if (r.has(key))
        r.log().error(r.pathOf(key), fmt::format("expected no {} on a piece with \"solver\": \"implicit\" (a PBD "
                                                 "key; set the garment section instead, docs/scene-format.md)",
                                                 key));
    if (const Json* sc = r.get("selfCollision"); sc && sc->is_boolean() && sc->get<bool>())
      r.log().error(r.pathOf("selfCollision"),
                    "expected false on a piece with \"solver\": \"implicit\" (the implicit solver has no "
                    "self-collision), got true");
  }
  m.particleMass = r.number("particleMass", d.particleMass, Range::positive());
  m.restDensity = r.number("restDensity", d.restDensity, Range::positive());
  m.stretchCompliance = r.number("stretchCompliance", d.stretchCompliance, Range::nonNegative());
  m.bendCompliance = r.number("bendCompliance", d.bendCompliance, Range::nonNegative());
  m.damping = r.number("damping", d.damping, Range::nonNegative());
  m.thickness = r.number("thickness", d.thickness, Range::positive());
  m.friction = r.number("friction", d.friction, Range::unit());
  m.selfCollision = r.boolean("selfCollision", d.selfCollision) && solver == ClothSolver::Pbd;
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

std::vector<std::string> concat(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// reads "mesh" and builds the triangle mesh; nullopt when it is invalid (errors logged)
std::optional<TriangleMesh> readMesh(ObjectReader m, const std::string& baseDir, int maxVertices,
                                     std::optional<RectangleInfo>& rect, const Bodies& bodies,
                                     std::vector<int>& panelOfVertex) {
  ErrorLog& log = m.log();
  const size_t errorsBefore = log.messages().size();
  const int type = m.choice("type", {"rectangle", "obj", "garment"}, std::nullopt);
  if (type == 2) {
    std::optional<TriangleMesh> mesh = readGarmentMesh(m, bodies, panelOfVertex);
    m.finish(concat(kRectangleKeys, kObjKeys), "a garment mesh");
    if (mesh && int64_t(mesh->vertices.size()) > maxVertices) {
      log.error(m.path(), fmt::format("expected at most solver.maxParticles ({}) vertices, got {}", maxVertices,
                                      mesh->vertices.size()));
      return std::nullopt;
    }
    return mesh;
  }
  if (type == 0) {
    const Vec3 center = m.vec3("center", Vec3::Zero());
    const std::vector<float> size = m.numbers("size", 2, std::nullopt, Range::positive());
    const std::vector<int> res = m.integers("resolution", 2, std::nullopt, Range::atLeast(2));
    const Vec3 u = m.unitVec3("axisU", Vec3::UnitX());
    const Vec3 v = m.unitVec3("axisV", Vec3::UnitZ());
    m.finish(concat(kObjKeys, kGarmentMeshKeys), "a rectangle mesh");
    if (std::abs(u.dot(v)) > 1e-3f)
      log.error(m.pathOf("axisV"), fmt::format("expected a direction perpendicular to axisU {}, got {}", fmtVec(u),
                                               fmtVec(v)));
    if (log.messages().size() != errorsBefore) return std::nullopt;
    if (int64_t(res[0]) * res[1] > maxVertices) {
      log.error(m.pathOf("resolution"), fmt::format("expected at most solver.maxParticles ({}) vertices, got {} x {}",
                                                    maxVertices, res[0], res[1]));
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
    m.finish(concat(kRectangleKeys, kGarmentMeshKeys), "an obj mesh");
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
      if (int64_t(mesh.vertices.size()) > maxVertices) {
        log.error(m.pathOf("path"), fmt::format("expected at most solver.maxParticles ({}) vertices, got {}",
                                                maxVertices, mesh.vertices.size()));
        return std::nullopt;
      }
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

std::optional<ClothSpec> readCloth(ErrorLog& log, const Json& v, const std::string& path, int index,
                                   const std::string& baseDir, int maxVertices, bool shaoWetting, const Bodies& bodies,
                                   const std::vector<Collider>& colliders) {
  if (!v.is_object()) {
    log.expected(path, "an object (a cloth piece)", v);
    return std::nullopt;
  }
  ObjectReader r(log, &v, path);
  ClothSpec spec;
  spec.path = path;
  spec.name = r.string("name", fmt::format("cloth{}", index));
  const ClothSolver solver = readClothSolver(r);
  std::optional<RectangleInfo> rect;
  std::optional<TriangleMesh> mesh =
      readMesh(r.object("mesh", true), baseDir, maxVertices, rect, bodies, spec.panelOfVertex);
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

// in ColliderShape order, then the mannequin (many colliders)
const std::vector<std::string> kColliderTypes = {"plane", "box", "container", "sphere", "capsule", "mesh", "mannequin"};
// the keys that only some collider types have
const std::vector<std::string> kColliderShapeKeys = {"normal", "halfExtents", "wallThickness", "radius", "halfHeight",
                                                     "path",   "resolution",  "padding",       "height", "yaw",
                                                     "proportions", "pose", "sampleInterval"};

std::optional<std::vector<Collider>> readCollider(ErrorLog& log, const Json& v, const std::string& path, int index,
                                                  const std::string& baseDir, Bodies& bodies) {
  if (!v.is_object()) {
    log.expected(path, "an object (a collider)", v);
    return std::nullopt;
  }
  ObjectReader r(log, &v, path);
  Collider c;
  c.name = r.string("name", fmt::format("collider{}", index));
  const int type = r.choice("type", kColliderTypes, std::nullopt);
  if (type < 0) return std::nullopt;  // keys depend on the type: nothing more to check
  if (kColliderTypes[size_t(type)] == "mannequin") {
    if (bodies.count(c.name)) log.error(r.pathOf("name"), fmt::format("expected a unique name, got \"{}\" twice", c.name));
    std::vector<Collider> body = readMannequin(r, c.name, bodies);
    if (body.empty()) return std::nullopt;
    return body;
  }
  c.shape = ColliderShape(type);
  const Collider d;
  std::vector<std::string> mine;
  switch (c.shape) {
    case ColliderShape::Plane:
      mine = {"normal"};
      break;
    case ColliderShape::Box:
      c.halfExtents = r.vec3("halfExtents", d.halfExtents, Range::positive());
      mine = {"halfExtents"};
      break;
    case ColliderShape::Container:
      c.halfExtents = r.vec3("halfExtents", d.halfExtents, Range::positive());
      c.wallThickness = r.number("wallThickness", d.wallThickness, Range::positive());
      mine = {"halfExtents", "wallThickness"};
      break;
    case ColliderShape::Sphere:
      c.radius = r.number("radius", d.radius, Range::positive());
      mine = {"radius"};
      break;
    case ColliderShape::Capsule:
      c.radius = r.number("radius", d.radius, Range::positive());
      c.halfHeight = r.number("halfHeight", d.halfHeight, Range::positive());
      mine = {"radius", "halfHeight"};
      break;
    case ColliderShape::Mesh:
      readMeshColliderShape(r, c, baseDir);
      mine = {"path", "resolution", "padding"};
      break;
  }
  c.friction = r.number("friction", d.friction, Range::unit());
  c.restitution = r.number("restitution", d.restitution, Range::unit());
  c.keys = readPose(r, c.shape == ColliderShape::Plane);
  std::vector<std::string> others;
  for (const auto& k : kColliderShapeKeys)
    if (std::find(mine.begin(), mine.end(), k) == mine.end()) others.push_back(k);
  r.finish(others, "a " + kColliderTypes[size_t(type)] + " collider");
  if (c.shape == ColliderShape::Mesh && !c.sdf) return std::nullopt;
  return std::vector<Collider>{c};
}

const std::vector<std::string> kBlockKeys = {"min", "max", "velocity"};
const std::vector<std::string> kJetKeys = {"origin", "direction", "speed", "radius", "end"};
const std::vector<std::string> kRainKeys = {"origin", "halfExtents", "rate", "dropSpeed", "dropRadius", "direction", "end"};

// true also when the domain itself is invalid (that error is reported once, at solver.domain)
bool insideDomain(const SolverParams& s, const Vec3& p) {
  if (!(s.domainMax.array() > s.domainMin.array()).all()) return true;
  return (p.array() >= s.domainMin.array()).all() && (p.array() <= s.domainMax.array()).all();
}

std::optional<Emitter> readEmitter(ErrorLog& log, const Json& v, const std::string& path, int index,
                                   const SolverParams& solver) {
  if (!v.is_object()) {
    log.expected(path, "an object (an emitter)", v);
    return std::nullopt;
  }
  ObjectReader r(log, &v, path);
  Emitter e;
  const Emitter d;
  e.name = r.string("name", fmt::format("emitter{}", index));
  const int type = r.choice("type", {"block", "jet", "rain"}, std::nullopt);
  if (type < 0) return std::nullopt;
  e.kind = EmitterKind(type);
  const std::string domain = fmt::format("inside solver.domain ({} to {})", fmtVec(solver.domainMin),
                                         fmtVec(solver.domainMax));
  if (e.kind == EmitterKind::Block) {
    e.boxMin = r.vec3("min", std::nullopt);
    e.boxMax = r.vec3("max", std::nullopt);
    e.velocity = r.vec3("velocity", d.velocity);
    e.start = r.number("start", d.start, Range::nonNegative());
    r.finish(concat(kJetKeys, kRainKeys), "a block emitter");
    if (r.has("min") && r.has("max") && checkOrdered(log, r.pathOf("max"), "min", e.boxMin, e.boxMax)) {
      if (!insideDomain(solver, e.boxMin) || !insideDomain(solver, e.boxMax))
        log.error(r.path(), fmt::format("expected a block {}, got min {} max {}", domain, fmtVec(e.boxMin),
                                        fmtVec(e.boxMax)));
    }
  } else if (e.kind == EmitterKind::Rain) {
    readRain(r, e);
    r.finish(concat(kBlockKeys, kJetKeys), "a rain emitter");
    if (r.has("origin") && !insideDomain(solver, e.origin))
      log.error(r.pathOf("origin"), fmt::format("expected a point {}, got {}", domain, fmtVec(e.origin)));
  } else {
    e.origin = r.vec3("origin", std::nullopt);
    e.direction = r.unitVec3("direction", d.direction);
    e.speed = r.number("speed", d.speed, Range::positive());
    e.radius = r.number("radius", d.radius, Range::positive());
    e.start = r.number("start", d.start, Range::nonNegative());
    e.end = r.number("end", d.end, Range::positive());
    r.finish(concat(kBlockKeys, kRainKeys), "a jet emitter");
    if (r.has("end") && !(e.end > e.start))
      log.error(r.pathOf("end"), fmt::format("expected a time > start ({} s), got {}", e.start, e.end));
    if (r.has("origin") && !insideDomain(solver, e.origin))
      log.error(r.pathOf("origin"), fmt::format("expected a point {}, got {}", domain, fmtVec(e.origin)));
  }
  return e;
}

// reads an array of objects with `readOne(value, path, index)`
template <class T, class F>
std::vector<T> readArray(ObjectReader& top, const std::string& key, F&& readOne) {
  std::vector<T> out;
  if (const Json* a = top.array(key))
    for (size_t i = 0; i < a->size(); ++i)
      if (auto item = readOne((*a)[i], indexPath(top.pathOf(key), i), int(i))) out.push_back(std::move(*item));
  return out;
}

Scene buildScene(Json doc, const std::string& file, const std::string& baseDir,
                 const std::vector<std::string>& overrides) {
  applyOverrides(doc, overrides, file);
  ErrorLog log(file);
  if (!doc.is_object()) {
    log.expected("", "a JSON object at the top level", doc);
    log.throwIfAny();
  }
  Scene scene;
  scene.path = file;
  Model& model = scene.model;
  ObjectReader top(log, &doc, "");
  scene.name = top.string("name", fs::path(file).stem().string());
  scene.description = top.string("description", "");
  readSolver(top.object("solver"), model.solver);
  readWater(top.object("water"), model.water);
  readOutput(top.object("output"), scene.output);
  readView(top.object("view"), scene.view);
  readWetting(top.object("wetting"), model.wetting);
  const int maxVertices = model.solver.maxParticles;
  Bodies bodies;  // mannequins by name, for the garments sewn around them
  for (auto& group : readArray<std::vector<Collider>>(top, "colliders", [&](const Json& v, const std::string& p, int i) {
         return readCollider(log, v, p, i, baseDir, bodies);
       }))
    for (Collider& c : group) model.colliders.push_back(std::move(c));
  const std::vector<ClothSpec> cloth = readArray<ClothSpec>(top, "cloth", [&](const Json& v, const std::string& p, int i) {
    return readCloth(log, v, p, i, baseDir, maxVertices, model.wetting.enabled, bodies, model.colliders);
  });
  model.emitters = readArray<Emitter>(top, "emitters", [&](const Json& v, const std::string& p, int i) {
    return readEmitter(log, v, p, i, model.solver);
  });
  top.finish();
  const Json* clothJson = top.get("cloth");
  const Json* emitterJson = top.get("emitters");
  const bool noCloth = !clothJson || !clothJson->is_array() || clothJson->empty();
  const bool noEmitter = !emitterJson || !emitterJson->is_array() || emitterJson->empty();
  if (noCloth && noEmitter) log.error("", "expected at least one cloth piece or emitter, got none (empty scene)");
  size_t clothParticles = 0;
  for (const ClothSpec& c : cloth) clothParticles += c.mesh.vertices.size();
  if (clothParticles > size_t(maxVertices))
    log.error("cloth", fmt::format("expected at most solver.maxParticles ({}) cloth particles in all, got {}",
                                   maxVertices, clothParticles));
  log.throwIfAny();

  // build: topology is checked by addClothPiece (manifold edges, degenerate triangles)
  for (const ClothSpec& c : cloth) {
    addClothPiece(model, c.name, c.mesh, c.material, c.pinned, fmt::format("{}: at {}.mesh", file, c.path),
                  c.chen.solver);
    ClothPiece& piece = model.pieces.back();
    piece.garment = c.chen.garment;
    piece.wetByContact = c.chen.wetByContact;
    piece.dropsVanish = c.chen.dropsVanish;
    piece.panelOfVertex = c.panelOfVertex;
  }
  buildTethers(model);
  buildGarmentPieces(model);  // Chen 2012 springs of the implicit pieces
  Particles& p = scene.state.particles;
  for (size_t k = 0; k < model.pieces.size(); ++k) {
    const ClothPiece& piece = model.pieces[k];
    for (int i = piece.firstParticle; i < piece.firstParticle + piece.particleCount; ++i) {
      p.add(int32_t(k + 1), uint32_t(i), model.clothDryMass[size_t(i)], model.water.supportRadius,
            model.clothRestPosition[size_t(i)], Vec3::Zero());
      if (model.clothPinned[size_t(i)]) p.invMass.back() = 0.0f;
    }
  }
  scene.state.nextId = uint32_t(model.numCloth);
  scene.state.emitters.resize(model.emitters.size());
  for (const ClothPiece& piece : model.pieces)
    if (piece.wetByContact) scene.state.clothWetStart.assign(size_t(model.numCloth), std::numeric_limits<float>::infinity());
  for (size_t k = 0; k < cloth.size(); ++k)
    if (cloth[k].chen.wetAtStart && model.pieces[k].wetByContact)
      std::fill_n(scene.state.clothWetStart.begin() + model.pieces[k].firstParticle, model.pieces[k].particleCount, 0.0f);
  if (model.wetting.enabled) {
    const std::vector<float> volume = restVolumes(model, p.radius);
    checkDripThreshold(log, model, volume);
    log.throwIfAny();
    initWettingState(model, volume, scene.state);
  }
  return scene;
}

}  // namespace

Scene loadSceneFromString(const std::string& text, const std::string& sourceName, const std::string& baseDir,
                          const std::vector<std::string>& overrides) {
  return buildScene(parseSceneJson(text, sourceName), sourceName, baseDir, overrides);
}

Scene loadScene(const std::string& path, const std::vector<std::string>& overrides) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw errorAt(path, "", "cannot open the scene file (expected a readable JSON file)");
  std::ostringstream text;
  text << in.rdbuf();
  const fs::path parent = fs::path(path).parent_path();
  return loadSceneFromString(text.str(), path, parent.empty() ? fs::path(".").string() : parent.string(), overrides);
}

}  // namespace soak
