// scene files: JSON -> validated Model + initial State (docs/scene-format.md). Every section is read
// by a checked reader that collects all errors; nothing is built until the whole file is valid. The
// cloth entries are read in cloth_keys.cpp, the Chen 2012 keys in chen_keys.cpp.
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
#include "scene/clearance.hpp"
#include "scene/cloth_keys.hpp"
#include "scene/cloth_piece.hpp"
#include "scene/common.hpp"
#include "scene/limits.hpp"
#include "scene/overrides.hpp"
#include "scene/reader.hpp"
#include "wetting/wetting.hpp"

namespace soak {

std::string fmtVec(const Vec3& v) { return fmt::format("[{}, {}, {}]", v.x(), v.y(), v.z()); }

std::vector<std::string> concat(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

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

void readFriction(ObjectReader& r, float defaultKinetic, float& kinetic, float& staticCoef) {
  kinetic = r.number("friction", defaultKinetic, Range::nonNegative());
  staticCoef = r.number("staticFriction", kinetic, Range::nonNegative());
  if (staticCoef < kinetic)
    r.log().error(r.pathOf("staticFriction"),
                  fmt::format("expected a number >= friction ({}), got {}", kinetic, staticCoef));
}

namespace {

namespace fs = std::filesystem;

void readSolver(ObjectReader r, SolverParams& s, float& maxMemoryGB) {
  const SolverParams d;
  s.dt = r.number("dt", d.dt, Range::positive());
  // loop counts of a step are bounded (kMaxLoopCount): a mistyped 1e9 would hang the first step
  const Range loops = Range::between(1, kMaxLoopCount), loops0 = Range::between(0, kMaxLoopCount);
  s.substeps = r.integer("substeps", d.substeps, loops);
  s.fluidIterations = r.integer("fluidIterations", d.fluidIterations, loops);
  s.fluidMaxIterations = r.integer("fluidMaxIterations", std::max(d.fluidMaxIterations, s.fluidIterations),
                                   Range::between(s.fluidIterations, std::max(s.fluidIterations, kMaxLoopCount)));
  s.fluidTolerance = r.number("fluidTolerance", d.fluidTolerance, Range::positive());
  s.clothSubsteps = r.integer("clothSubsteps", d.clothSubsteps, loops);
  s.clothIterations = r.integer("clothIterations", d.clothIterations, loops0);
  s.clothCollidersInSmallSteps = r.boolean("clothCollidersInSmallSteps", d.clothCollidersInSmallSteps);
  s.clothHierarchy = r.integer("clothHierarchy", d.clothHierarchy, Range::between(0, 16));
  s.clothPinPasses = r.integer("clothPinPasses", d.clothPinPasses, Range::between(0, 64));
  s.clothPinRings = r.integer("clothPinRings", d.clothPinRings, Range::between(1, 64));
  s.clothGlobalStretch = r.boolean("clothGlobalStretch", d.clothGlobalStretch);
  s.couplingIterations = r.integer("couplingIterations", d.couplingIterations, loops0);
  s.gravity = r.vec3("gravity", d.gravity);
  ObjectReader dom = r.object("domain");
  s.domainMin = dom.vec3("min", d.domainMin);
  s.domainMax = dom.vec3("max", d.domainMax);
  dom.finish();
  checkOrdered(r.log(), dom.pathOf("max"), "solver.domain.min", s.domainMin, s.domainMax);
  s.maxParticles = r.integer("maxParticles", d.maxParticles, Range::atLeast(1));
  s.maxSpeed = r.number("maxSpeed", d.maxSpeed, Range::positive());
  maxMemoryGB = r.number("maxMemoryGB", 0.0f, Range::positive());
  r.finish();
}

void readWater(ObjectReader r, WaterParams& w) {
  const WaterParams d;
  w.restDensity = r.number("restDensity", d.restDensity, Range::positive());
  w.spacing = r.number("spacing", d.spacing, Range::positive());
  w.supportRadius = r.number("supportRadius", d.supportRadius, Range::positive());
  // above the spacing, and at most kMaxSupportRatio spacings: the lattice sums of the emitters visit
  // (2 h / spacing + 1)^3 sites and the neighbour lists grow as (h / spacing)^3
  if (!(w.supportRadius > w.spacing) || !(double(w.supportRadius) <= kMaxSupportRatio * double(w.spacing)))
    r.log().error(r.pathOf("supportRadius"),
                  fmt::format("expected a number in (water.spacing, {:g} x water.spacing] = ({}, {:g}], got {}",
                              kMaxSupportRatio, w.spacing, kMaxSupportRatio * double(w.spacing), w.supportRadius));
  w.particleMass = r.number("particleMass", d.particleMass, Range::positive());
  w.relaxation = r.number("relaxation", d.relaxation, Range::positive());
  w.viscosity = r.number("viscosity", d.viscosity, Range::unit());
  w.vorticity = r.number("vorticity", d.vorticity, Range::nonNegative());
  w.hyperviscosity = r.number("hyperviscosity", d.hyperviscosity, Range::nonNegative());
  ObjectReader t = r.object("tensile");
  w.tensileK = t.number("k", d.tensileK, Range::nonNegative());
  w.tensileDq = t.number("dq", d.tensileDq, Range{0.0, 1.0, false, true});
  w.tensileN = t.integer("n", d.tensileN, Range::between(1, 32));  // the solver takes powers up to 63
  t.finish();
  w.boundaryFriction = r.number("boundaryFriction", d.boundaryFriction, Range::nonNegative());
  w.clothFriction = r.number("clothFriction", d.clothFriction, Range::nonNegative());
  r.finish();
}

void readOutput(ObjectReader r, OutputSettings& o) {
  const OutputSettings d;
  o.frames = r.integer("frames", d.frames, Range::atLeast(1));
  o.stepsPerFrame = r.integer("stepsPerFrame", d.stepsPerFrame, Range::between(1, kMaxStepsPerFrame));
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
  w.referenceArea = r.number("referenceArea", d.referenceArea, Range::nonNegative());
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
  w.diffusivity = f.number("diffusivity", d.diffusivity, Range::nonNegative());
  w.wickingHeight = f.number("wickingHeight", d.wickingHeight, Range::positive());
  w.diffusionGravityFactor = f.number("gravityInfluence", d.diffusionGravityFactor, Range::unit());
  w.diffusionIterations = f.integer("iterations", d.diffusionIterations, Range::between(1, kMaxLoopCount));
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
// some piece can hold at S^MAX (S^MAX V / c, Eq. 10), both per referenceArea of cloth; and, with a
// referenceArea, a vertex in no triangle (no area: its m^threshold would be 0)
void checkDripThreshold(ErrorLog& log, const Model& model, const std::vector<float>& volume) {
  const WettingParams& w = model.wetting;
  if (!w.enabled || !w.emission) return;
  for (size_t k = 0; k < model.pieces.size(); ++k) {
    const ClothPiece& piece = model.pieces[k];
    std::vector<double> hold;  // kg per referenceArea
    for (int i = piece.firstParticle; i < piece.firstParticle + piece.particleCount; ++i) {
      const float share = areaShare(w.referenceArea, model.clothRestArea[size_t(i)]);
      if (share > 0.0f) {
        hold.push_back(mostHeldWater(w, volume[size_t(i)]) / share);
        continue;
      }
      log.error("wetting.referenceArea",
                fmt::format("expected 0 (amounts per particle) when cloth[{}] ('{}') has a vertex in no triangle "
                            "(vertex {}, 0-based: no area to share m^threshold by), got {}",
                            k, piece.name, i - piece.firstParticle, w.referenceArea));
      break;
    }
    if (hold.size() < size_t(piece.particleCount) || hold.empty()) continue;
    std::nth_element(hold.begin(), hold.begin() + std::ptrdiff_t(hold.size() / 2), hold.end());
    const double median = hold[hold.size() / 2];
    if (double(w.massThreshold) > median)
      log.error("wetting.emission.massThreshold",
                fmt::format("expected at most the water a cloth particle of cloth[{}] ('{}') can hold, S^MAX V / c = "
                            "{:.4g} kg (the median{}), got {} (lower it, or lower wetting.c)",
                            k, piece.name, median,
                            w.referenceArea > 0.0f ? fmt::format(" per wetting.referenceArea = {} m^2", w.referenceArea) : "",
                            w.massThreshold));
  }
}

// in ColliderShape order; a "mannequin" makes a Body
const std::vector<std::string> kColliderTypes = {"plane", "box",  "container", "sphere",
                                                 "capsule", "mesh", "mannequin", "meshSequence"};
// the keys that only some collider types have
const std::vector<std::string> kColliderShapeKeys = {"normal", "halfExtents", "wallThickness", "radius", "halfHeight",
                                                     "path",   "resolution",  "padding",       "height", "yaw",
                                                     "proportions", "pose", "sampleInterval", "fps",
                                                     "start", "scale", "firstFrame", "lastFrame"};

std::optional<std::vector<Collider>> readCollider(ErrorLog& log, const Json& v, const std::string& path, int index,
                                                  const std::string& baseDir, Bodies& bodies) {
  if (!v.is_object()) {
    log.expected(path, "an object (a collider)", v);
    return std::nullopt;
  }
  ObjectReader r(log, &v, path);
  Collider c;
  c.name = r.name("name", fmt::format("collider{}", index));
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
    case ColliderShape::MeshSequence:
      readMeshSequenceShape(r, c, baseDir);
      mine = {"path", "fps", "start", "scale", "firstFrame", "lastFrame"};
      break;
    case ColliderShape::Body:  // only a "mannequin" makes one (read above)
      break;
  }
  readFriction(r, d.friction, c.friction, c.staticFriction);
  c.restitution = r.number("restitution", d.restitution, Range::unit());
  c.keys = readPose(r, c.shape == ColliderShape::Plane);
  std::vector<std::string> others;
  for (const auto& k : kColliderShapeKeys)
    if (std::find(mine.begin(), mine.end(), k) == mine.end()) others.push_back(k);
  r.finish(others, "a " + kColliderTypes[size_t(type)] + " collider");
  if (c.shape == ColliderShape::Mesh && !c.sdf) return std::nullopt;
  if (c.shape == ColliderShape::MeshSequence && !c.sequence) return std::nullopt;
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
                                   const SolverParams& solver, const WaterParams& water) {
  if (!v.is_object()) {
    log.expected(path, "an object (an emitter)", v);
    return std::nullopt;
  }
  ObjectReader r(log, &v, path);
  Emitter e;
  const Emitter d;
  e.name = r.name("name", fmt::format("emitter{}", index));
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
    if (e.dropSpeed > solver.maxSpeed)
      log.error(r.pathOf("dropSpeed"), fmt::format("expected a number <= solver.maxSpeed ({} m/s), got {}",
                                                   solver.maxSpeed, e.dropSpeed));
    const double perSecond = double(e.rate) * 4.0 * double(e.halfExtents.x()) * double(e.halfExtents.z());
    if (perSecond > kMaxDropsPerSecond)
      log.error(r.pathOf("rate"), fmt::format("expected at most {:g} drops a second over the rectangle (rate x area), "
                                              "got {:.4g}",
                                              kMaxDropsPerSecond, perSecond));
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
    // water faster than solver.maxSpeed stops the run as diverged at its first frame
    if (e.speed > solver.maxSpeed)
      log.error(r.pathOf("speed"), fmt::format("expected a number <= solver.maxSpeed ({} m/s), got {}",
                                               solver.maxSpeed, e.speed));
    // a disc is a lattice of (2 radius / spacing)^2 sites: bounded so the count fits and a step ends
    if (double(e.radius) > kMaxJetRadiusRatio * double(water.spacing))
      log.error(r.pathOf("radius"), fmt::format("expected a number <= {:g} x water.spacing = {:g} m, got {}",
                                                kMaxJetRadiusRatio, kMaxJetRadiusRatio * double(water.spacing),
                                                e.radius));
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

// the scene needs something to simulate, and its particles fit in the limit (solver.maxParticles and
// the memory budget): the cloth, and the water its emitters can make over the scene's frames
void checkSceneSize(ErrorLog& log, ObjectReader& top, const std::vector<ClothSpec>& cloth, const Model& model,
                    const OutputSettings& output, const ParticleLimit& limit) {
  const Json* clothJson = top.get("cloth");
  const Json* emitterJson = top.get("emitters");
  const bool noCloth = !clothJson || !clothJson->is_array() || clothJson->empty();
  const bool noEmitter = !emitterJson || !emitterJson->is_array() || emitterJson->empty();
  if (noCloth && noEmitter) log.error("", "expected at least one cloth piece or emitter, got none (empty scene)");
  int64_t clothParticles = 0;
  for (const ClothSpec& c : cloth) clothParticles += int64_t(c.mesh.vertices.size());
  if (clothParticles > limit.count) {
    log.error("cloth", fmt::format("expected at most {} cloth particles in all ({}), got {}", limit.count, limit.why,
                                   clothParticles));
    return;
  }
  // emitters stop quietly at solver.maxParticles; only a memory budget below it can be exceeded
  const double duration = double(model.solver.dt) * output.stepsPerFrame * output.frames;
  const int64_t water = emitterParticleBound(model, duration);
  const int64_t total = std::min<int64_t>(clothParticles + water, model.solver.maxParticles);
  if (total > limit.count)
    log.error("emitters", fmt::format("expected at most {} particles in all ({}), got up to {} ({} cloth and up to "
                                      "{} water from the emitters in the scene's {:.4g} s; lower "
                                      "solver.maxParticles to cap them)",
                                      limit.count, limit.why, total, clothParticles, water, duration));
}

// appends the validated pieces with their Chen 2012 settings, then the tethers and the springs of the
// implicit pieces; topology is checked by addClothPiece (manifold edges, degenerate triangles)
void buildCloth(Model& model, const std::vector<ClothSpec>& cloth, const std::string& file) {
  for (const ClothSpec& c : cloth) {
    addClothPiece(model, c.name, c.mesh, c.material, c.pinned, fmt::format("{}: at {}.mesh", file, c.path),
                  c.chen.solver);
    ClothPiece& piece = model.pieces.back();
    piece.garment = c.chen.garment;
    piece.wetByContact = c.chen.wetByContact;
    piece.dropsVanish = c.chen.dropsVanish;
    piece.panelOfVertex = c.panelOfVertex;
    piece.seams = c.seams;
  }
  buildTethers(model);
  buildGarmentPieces(model);  // Chen 2012 springs of the implicit pieces
}

// a Chen piece soaked at load: wet from t = 0; without Shao's wetting it holds delta m_dry at
// saturation 1 (counted as emitted water, so the ledger closes) unless its supply is unlimited
void wetPieceAtStart(const Model& model, int k, State& state) {
  const ClothPiece& piece = model.pieces[size_t(k)];
  const size_t first = size_t(piece.firstParticle), n = size_t(piece.particleCount);
  std::fill_n(state.clothWetStart.begin() + first, n, 0.0f);
  if (model.wetting.enabled || piece.garment.saturation.unlimitedSupply) return;
  for (size_t i = first; i < first + n; ++i) {
    state.clothWater[i] = waterCapacity(model.clothDryMass[i], piece.garment.saturation);
    state.clothSaturation[i] = 1.0f;
    state.ledger.emitted += state.clothWater[i];
  }
}

// the initial state: the cloth particles at rest (pinned ones immovable), the emitters' states, the
// wet-by-contact start times (0 for a piece wet from the start) and the wetting state
void initState(ErrorLog& log, const Model& model, const std::vector<ClothSpec>& cloth, State& state) {
  Particles& p = state.particles;
  for (size_t k = 0; k < model.pieces.size(); ++k) {
    const ClothPiece& piece = model.pieces[k];
    for (int i = piece.firstParticle; i < piece.firstParticle + piece.particleCount; ++i) {
      p.add(int32_t(k + 1), uint32_t(i), model.clothDryMass[size_t(i)], model.water.supportRadius,
            model.clothRestPosition[size_t(i)], Vec3::Zero());
      if (model.clothPinned[size_t(i)]) p.invMass.back() = 0.0f;
    }
  }
  state.nextId = uint32_t(model.numCloth);
  state.emitters.resize(model.emitters.size());
  for (const ClothPiece& piece : model.pieces)
    if (piece.wetByContact) state.clothWetStart.assign(size_t(model.numCloth), std::numeric_limits<float>::infinity());
  if (model.hasImplicitCloth()) state.clothVelocityChange.assign(size_t(model.numCloth), Vec3::Zero());
  if (!state.clothWetStart.empty() && !model.wetting.enabled) {  // Chen's saturation: water held, s per vertex
    state.clothWater.assign(size_t(model.numCloth), 0.0);
    state.clothBuffer.assign(size_t(model.numCloth), 0.0);
    state.clothSaturation.assign(size_t(model.numCloth), 0.0f);
  }
  for (size_t k = 0; k < cloth.size(); ++k)
    if (cloth[k].chen.wetAtStart && model.pieces[k].wetByContact) wetPieceAtStart(model, static_cast<int>(k), state);
  if (model.wetting.enabled) {
    const std::vector<float> volume = restVolumes(model, p.radius);
    checkDripThreshold(log, model, volume);
    log.throwIfAny();
    initWettingState(model, volume, state);
  }
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
  scene.name = top.name("name", fs::path(file).stem().string());
  scene.description = top.string("description", "");
  float maxMemoryGB = 0.0f;  // 0: the machine's available memory
  readSolver(top.object("solver"), model.solver, maxMemoryGB);
  readWater(top.object("water"), model.water);
  readOutput(top.object("output"), scene.output);
  readView(top.object("view"), scene.view);
  readWetting(top.object("wetting"), model.wetting);
  // the memory budget is known before any mesh is built: a rectangle's resolution is checked against it
  const ParticleLimit limit = particleLimit(model.solver.maxParticles, maxMemoryGB);
  Bodies bodies;  // mannequins by name, for the garments sewn around them
  for (auto& group : readArray<std::vector<Collider>>(top, "colliders", [&](const Json& v, const std::string& p, int i) {
         return readCollider(log, v, p, i, baseDir, bodies);
       }))
    for (Collider& c : group) model.colliders.push_back(std::move(c));
  const std::vector<ClothSpec> cloth = readArray<ClothSpec>(top, "cloth", [&](const Json& v, const std::string& p, int i) {
    return readCloth(log, v, p, i, baseDir, limit, model.wetting.enabled, bodies, model.colliders);
  });
  model.emitters = readArray<Emitter>(top, "emitters", [&](const Json& v, const std::string& p, int i) {
    return readEmitter(log, v, p, i, model.solver, model.water);
  });
  top.finish();
  checkSceneSize(log, top, cloth, model, scene.output, limit);
  checkClothClearOfColliders(log, cloth, model.colliders);
  log.throwIfAny();

  buildCloth(model, cloth, file);
  initState(log, model, cloth, scene.state);
  return scene;
}

}  // namespace

Scene loadSceneFromString(const std::string& text, const std::string& sourceName, const std::string& baseDir,
                          const std::vector<std::string>& overrides) {
  return buildScene(parseSceneJson(text, sourceName), sourceName, baseDir, overrides);
}

Scene loadScene(const std::string& path, const std::vector<std::string>& overrides) {
  const std::string text = readSceneText(path);
  const fs::path parent = fs::path(path).parent_path();
  return loadSceneFromString(text, path, parent.empty() ? fs::path(".").string() : parent.string(), overrides);
}

}  // namespace soak
