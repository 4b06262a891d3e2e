// a run's output folder read back: scene.json, the frame files present, stats.jsonl times
#include "render/run_output.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <soak/error.hpp>
#include <sstream>

#include "io/file.hpp"
#include "io/ply.hpp"

namespace soak {

namespace {

namespace fs = std::filesystem;

// "123" -> 123; false for anything else
bool parseInt(const std::string& s, int& out) {
  if (s.empty()) return false;
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc() && p == s.data() + s.size() && out >= 0;
}

std::vector<int> findFrames(const std::string& dir) {
  static const std::regex frameFile(R"((cloth_(\d{4,})\.(obj|ply))|(water_(\d{4,})\.ply))");
  std::set<int> frames;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    std::smatch m;
    if (!std::regex_match(name, m, frameFile)) continue;
    int f = 0;
    if (parseInt(m[2].matched ? m[2].str() : m[5].str(), f)) frames.insert(f);
  }
  return {frames.begin(), frames.end()};
}

// run.json's count of complete frames (frames 0..n-1), -1 when it has none: the frame files are each
// renamed into place when complete, but a run that died between two renames, or a resume that has
// not yet replaced a later frame, can leave files that run.json does not count
int framesWritten(const std::string& dir) {
  const std::string path = (fs::path(dir) / "run.json").string();
  std::error_code ec;
  if (!fs::exists(path, ec)) return -1;
  const nlohmann::json j = nlohmann::json::parse(readTextFile(path), nullptr, false);
  if (!j.is_object() || !j.contains("framesWritten") || !j["framesWritten"].is_number_integer()) return -1;
  return j["framesWritten"].get<int>();
}

std::map<int, double> readStatsTimes(const std::string& path) {
  std::map<int, double> times;
  std::error_code ec;
  if (!fs::exists(path, ec)) return times;
  std::istringstream in(readTextFile(path));
  for (std::string line; std::getline(in, line);) {
    // a run that stopped may have left a half-written last line: skip what does not parse
    const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_object() && j.contains("frame") && j.contains("time") && j["frame"].is_number_integer() &&
        j["time"].is_number())
      times[j["frame"].get<int>()] = j["time"].get<double>();
  }
  return times;
}

Vec3 vecAt(const PlyElement& e, const char* a, const char* b, const char* c, size_t i) {
  return Vec3(static_cast<float>(e.scalar(a)[i]), static_cast<float>(e.scalar(b)[i]),
              static_cast<float>(e.scalar(c)[i]));
}

std::vector<std::array<int, 3>> plyTriangles(const PlyElement& faces, const std::string& path, size_t vertices) {
  std::vector<std::array<int, 3>> tris;
  const std::string prop = faces.has("vertex_indices") ? "vertex_indices" : "vertex_index";
  if (!faces.listStart.count(prop)) throw Error(path + ": element face has no list property vertex_indices");
  const std::vector<size_t>& start = faces.listStart.at(prop);
  const std::vector<int64_t>& v = faces.listValues.at(prop);
  for (size_t f = 0; f < faces.count; ++f) {
    const size_t n = start[f + 1] - start[f];
    // polygons are fanned into triangles
    for (size_t k = 1; k + 1 < n; ++k) {
      const std::array<int64_t, 3> t = {v[start[f]], v[start[f] + k], v[start[f] + k + 1]};
      for (int64_t id : t)
        if (id < 0 || static_cast<size_t>(id) >= vertices)
          throw Error(fmt::format("{}: face {} uses vertex {}, but there are {} vertices", path, f, id, vertices));
      tris.push_back({int(t[0]), int(t[1]), int(t[2])});
    }
  }
  return tris;
}

ClothFrame clothFromPly(const std::string& path) {
  const PlyData ply = readPly(path);
  const PlyElement& v = ply.element("vertex");
  ClothFrame c;
  c.x.resize(v.count);
  for (size_t i = 0; i < v.count; ++i) c.x[i] = vecAt(v, "x", "y", "z", i);
  c.normal.assign(v.count, Vec3::Zero());
  if (v.has("nx") && v.has("ny") && v.has("nz"))
    for (size_t i = 0; i < v.count; ++i) c.normal[i] = vecAt(v, "nx", "ny", "nz", i);
  if (v.has("saturation")) {
    const std::vector<double>& s = v.scalar("saturation");
    c.saturation.assign(s.begin(), s.end());
  } else if (v.has("wetness")) {  // Q(t) / delta of Chen 2012 pieces: 1 is fully wet
    const std::vector<double>& s = v.scalar("wetness");
    c.saturation.assign(s.begin(), s.end());
    c.saturationMax = 1.0f;
  }
  if (ply.has("face")) c.triangles = plyTriangles(ply.element("face"), path, v.count);
  return c;
}

