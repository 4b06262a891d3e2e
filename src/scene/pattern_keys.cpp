// "type": "pattern" cloth meshes: the pattern's JSON (inline or a file) into a SewingPattern, sewn
#include "scene/pattern_keys.hpp"

#include <soak/error.hpp>

#include "scene/common.hpp"
#include "scene/overrides.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>

namespace soak {

const std::vector<std::string> kPatternMeshKeys = {"pattern", "path", "body", "edgeLength"};

namespace {

constexpr double kDegree = 3.14159265358979323846 / 180.0;

// "outline": [[u, v], ...] in metres
std::vector<Vec2d> readOutline(ObjectReader& r, int& corners) {
  std::vector<Vec2d> out;
  const Json* o = r.array("outline");
  if (!o) {
    if (!r.has("outline")) r.log().error(r.pathOf("outline"), "expected the panel's corners [[u, v], ...] (m), got none");
    return out;
  }
  corners += static_cast<int>(o->size());
  if (corners > kMaxPatternCorners) {
    r.log().error(r.pathOf("outline"), fmt::format("expected at most {} corners in all panels, got more", kMaxPatternCorners));
    return {};
  }
  for (size_t k = 0; k < o->size(); ++k) {
    const Json& c = (*o)[k];
    const std::string where = indexPath(r.pathOf("outline"), k);
    if (!c.is_array() || c.size() != 2) {
      r.log().expected(where, "a corner [u, v] (m)", c);
      continue;
    }
    const auto u = readNumber(r.log(), c[0], indexPath(where, 0), Range::any(), false);
    const auto v = readNumber(r.log(), c[1], indexPath(where, 1), Range::any(), false);
    if (u && v) out.emplace_back(*u, *v);
  }
  return out;
}

PatternPanel readPanel(ObjectReader r, int& corners) {
  PatternPanel p;
  p.name = r.name("name", std::nullopt);
  p.outline = readOutline(r, corners);
  p.origin = r.vec3("origin", Vec3::Zero()).cast<double>();
  p.yaw = r.number("yaw", 0.0f, Range::between(-360.0, 360.0)) * kDegree;
  p.bend = r.number("bend", 0.0f, Range::nonNegative());
  r.finish();
  return p;
}

// a seam's side {"panel": name, "from": corner, "to": corner}
PatternEdge readSide(ObjectReader r, const std::vector<PatternPanel>& panels) {
  PatternEdge e;
  const std::string name = r.string("panel", std::nullopt);
  e.from = r.integer("from", std::nullopt, Range::nonNegative());
  e.to = r.integer("to", std::nullopt, Range::nonNegative());
  r.finish();
  e.panel = -1;
  std::vector<std::string> names;
  for (size_t i = 0; i < panels.size(); ++i) {
    names.push_back(panels[i].name);
    if (panels[i].name == name) e.panel = static_cast<int>(i);
  }
  if (e.panel < 0 && r.present())
    r.log().error(r.pathOf("panel"), fmt::format("expected the name of a panel ({}), got \"{}\"", fmt::join(names, ", "), name));
  return e;
}

// the pattern object: "panels", "seams" (and "name", "description", free text)
std::optional<SewingPattern> readPattern(ObjectReader r) {
  ErrorLog& log = r.log();
  const size_t errorsBefore = log.messages().size();
  SewingPattern s;
  r.string("name", std::string());
  r.string("description", std::string());
  const Json* panels = r.array("panels");
  if (!panels || panels->empty()) log.error(r.pathOf("panels"), "expected an array of at least one panel");
  else if (panels->size() > size_t(kMaxPatternPanels))
    log.error(r.pathOf("panels"), fmt::format("expected at most {} panels, got {}", kMaxPatternPanels, panels->size()));
  else {
    int corners = 0;
    for (size_t i = 0; i < panels->size(); ++i)
      s.panels.push_back(readPanel(ObjectReader(log, &(*panels)[i], indexPath(r.pathOf("panels"), i)), corners));
  }
  const Json* seams = r.array("seams");
  if (seams && seams->size() > size_t(kMaxPatternSeams))
    log.error(r.pathOf("seams"), fmt::format("expected at most {} seams, got {}", kMaxPatternSeams, seams->size()));
  else if (seams && log.messages().size() == errorsBefore)
    for (size_t i = 0; i < seams->size(); ++i) {
      ObjectReader sr(log, &(*seams)[i], indexPath(r.pathOf("seams"), i));
      PatternSeam seam;
      seam.a = readSide(sr.object("a", true), s.panels);
      seam.b = readSide(sr.object("b", true), s.panels);
      seam.reverse = sr.boolean("reverse", false);
      sr.finish();
      s.seams.push_back(seam);
    }
  r.finish();
  if (log.messages().size() != errorsBefore) return std::nullopt;
  return s;
}

// the pattern of the mesh entry, inline or from its file; errors of a file go to a log of that file
// and are copied into the scene's
std::optional<SewingPattern> loadPattern(ObjectReader& m, const std::string& baseDir, std::string& source) {
  ErrorLog& log = m.log();
  if (m.has("pattern") == m.has("path")) {
    log.error(m.path(), "expected either \"pattern\" (the pattern inline) or \"path\" (a pattern file), got " +
                            std::string(m.has("pattern") ? "both" : "neither"));
    return std::nullopt;
  }
  if (m.has("pattern")) {
    source = log.file() + ": at " + m.pathOf("pattern");
    return readPattern(m.object("pattern", true));
  }
  const std::string file = resolvePath(m.string("path", std::nullopt), baseDir);
  source = file + ": at ";
  try {
    const Json doc = parseSceneJson(readSceneText(file), file);
    ErrorLog fileLog(file);
    std::optional<SewingPattern> s = readPattern(ObjectReader(fileLog, &doc, ""));
    for (const std::string& msg : fileLog.messages()) log.add(msg);
    return s;
  } catch (const Error& e) {
    log.error(m.pathOf("path"), fmt::format("expected a readable pattern file: {}", e.what()));
    return std::nullopt;
  }
}

}  // namespace

std::optional<SewnGarment> readPatternMesh(ObjectReader& m, const std::string& baseDir, const Bodies& bodies,
                                           const ParticleLimit& limit) {
  ErrorLog& log = m.log();
  const size_t errorsBefore = log.messages().size();
  const double edgeLength = m.number("edgeLength", 0.02f, Range::atLeast(kMinGarmentEdgeLength));
  const std::string body = m.string("body", std::string());
  const auto it = bodies.find(body);
  if (!body.empty() && it == bodies.end())
    log.error(m.pathOf("body"), fmt::format("expected the name of a mannequin collider, got \"{}\"", body));
  std::string source;
  const std::optional<SewingPattern> pattern = loadPattern(m, baseDir, source);
  if (!pattern || log.messages().size() != errorsBefore) return std::nullopt;
  const double estimate = estimatedPatternVertices(*pattern, edgeLength);
  if (estimate > 0.8 * limit.count) {  // the mesher's count is within 15% of the estimate
    log.error(m.pathOf("edgeLength"), fmt::format("expected at most {} vertices ({}), got about {:.0f} at an edge "
                                                  "length of {} m",
                                                  limit.count, limit.why, estimate, edgeLength));
    return std::nullopt;
  }
  try {
    SewnGarment g = sewPattern(*pattern, edgeLength, source);
    if (it != bodies.end()) {  // the pattern is placed relative to the body's origin and facing
      const MannequinParams& b = it->second.params;
      const Eigen::AngleAxisf turn(b.yaw, Vec3::UnitY());
      for (Vec3& x : g.mesh.vertices) x = b.position + turn * x;
    }
    return g;
  } catch (const Error& e) {
    log.add(e.what());
    return std::nullopt;
  }
}

}  // namespace soak
