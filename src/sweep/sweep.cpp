// SWEEP.json: the base scene, the values every variant shares and the swept ones (sweep.hpp)
#include <soak/error.hpp>
#include <soak/scene.hpp>
#include <soak/sweep.hpp>

#include "scene/limits.hpp"
#include "scene/overrides.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>

namespace soak {

namespace {

namespace fs = std::filesystem;
using Ordered = nlohmann::ordered_json;

constexpr size_t kMaxSweepBytes = size_t(1) << 20;

[[noreturn]] void fail(const std::string& file, const std::string& path, const std::string& what) {
  throw Error(path.empty() ? fmt::format("{}: {}", file, what) : fmt::format("{}: at {}: {}", file, path, what));
}

std::string kindOf(const Ordered& v) {
  if (v.is_object()) return "an object";
  if (v.is_array()) return "an array";
  if (v.is_string()) return "a string";
  if (v.is_boolean()) return "a boolean";
  if (v.is_number()) return "a number";
  return "null";
}

// a swept value: a number, a string, a boolean or a small array (a vector), as JSON text
std::string valueText(const std::string& file, const std::string& path, const Ordered& v) {
  if (v.is_object() || v.is_null()) fail(file, path, "expected a value (a number, string, boolean or array), got " + kindOf(v));
  return v.dump();
}

// {"from": a, "to": b, "count": n, "log": false}: n values from a to b, evenly or geometrically spaced
std::vector<std::string> rangeValues(const std::string& file, const std::string& path, const Ordered& r) {
  for (const auto& [k, v] : r.items())
    if (k != "from" && k != "to" && k != "count" && k != "log")
      fail(file, path + "." + k, "unknown key (known: from, to, count, log)");
  for (const char* k : {"from", "to"})
    if (!r.contains(k) || !r[k].is_number() || !std::isfinite(r[k].get<double>()))
      fail(file, path + "." + k, "expected a finite number");
  if (!r.contains("count") || !r["count"].is_number_integer() || r["count"].get<int64_t>() < 1 ||
      r["count"].get<int64_t>() > kMaxSweepVariants)
    fail(file, path + ".count", fmt::format("expected an integer in [1, {}]", kMaxSweepVariants));
  const bool log = r.value("log", false);
  if (r.contains("log") && !r["log"].is_boolean()) fail(file, path + ".log", "expected true or false");
  const double a = r["from"].get<double>(), b = r["to"].get<double>();
  const int n = static_cast<int>(r["count"].get<int64_t>());
  if (log && !(a > 0.0 && b > 0.0)) fail(file, path, "expected from > 0 and to > 0 with \"log\": true");
  std::vector<std::string> values;
  for (int i = 0; i < n; ++i) {
    const double t = n == 1 ? 0.0 : double(i) / double(n - 1);
    const double x = log ? a * std::pow(b / a, t) : a + (b - a) * t;
    values.push_back(Ordered(x).dump());
  }
  return values;
}

// "axes": every combination of the keys' values, the first key slowest
void readAxes(const std::string& file, const Ordered& axes, SweepSpec& spec) {
  if (!axes.is_object() || axes.empty()) fail(file, "axes", "expected an object of scene key -> values, got " + kindOf(axes));
  std::vector<std::vector<std::string>> values;
  size_t total = 1;
  for (const auto& [key, v] : axes.items()) {
    const std::string path = "axes." + key;
    std::vector<std::string> list;
    if (v.is_array()) {
      if (v.empty()) fail(file, path, "expected at least one value");
      for (size_t i = 0; i < v.size(); ++i) list.push_back(valueText(file, fmt::format("{}[{}]", path, i), v[i]));
    } else if (v.is_object()) {
      list = rangeValues(file, path, v);
    } else {
      fail(file, path, "expected a list of values or {\"from\", \"to\", \"count\"}, got " + kindOf(v));
    }
    total *= list.size();
    if (total > size_t(kMaxSweepVariants))
      fail(file, "axes", fmt::format("expected at most {} variants in all, got more", kMaxSweepVariants));
    spec.keys.push_back(key);
    values.push_back(std::move(list));
  }
  for (size_t n = 0; n < total; ++n) {
    SweepVariant variant;
    size_t rest = n;
    for (size_t k = values.size(); k-- > 0;) {
      variant.params.insert(variant.params.begin(), {spec.keys[k], values[k][rest % values[k].size()]});
      rest /= values[k].size();
    }
    spec.variants.push_back(std::move(variant));
  }
}

// "variants": a list of {key: value}, every one with the keys of the first
void readVariantList(const std::string& file, const Ordered& list, SweepSpec& spec) {
  if (!list.is_array() || list.empty()) fail(file, "variants", "expected a non-empty list of {key: value} objects");
  if (list.size() > size_t(kMaxSweepVariants))
    fail(file, "variants", fmt::format("expected at most {} variants, got {}", kMaxSweepVariants, list.size()));
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string path = fmt::format("variants[{}]", i);
    const Ordered& v = list[i];
    if (!v.is_object() || v.empty()) fail(file, path, "expected an object of scene key -> value, got " + kindOf(v));
    SweepVariant variant;
    for (const auto& [key, value] : v.items()) variant.params.emplace_back(key, valueText(file, path + "." + key, value));
    if (i == 0)
      for (const auto& p : variant.params) spec.keys.push_back(p.first);
    std::vector<std::string> keys;
    for (const auto& p : variant.params) keys.push_back(p.first);
    if (keys != spec.keys)
      fail(file, path, fmt::format("expected the keys of variants[0] ({}), in that order", fmt::join(spec.keys, ", ")));
    spec.variants.push_back(std::move(variant));
  }
}

// "contactSheet": {"frame", "columns", "width", "height", "particles"}, each optional
SweepSheet readSheet(const std::string& file, const Ordered& o) {
  if (!o.is_object()) fail(file, "contactSheet", "expected an object, got " + kindOf(o));
  SweepSheet sheet;
  const auto integer = [&](const char* key, int lo, int hi, int& out) {
    if (!o.contains(key)) return;
    if (!o[key].is_number_integer() || o[key].get<int64_t>() < lo || o[key].get<int64_t>() > hi)
      fail(file, std::string("contactSheet.") + key, fmt::format("expected an integer in [{}, {}]", lo, hi));
    out = static_cast<int>(o[key].get<int64_t>());
  };
  for (const auto& [k, v] : o.items())
    if (k != "frame" && k != "columns" && k != "width" && k != "height" && k != "particles")
      fail(file, "contactSheet." + k, "unknown key (known: frame, columns, width, height, particles)");
  integer("frame", -1, 100000000, sheet.frame);
  integer("columns", 0, kMaxSweepVariants, sheet.columns);
  integer("width", 16, 4096, sheet.width);
  integer("height", 16, 4096, sheet.height);
  if (o.contains("particles")) {
    if (!o["particles"].is_boolean()) fail(file, "contactSheet.particles", "expected true or false");
    sheet.particles = o["particles"].get<bool>();
  }
  return sheet;
}

}  // namespace

