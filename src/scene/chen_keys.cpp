// scene keys of the Chen 2012 models (chen_keys.hpp, docs/scene-format.md "Garments")
#include "scene/chen_keys.hpp"

#include <soak/error.hpp>

#include "garment/implicit.hpp"
#include "garment/saturation_mass.hpp"
#include "scene/common.hpp"
#include "scene/limits.hpp"
#include "world/garment_mesh.hpp"
#include "world/mesh_sdf.hpp"
#include "world/mesh_sequence.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace soak {

namespace {

constexpr float kDeg = kPi / 180.0f;

std::string joinNames(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += fmt::format("{}{}", s.empty() ? "" : ", ", n);
  return s;
}

// joint angles in degrees, [left, right]
MannequinPose readMannequinPose(ObjectReader r) {
  MannequinPose pose;
  auto pair = [&](const char* key, std::array<float, 2>& out) {
    const std::vector<float> v = r.numbers(key, 2, std::vector<float>{0.0f, 0.0f}, Range::between(-180.0, 180.0));
    if (v.size() == 2) out = {v[0] * kDeg, v[1] * kDeg};
  };
  pair("shoulderAbduction", pose.shoulderAbduction);
  pair("shoulderFlexion", pose.shoulderFlexion);
  pair("elbowFlexion", pose.elbowFlexion);
  pair("hipFlexion", pose.hipFlexion);
  pair("kneeFlexion", pose.kneeFlexion);
  pose.rootOffset = r.vec3("rootOffset", Vec3::Zero());
  r.finish();
  return pose;
}

void readProportions(ObjectReader r, MannequinParams& m) {
  const MannequinParams d;
  const std::pair<const char*, float MannequinParams::*> keys[] = {
      {"shoulderWidth", &MannequinParams::shoulderWidth}, {"hipWidth", &MannequinParams::hipWidth},
      {"chestWidth", &MannequinParams::chestWidth},       {"chestDepth", &MannequinParams::chestDepth},
      {"waistWidth", &MannequinParams::waistWidth},       {"headRadius", &MannequinParams::headRadius},
      {"neckRadius", &MannequinParams::neckRadius},       {"upperArmRadius", &MannequinParams::upperArmRadius},
      {"forearmRadius", &MannequinParams::forearmRadius}, {"handRadius", &MannequinParams::handRadius},
      {"thighRadius", &MannequinParams::thighRadius},     {"shankRadius", &MannequinParams::shankRadius},
      {"footRadius", &MannequinParams::footRadius}};
  for (const auto& [key, member] : keys) m.*member = r.number(key, d.*member, Range{0.0, 1.0, true, false});
  r.finish();
}

KesLaw readLaw(ObjectReader r, const KesLaw& d) {
  KesLaw law;
  law.a1 = r.number("a1", d.a1, Range::positive());
  law.a2 = r.number("a2", d.a2, Range::nonNegative());
  r.finish();
  return law;
}

void readGarmentSolver(ObjectReader r, GarmentParams& g) {
  const GarmentParams d;
  ErrorLog& log = r.log();
  g.laws.stretch = readLaw(r.object("stretch"), d.laws.stretch);
  g.laws.shear = readLaw(r.object("shear"), d.laws.shear);
  g.laws.bend = readLaw(r.object("bend"), d.laws.bend);
  g.laws.strainLimit = r.number("strainLimit", d.laws.strainLimit, Range{0.0, 1.0, true, true});
  g.build.bendStraightness = r.number("bendStraightness", d.build.bendStraightness, Range::unit());
  ObjectReader f = r.object("friction");
  g.friction.dry = f.number("dry", d.friction.dry, Range::nonNegative());
  g.friction.peak = f.number("peak", d.friction.peak, Range::nonNegative());
  g.friction.plateau = f.number("plateau", d.friction.plateau, Range::nonNegative());
  g.friction.peakSaturation = f.number("peakSaturation", d.friction.peakSaturation, Range{0.0, 1.0, true, true});
  g.friction.plateauSaturation =
      f.number("plateauSaturation", d.friction.plateauSaturation, Range{0.0, 1.0, true, false});
  for (const char* key : {"tau1", "tau2", "timeScale"})  // a curve over time: this one follows the saturation
    if (f.has(key))
      log.error(f.pathOf(key), "expected no times: the friction curve follows the saturation (give peakSaturation "
                               "and plateauSaturation in (0, 1]; docs/scene-format.md)");
  f.finish();
  if (!(g.friction.plateauSaturation > g.friction.peakSaturation))
    log.error(f.pathOf("plateauSaturation"), fmt::format("expected a saturation > friction.peakSaturation ({}), got {}",
                                                         g.friction.peakSaturation, g.friction.plateauSaturation));
  ObjectReader ray = r.object("rayleigh");
  if (const Json* a = ray.get("alpha"); a && a->is_number() && a->get<double>() < 0.0)
    log.error(ray.pathOf("alpha"), fmt::format("expected a number >= 0 (1/s; a negative alpha adds energy: the "
                                               "paper's -9 is a typo, docs/garment.md), got {}",
                                               a->get<double>()));
  else
    g.rayleighAlpha = ray.number("alpha", d.rayleighAlpha, Range::nonNegative());
  g.rayleighBeta = ray.number("beta", d.rayleighBeta, Range::nonNegative());
  ray.finish();
  g.edgeContact = r.boolean("edgeContact", d.edgeContact);
  g.strainLimiting = r.boolean("strainLimiting", d.strainLimiting);
  ObjectReader seams = r.object("seams");  // a sewn garment's (pattern meshes)
  g.seams.closeTime = seams.number("closeTime", d.seams.closeTime, Range::nonNegative());
  g.laws.seamStiffness = seams.number("stiffness", g.laws.stretch.a1, Range::positive());  // N/m; an edge's
  g.seams.gravityWhileClosing = seams.boolean("gravityWhileClosing", d.seams.gravityWhileClosing);
  g.seams.settleTime = seams.number("settleTime", d.seams.settleTime, Range::nonNegative());
  seams.finish();
  ObjectReader cg = r.object("cg");
  g.cgTolerance = cg.number("tolerance", d.cgTolerance, Range::positive());
  g.cgMaxIterations = cg.integer("maxIterations", d.cgMaxIterations, Range::between(1, kMaxCgIterations));
  g.cgPreconditioner = static_cast<CgPreconditioner>(
      cg.choice("preconditioner", {"blockJacobi", "cholesky", "multigrid", "gaussSeidel"}, std::string("blockJacobi")));
  g.cgWarmStart = cg.boolean("warmStart", d.cgWarmStart);
  cg.finish();
  ObjectReader w = r.object("wrinkles");
  g.wrinkles.enabled = w.boolean("enabled", w.present());
  g.wrinkles.compressionThreshold =
      w.number("compressionThreshold", d.wrinkles.compressionThreshold, Range{0.0, 1.0, true, true});
  g.wrinkles.equilibriumSpeed = w.number("equilibriumSpeed", d.wrinkles.equilibriumSpeed, Range::nonNegative());
  g.wrinkles.interval = w.integer("interval", d.wrinkles.interval, Range::atLeast(1));
  g.wrinkles.patchSize = w.integer("patchSize", d.wrinkles.patchSize, Range::atLeast(3));
  g.wrinkles.tieTolerance = w.number("tieTolerance", d.wrinkles.tieTolerance, Range::nonNegative());
  g.wrinkles.strength = w.number("strength", d.wrinkles.strength, Range{0.0, 1.0, true, false});
  g.wrinkles.dryStrength = w.number("dryStrength", d.wrinkles.dryStrength, Range::unit());
  if (g.wrinkles.dryStrength > g.wrinkles.strength)
    log.error(w.pathOf("dryStrength"), fmt::format("expected a fraction <= wrinkles.strength ({}), got {}",
                                                   g.wrinkles.strength, g.wrinkles.dryStrength));
  g.wrinkles.seed = static_cast<uint32_t>(w.integer("seed", int(d.wrinkles.seed), Range::atLeast(0)));
  w.finish();
  r.finish();
}

}  // namespace