// the OBJ the run writes: v x y z [r g b], vn, f a//a b//b c//c (docs/output-format.md)
ClothFrame clothFromObj(const std::string& path) {
  std::istringstream in(readTextFile(path));
  ClothFrame c;
  std::vector<Vec3> normals;
  bool colored = true;
  int lineNo = 0;
  for (std::string line; std::getline(in, line);) {
    ++lineNo;
    std::istringstream ls(line);
    std::string tag;
    ls >> tag;
    auto bad = [&](const std::string& what) { return errorAt(path, fmt::format("line {}", lineNo), what); };
    if (tag == "v") {
      float x, y, z, r, g, b;
      if (!(ls >> x >> y >> z)) throw bad("expected 'v x y z [r g b]'");
      c.x.emplace_back(x, y, z);
      if (ls >> r >> g >> b)
        c.color.emplace_back(r, g, b);
      else
        colored = false;
    } else if (tag == "vn") {
      float x, y, z;
      if (!(ls >> x >> y >> z)) throw bad("expected 'vn nx ny nz'");
      normals.emplace_back(x, y, z);
    } else if (tag == "f") {
      std::vector<int> ids;
      for (std::string tok; ls >> tok;) {
        int id = 0;
        const auto [p, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), id);
        if (ec != std::errc() || id == 0)
          throw bad("expected 'f a b c' with 1-based vertex indices, got '" + tok + "'");
        if (p == tok.data()) throw bad("bad face index '" + tok + "'");
        ids.push_back(id < 0 ? static_cast<int>(c.x.size()) + id : id - 1);
      }
      if (ids.size() < 3) throw bad("a face needs at least 3 vertices");
      for (int id : ids)
        if (id < 0 || static_cast<size_t>(id) >= c.x.size())
          throw bad(fmt::format("face vertex {} does not exist yet", id + 1));
      for (size_t k = 1; k + 1 < ids.size(); ++k) c.triangles.push_back({ids[0], ids[k], ids[k + 1]});
    }
  }
  c.normal = normals.size() == c.x.size() ? normals : std::vector<Vec3>(c.x.size(), Vec3::Zero());
  if (!colored || c.color.size() != c.x.size()) c.color.clear();
  return c;
}

}  // namespace

double RunOutput::timeOf(int frame) const {
  const auto it = statsTime.find(frame);
  if (it != statsTime.end()) return it->second;
  return static_cast<double>(frame) * scene.output.stepsPerFrame * scene.model.solver.dt;
}

std::string RunOutput::framePath(const std::string& prefix, int frame, const std::string& ext) const {
  return (fs::path(dir) / frameFileName(prefix, frame, ext)).string();
}

RunOutput openRunOutput(const std::string& dir) {
  std::error_code ec;
  if (!fs::exists(dir, ec))
    throw Error(dir + ": no such output folder (make one with `soak run SCENE -o " + dir + "`)");
  if (!fs::is_directory(dir, ec)) throw Error(dir + ": not a folder (expected the output folder of `soak run`)");
  const std::string scenePath = (fs::path(dir) / "scene.json").string();
  if (!fs::exists(scenePath, ec))
    throw Error(dir + ": not a soak output folder: scene.json is missing (make one with `soak run SCENE -o " + dir +
                "`)");
  RunOutput run;
  run.dir = dir;
  run.scene = loadScene(scenePath);
  run.frames = findFrames(dir);
  const bool anyFile = !run.frames.empty();
  if (const int n = framesWritten(dir); n >= 0) std::erase_if(run.frames, [n](int f) { return f >= n; });
  if (run.frames.empty() && anyFile)
    throw Error(dir + ": no complete frame yet (run.json counts " + std::to_string(framesWritten(dir)) + " frames written)");
  if (run.frames.empty())
    throw Error(dir + ": no frame files (cloth_NNNN.ply, cloth_NNNN.obj or water_NNNN.ply) in the output folder");
  run.statsTime = readStatsTimes((fs::path(dir) / "stats.jsonl").string());
  return run;
}

std::vector<int> selectFrames(const RunOutput& run, const std::string& range) {
  int lo = 0, hi = std::numeric_limits<int>::max();
  if (!range.empty()) {
    const size_t colon = range.find(':');
    bool ok = false;
    if (colon == std::string::npos) {
      ok = parseInt(range, lo);
      hi = lo;
    } else {
      const std::string a = range.substr(0, colon), b = range.substr(colon + 1);
      ok = (a.empty() || parseInt(a, lo)) && (b.empty() || parseInt(b, hi));
    }
    if (!ok)
      throw Error("--frames: expected A:B, A:, :B or A with frame numbers >= 0 (e.g. 0:100), got '" + range + "'");
    if (hi < lo) throw Error("--frames: '" + range + "' ends before it starts");
  }
  std::vector<int> out;
  for (int f : run.frames)
    if (f >= lo && f <= hi) out.push_back(f);
  if (out.empty())
    throw Error(fmt::format("{}: no frames in {} (the folder has frames {}..{})", run.dir, range, run.frames.front(),
                            run.frames.back()));
  return out;
}

ClothFrame readClothFrame(const RunOutput& run, int frame) {
  std::error_code ec;
  const std::string ply = run.framePath("cloth", frame, "ply");
  if (fs::exists(ply, ec)) return clothFromPly(ply);
  const std::string obj = run.framePath("cloth", frame, "obj");
  if (fs::exists(obj, ec)) return clothFromObj(obj);
  return {};
}

WaterFrame readWaterFrame(const RunOutput& run, int frame) {
  std::error_code ec;
  const std::string path = run.framePath("water", frame, "ply");
  WaterFrame w;
  if (!fs::exists(path, ec)) return w;
  const PlyData ply = readPly(path);
  const PlyElement& v = ply.element("vertex");
  w.x.resize(v.count);
  for (size_t i = 0; i < v.count; ++i) w.x[i] = vecAt(v, "x", "y", "z", i);
  const float mass = run.scene.model.water.particleMass, h = run.scene.model.water.supportRadius;
  w.mass.assign(v.count, mass);
  w.radius.assign(v.count, h);
  if (v.has("mass"))
    std::transform(v.scalar("mass").begin(), v.scalar("mass").end(), w.mass.begin(), [](double m) { return float(m); });
  if (v.has("radius"))
    std::transform(v.scalar("radius").begin(), v.scalar("radius").end(), w.radius.begin(),
                   [](double r) { return float(r); });
  return w;
}

}  // namespace soak
