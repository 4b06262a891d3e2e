// one run folder's measurements for soak sweep's summary (run_summary.hpp)
#include <soak/error.hpp>
#include <soak/run_summary.hpp>

#include "io/file.hpp"
#include "render/run_output.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <sstream>

namespace soak {

namespace {

namespace fs = std::filesystem;

nlohmann::json parseFile(const std::string& path, const std::string& text) {
  nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) throw Error(path + ": expected a JSON object (soak's run record)");
  return j;
}

// the mean ms per step over every stats line, and the held water of the line of `frame`
void readStats(const std::string& path, int frame, RunSummary& s) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return;
  std::istringstream in(readTextFile(path));
  double ms = 0.0, steps = 0.0;
  int lineNo = 0;
  for (std::string line; std::getline(in, line);) {
    ++lineNo;
    if (line.empty()) continue;
    const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_discarded() || !j.is_object())
      throw Error(fmt::format("{}: at line {}: expected one JSON object per line", path, lineNo));
    const double n = j.value("steps", 0.0);
    if (n > 0.0 && j.contains("msPerStep") && j["msPerStep"].is_number()) {
      ms += j["msPerStep"].get<double>() * n;
      steps += n;
    }
    if (j.value("frame", -1) == frame && j.contains("waterMass") && j["waterMass"].is_object())
      s.heldWaterKg = j["waterMass"].value("heldInCloth", 0.0) + j["waterMass"].value("inBuffers", 0.0);
  }
  if (steps > 0.0) s.msPerStep = ms / steps;
}

// the wet share of the rest area and the largest edge strain of the cloth at `frame`
void measureCloth(const RunOutput& run, int frame, RunSummary& s) {
  const Model& m = run.scene.model;
  const ClothFrame c = readClothFrame(run, frame);
  if (c.x.size() != size_t(m.numCloth) || m.numCloth == 0) return;  // no cloth file for the frame
  double strain = -1.0;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      const double rest = (m.clothRestPosition[a] - m.clothRestPosition[b]).norm();
      if (rest > 0.0) strain = std::max(strain, (c.x[a] - c.x[b]).norm() / rest - 1.0);
    }
  if (strain > -1.0) s.maxClothStrain = strain;
  if (c.saturation.size() != c.x.size()) return;
  const float sMax = c.saturationMax > 0.0f ? c.saturationMax : m.wetting.saturationMax;
  double wet = 0.0, all = 0.0;
  for (size_t i = 0; i < c.x.size(); ++i) {
    all += m.clothRestArea[i];
    if (c.saturation[i] >= 0.1f * sMax) wet += m.clothRestArea[i];
  }
  if (all > 0.0) s.wetAreaFraction = wet / all;
}

}  // namespace

RunSummary runStatus(const std::string& dir) {
  RunSummary s;
  const std::string record = (fs::path(dir) / "run.json").string();
  std::error_code ec;
  if (!fs::exists(record, ec)) return s;
  const nlohmann::json j = parseFile(record, readTextFile(record));
  s.status = j.value("status", "missing");
  s.framesWritten = j.contains("framesWritten") && j["framesWritten"].is_number_integer() ? j["framesWritten"].get<int>() : 0;
  return s;
}

RunSummary summarizeRun(const std::string& dir) {
  RunSummary s = runStatus(dir);
  if (s.framesWritten <= 0) return s;
  s.frame = s.framesWritten - 1;
  readStats((fs::path(dir) / "stats.jsonl").string(), s.frame, s);
  const RunOutput run = openRunOutput(dir);
  if (std::find(run.frames.begin(), run.frames.end(), s.frame) != run.frames.end()) measureCloth(run, s.frame, s);
  return s;
}

}  // namespace soak