std::vector<Collider> readMannequin(ObjectReader& r, const std::string& name, Bodies& bodies) {
  ErrorLog& log = r.log();
  const size_t errorsBefore = log.messages().size();
  MannequinParams m;
  const MannequinParams d;
  m.height = r.number("height", d.height, Range{0.0, kMaxMannequinHeight, true, false});
  m.position = r.vec3("position", d.position);
  m.yaw = r.number("yaw", 0.0f) * kDeg;
  const float friction = r.number("friction", 0.5f, Range::unit());
  readProportions(r.object("proportions"), m);
  if (r.has("pose") && r.has("keyframes"))
    log.error(r.pathOf("keyframes"), "expected either pose or keyframes, got both");
  m.pose = readMannequinPose(r.object("pose"));
  const std::vector<PoseKey> keys =
      readKeyframes<PoseKey>(r, "a pose keyframe: time, pose", [](ObjectReader& k, PoseKey& key) {
        key.pose = readMannequinPose(k.object("pose"));
      });
  m.sampleInterval = r.number("sampleInterval", d.sampleInterval, Range::positive());
  m.blend = r.number("blend", d.blend, Range::between(0.0, 0.1));
  r.finish({"normal", "halfExtents", "wallThickness", "radius", "halfHeight", "path", "resolution", "padding",
            "restitution", "rotation"},
           "a mannequin collider");
  if (log.messages().size() != errorsBefore) return {};
  try {
    std::vector<Collider> cols = mannequinColliders(m, keys, friction, name, r.path());
    bodies[name] = BodySpec{m, keys, cols};
    return cols;
  } catch (const Error& e) {
    log.error(r.path(), e.what());
    return {};
  }
}