std::vector<std::string> SweepVariant::overrides() const {
  std::vector<std::string> out;
  for (const auto& [key, value] : params) out.push_back(key + "=" + value);
  return out;
}

std::string SweepVariant::label() const { return fmt::format("{}", fmt::join(overrides(), ", ")); }

SweepSpec loadSweep(const std::string& path) {
  const std::string text = readSceneText(path, kMaxSweepBytes);
  checkJsonText(text, path);
  parseSceneJson(text, path);  // syntax errors with line and column, keys repeated in an object
  const Ordered doc = Ordered::parse(text, nullptr, true, true);
  if (!doc.is_object()) fail(path, "", "expected a JSON object at the top level, got " + kindOf(doc));
  for (const auto& [k, v] : doc.items())
    if (k != "scene" && k != "set" && k != "frames" && k != "axes" && k != "variants" && k != "description" &&
        k != "contactSheet")
      fail(path, k, "unknown key (known: scene, set, frames, axes, variants, contactSheet, description)");
  SweepSpec spec;
  spec.file = path;
  if (!doc.contains("scene") || !doc["scene"].is_string() || doc["scene"].get<std::string>().empty())
    fail(path, "scene", "expected the base scene's path (a string, relative to this file's folder)");
  const fs::path scene = doc["scene"].get<std::string>();
  spec.scene = scene.is_absolute() ? scene.string() : (fs::path(path).parent_path() / scene).lexically_normal().string();
  if (doc.contains("set")) {
    const Ordered& set = doc["set"];
    if (!set.is_array()) fail(path, "set", "expected a list of \"key=value\" strings, got " + kindOf(set));
    for (size_t i = 0; i < set.size(); ++i) {
      if (!set[i].is_string() || set[i].get<std::string>().find('=') == std::string::npos ||
          set[i].get<std::string>().front() == '=')
        fail(path, fmt::format("set[{}]", i), "expected \"key=value\" (e.g. \"output.frames=20\")");
      spec.common.push_back(set[i].get<std::string>());
    }
  }
  if (doc.contains("frames")) {
    if (!doc["frames"].is_number_integer() || doc["frames"].get<int64_t>() < 0 || doc["frames"].get<int64_t>() > 100000000)
      fail(path, "frames", "expected an integer in [0, 100000000]");
    spec.frames = static_cast<int>(doc["frames"].get<int64_t>());
  }
  if (doc.contains("contactSheet")) spec.sheet = readSheet(path, doc["contactSheet"]);
  if (doc.contains("axes") == doc.contains("variants"))
    fail(path, "", "expected either \"axes\" (every combination) or \"variants\" (a list), not both or neither");
  if (doc.contains("axes")) readAxes(path, doc["axes"], spec);
  else readVariantList(path, doc["variants"], spec);
  const int digits = std::max(3, static_cast<int>(std::to_string(spec.variants.size() - 1).size()));
  for (size_t i = 0; i < spec.variants.size(); ++i) spec.variants[i].folder = fmt::format("v{:0{}}", i, digits);
  return spec;
}

void checkSweepVariants(const SweepSpec& spec, int only) {
  for (const SweepVariant& v : spec.variants) {
    if (only >= 0 && &v != &spec.variants[size_t(only)]) continue;
    std::vector<std::string> overrides = spec.common;
    for (const std::string& o : v.overrides()) overrides.push_back(o);
    try {
      loadScene(spec.scene, overrides);
    } catch (const Error& e) {
      throw Error(fmt::format("{}: variant {} ({}): {}", spec.file, v.folder, v.label(), e.what()));
    }
  }
}

}  // namespace soak