bool readMeshColliderShape(ObjectReader& r, Collider& c, const std::string& baseDir) {
  ErrorLog& log = r.log();
  const size_t errorsBefore = log.messages().size();
  const std::string file = r.string("path", std::nullopt);
  const float cell = r.number("resolution", 0.01f, Range::positive());
  const float padding = r.number("padding", 3.0f * cell, Range::nonNegative());
  if (log.messages().size() != errorsBefore) return false;
  const std::string resolved = resolvePath(file, baseDir);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(resolved, ec)) {
    log.error(r.pathOf("path"),
              fmt::format("expected the path of an existing OBJ file, got \"{}\" (tried \"{}\")", file, resolved));
    return false;
  }
  try {
    const Collider m = loadMeshCollider(c.name, resolved, cell, padding);
    c.shape = ColliderShape::Mesh;
    c.sdf = m.sdf;
    return true;
  } catch (const Error& e) {
    log.error(r.pathOf("path"), e.what());
    return false;
  }
}

bool readMeshSequenceShape(ObjectReader& r, Collider& c, const std::string& baseDir) {
  ErrorLog& log = r.log();
  const size_t errorsBefore = log.messages().size();
  const std::string pattern = r.string("path", std::nullopt);
  const float fps = r.number("fps", std::nullopt, Range::positive());
  const float start = r.number("start", 0.0f, Range::any());
  const float scale = r.number("scale", 1.0f, Range::positive());
  const int first = r.has("firstFrame") ? r.integer("firstFrame", std::nullopt, Range::between(0, 999999999)) : -1;
  const int last = r.has("lastFrame") ? r.integer("lastFrame", std::nullopt, Range::between(0, 999999999)) : -1;
  if (first >= 0 && last >= 0 && last < first)
    log.error(r.pathOf("lastFrame"), fmt::format("expected a frame >= firstFrame ({}), got {}", first, last));
  if (log.messages().size() != errorsBefore) return false;
  try {
    const std::vector<std::string> files = meshSequenceFiles(resolvePath(pattern, baseDir), first, last, nullptr);
    c.shape = ColliderShape::MeshSequence;
    c.sequence = std::make_shared<const MeshSequence>(loadMeshSequence(files, fps, start, scale));
    return true;
  } catch (const Error& e) {
    log.error(r.pathOf("path"), e.what());
    return false;
  }
}

void readRain(ObjectReader& r, Emitter& e) {
  const Emitter d;
  e.origin = r.vec3("origin", std::nullopt);
  const std::vector<float> half = r.numbers("halfExtents", 2, std::nullopt, Range::positive());
  if (half.size() == 2) e.halfExtents = Vec3(half[0], 0.0f, half[1]);
  e.rate = r.number("rate", d.rate, Range::positive());
  e.dropSpeed = r.number("dropSpeed", d.dropSpeed, Range::nonNegative());
  e.dropRadius = r.number("dropRadius", d.dropRadius, Range::nonNegative());
  e.direction = r.unitVec3("direction", d.direction);
  e.start = r.number("start", d.start, Range::nonNegative());
  e.end = r.number("end", d.end, Range::positive());
  if (r.has("end") && !(e.end > e.start))
    r.log().error(r.pathOf("end"), fmt::format("expected a time > start ({} s), got {}", e.start, e.end));
}

const std::vector<std::string> kGarmentMeshKeys = {"style", "body",         "edgeLength",  "margin", "ease",
                                                   "hem",   "sleeveLength", "neckOpening", "flare"};

std::optional<TriangleMesh> readGarmentMesh(ObjectReader& r, const Bodies& bodies, std::vector<int>& panelOfVertex) {
  ErrorLog& log = r.log();
  const size_t errorsBefore = log.messages().size();
  GarmentPattern g;
  const GarmentPattern d;
  const int style = r.choice("style", {"tshirt", "dress"}, std::string("tshirt"));
  g.style = style == 1 ? GarmentStyle::Dress : GarmentStyle::TShirt;
  const std::string body = r.string("body", std::nullopt);
  // the lattice has about (body size / edgeLength)^2 vertices: bounded before it is built
  g.edgeLength = r.number("edgeLength", d.edgeLength, Range::atLeast(kMinGarmentEdgeLength));
  g.margin = r.number("margin", d.margin, Range::nonNegative());
  g.ease = r.number("ease", d.ease, Range::nonNegative());
  g.hem = r.number("hem", d.hem, Range{0.0, 1.0, false, true});
  g.sleeveLength = r.number("sleeveLength", d.sleeveLength, Range{0.0, 1.0, true, false});
  g.neckOpening = r.number("neckOpening", d.neckOpening, Range::nonNegative());
  g.flare = r.number("flare", d.flare / kDeg, Range::between(0.0, 60.0)) * kDeg;
  const auto it = bodies.find(body);
  if (r.has("body") && it == bodies.end()) {
    std::vector<std::string> names;
    for (const auto& [n, b] : bodies) names.push_back(n);
    log.error(r.pathOf("body"), fmt::format("expected the name of a mannequin collider ({}), got \"{}\"",
                                            names.empty() ? "the scene has none" : "known: " + joinNames(names), body));
  }
  if (log.messages().size() != errorsBefore || it == bodies.end()) return std::nullopt;
  // the lattice spans the body: at most about 1000 edges along its height
  if (double(g.edgeLength) < double(it->second.params.height) / kMaxGarmentEdgesPerHeight) {
    log.error(r.pathOf("edgeLength"),
              fmt::format("expected a number >= the mannequin's height / {:g} = {:.4g} m, got {}", kMaxGarmentEdgesPerHeight,
                          double(it->second.params.height) / kMaxGarmentEdgesPerHeight, g.edgeLength));
    return std::nullopt;
  }
  try {
    const BodySpec& b = it->second;
    Garment garment = buildGarment(b.params, poseAt(b.params, b.keys, 0.0), g, r.path());
    panelOfVertex = garment.panelOfVertex;
    return garment.mesh;
  } catch (const Error& e) {
    log.error(r.path(), e.what());
    return std::nullopt;
  }
}

ClothSolver readClothSolver(ObjectReader& r) {
  return r.choice("solver", {"pbd", "implicit"}, std::string("pbd")) == 1 ? ClothSolver::Implicit : ClothSolver::Pbd;
}

ChenClothSpec readChenCloth(ObjectReader& r, ClothSolver solver, bool shaoWetting) {
  ErrorLog& log = r.log();
  ChenClothSpec spec;
  spec.solver = solver;
  const bool implicit = solver == ClothSolver::Implicit;
  GarmentParams& g = spec.garment;
  const int fabric = r.choice("fabric", saturationPresetNames(), std::string("cotton"));
  if (fabric >= 0) g.saturation = saturationPreset(saturationPresetNames()[size_t(fabric)]);
  ObjectReader s = r.object("saturation");
  const bool enabled = s.boolean("enabled", implicit && !shaoWetting);
  g.saturation.delta = s.number("delta", g.saturation.delta, Range::nonNegative());
  g.saturation.a3 = s.number("a3", g.saturation.a3, Range::positive());
  g.saturation.timeScale = s.number("timeScale", g.saturation.timeScale, Range::positive());
  g.saturation.unlimitedSupply = s.choice("supply", {"drops", "unlimited"}, std::string("drops")) == 1;
  spec.dropsVanish = s.boolean("dropsVanish", true);
  if (!g.saturation.unlimitedSupply && !spec.dropsVanish)
    log.error(s.pathOf("dropsVanish"), "expected true, or saturation.supply \"unlimited\" (with the drops supply "
                                       "the fabric takes the water particles that reach it)");
  spec.wetAtStart = s.boolean("wetAtStart", false);
  s.finish();
  if (enabled && shaoWetting)
    log.error(s.pathOf("enabled"), "expected false while the wetting section is on (Shao 2017's absorption already "
                                   "adds the water's mass; Chen 2012's Eq. 15-19 would overwrite it), got true");
  if (shaoWetting && s.has("dropsVanish"))
    log.error(s.pathOf("dropsVanish"), "expected no dropsVanish while the wetting section is on (Shao 2017's "
                                       "absorption takes the water particles in)");
  g.saturationMass = enabled;
  spec.wetByContact = implicit || enabled;
  ObjectReader gr = r.object("garment");
  if (gr.present() && !implicit)
    log.error(gr.path(), "expected no garment section on a piece solved by PBD (it configures the implicit "
                         "solver: add \"solver\": \"implicit\")");
  readGarmentSolver(gr, g);
  ObjectReader b = r.object("body");
  if (b.present()) {
    spec.body = b.string("name", std::nullopt);
    spec.bodyMargin = b.number("margin", -1.0f, Range::nonNegative());
    spec.pushOut = b.boolean("pushOut", true);
  }
  b.finish();
  return spec;
}

void checkOutsideBody(ErrorLog& log, const std::string& path, const ChenClothSpec& spec, const Bodies& bodies,
                      const std::vector<Collider>& colliders, TriangleMesh& mesh) {
  if (spec.body.empty()) return;
  std::vector<Collider> body;
  if (const auto it = bodies.find(spec.body); it != bodies.end()) {
    body = it->second.colliders;
  } else {
    for (const Collider& c : colliders)
      if (c.name == spec.body) body.push_back(c);
  }
  if (body.empty()) {
    std::vector<std::string> names;
    for (const auto& [n, b] : bodies) names.push_back(n);
    for (const Collider& c : colliders)
      if (c.name.find('.') == std::string::npos || !bodies.count(c.name.substr(0, c.name.find('.'))))
        names.push_back(c.name);
    log.error(joinPath(path, "body.name"),
              fmt::format("expected the name of a collider or mannequin (known: {}), got \"{}\"",
                          names.empty() ? "none" : joinNames(names), spec.body));
    return;
  }
  const float margin = spec.bodyMargin;
  std::vector<int> inside;
  if (spec.pushOut) {
    if (pushOutOfBody(mesh, body, 0.0, margin) > 0) inside = verticesInsideBody(mesh, body, 0.0, margin);
  } else {
    inside = verticesInsideBody(mesh, body, 0.0, margin);
  }
  if (inside.empty()) return;
  std::string list;
  for (size_t k = 0; k < std::min<size_t>(inside.size(), 12); ++k) list += fmt::format("{}{}", k ? ", " : "", inside[k]);
  if (inside.size() > 12) list += fmt::format(" and {} more", inside.size() - 12);
  log.error(joinPath(path, "mesh"),
            fmt::format("expected every vertex at least {} m outside \"{}\" at t = 0, got {} vertices inside{}: {}",
                        margin, spec.body, inside.size(), spec.pushOut ? " even after pushing them out" : "", list));
}

}  // namespace soak
