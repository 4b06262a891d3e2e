#include "scene/reader.hpp"

#include "scene/limits.hpp"

#include <soak/error.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cfloat>
#include <climits>
#include <cmath>

namespace soak {

namespace {

std::string formatNumber(double v) { return fmt::format("{}", v); }

// " > 0", " in [0, 1]", "" for an unbounded range
std::string describeBound(const Range& r) {
  const bool hasLo = r.lo > -1e299, hasHi = r.hi < 1e299;
  if (hasLo && hasHi)
    return fmt::format(" in {}{}, {}{}", r.loOpen ? "(" : "[", formatNumber(r.lo), formatNumber(r.hi),
                       r.hiOpen ? ")" : "]");
  if (hasLo) return fmt::format(" {} {}", r.loOpen ? ">" : ">=", formatNumber(r.lo));
  if (hasHi) return fmt::format(" {} {}", r.hiOpen ? "<" : "<=", formatNumber(r.hi));
  return "";
}

std::string joinList(const std::vector<std::string>& items) {
  std::string s;
  for (size_t i = 0; i < items.size(); ++i) s += (i ? ", " : "") + items[i];
  return s;
}

// Levenshtein distance, for "did you mean" hints on misspelt keys
size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diag = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      const size_t same = std::tolower((unsigned char)a[i - 1]) == std::tolower((unsigned char)b[j - 1]) ? 0 : 1;
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + same});
      diag = up;
    }
  }
  return row[b.size()];
}

}  // namespace

bool Range::contains(double v) const {
  if (loOpen ? !(v > lo) : !(v >= lo)) return false;
  if (hiOpen ? !(v < hi) : !(v <= hi)) return false;
  return true;
}

std::string Range::describe(bool integer) const {
  return std::string(integer ? "an integer" : "a number") + describeBound(*this);
}

std::string describeJson(const Json& v) {
  if (v.is_string()) {
    std::string s = v.get<std::string>();
    if (s.size() > 40) s = s.substr(0, 37) + "...";
    // control characters shown as \xNN: a message must not carry a newline or a terminal escape
    std::string shown;
    for (const char c : s)
      shown += static_cast<unsigned char>(c) < 0x20 || c == 0x7f ? fmt::format("\\x{:02x}", static_cast<unsigned char>(c))
                                                                   : std::string(1, c);
    return "the string \"" + shown + "\"";
  }
  if (v.is_object()) return v.empty() ? "an empty object" : "an object";
  // dumped only when small: a long array is not printed whole, and invalid UTF-8 (a string given
  // by an override) is replaced instead of throwing
  if (v.is_array()) {
    const bool small = v.size() <= 8 && std::all_of(v.begin(), v.end(), [](const Json& e) { return e.is_primitive(); });
    const std::string d = small ? v.dump(-1, ' ', false, Json::error_handler_t::replace) : std::string();
    if (!d.empty() && d.size() <= 40) return d;
    return fmt::format("an array of {} elements", v.size());
  }
  return v.dump(-1, ' ', false, Json::error_handler_t::replace);  // null, true, false, numbers
}

std::string joinPath(const std::string& parent, const std::string& key) {
  return parent.empty() ? key : parent + "." + key;
}

std::string indexPath(const std::string& parent, size_t index) { return fmt::format("{}[{}]", parent, index); }

void ErrorLog::error(const std::string& path, const std::string& what) {
  messages_.push_back(errorAt(file_, path.empty() ? "(top level)" : path, what).what());
}

void ErrorLog::expected(const std::string& path, const std::string& expected, const Json& got) {
  error(path, "expected " + expected + ", got " + describeJson(got));
}

void ErrorLog::throwIfAny() const {
  if (messages_.empty()) return;
  // a list of thousands of bad pins helps nobody: the first kMaxShown say enough
  constexpr size_t kMaxShown = 50;
  std::string all;
  for (size_t i = 0; i < std::min(messages_.size(), kMaxShown); ++i) all += (i ? "\n" : "") + messages_[i];
  if (messages_.size() > kMaxShown) all += fmt::format("\n{}: and {} more errors", file_, messages_.size() - kMaxShown);
  throw Error(all);
}

std::optional<double> readNumber(ErrorLog& log, const Json& v, const std::string& path, Range range, bool integer) {
  const std::string what = range.describe(integer);
  if (!v.is_number() || (integer && v.is_number_float() && v.get<double>() != std::floor(v.get<double>()))) {
    log.expected(path, what, v);
    return std::nullopt;
  }
  const double d = v.get<double>();
  if (!range.contains(d)) {
    log.expected(path, what, v);
    return std::nullopt;
  }
  const double limit = integer ? double(INT_MAX) : double(FLT_MAX);
  if (std::abs(d) > limit) {
    log.expected(path, what + (integer ? " that fits in 32 bits" : " within float range"), v);
    return std::nullopt;
  }
  return d;
}

std::optional<Vec3> readVec3(ErrorLog& log, const Json& v, const std::string& path, Range range) {
  if (!v.is_array() || v.size() != 3) {
    log.expected(path, "an array of 3 numbers" + describeBound(range), v);
    return std::nullopt;
  }
  Vec3 out;
  bool ok = true;
  for (int i = 0; i < 3; ++i) {
    const auto d = readNumber(log, v[size_t(i)], indexPath(path, size_t(i)), range, false);
    if (d) out[i] = float(*d);
    ok = ok && d.has_value();
  }
  return ok ? std::optional<Vec3>(out) : std::nullopt;
}

ObjectReader::ObjectReader(ErrorLog& log, const Json* object, std::string path)
    : log_(log), object_(object), path_(std::move(path)) {}

const Json* ObjectReader::fetch(const std::string& key, bool required, const std::string& what) {
  if (std::find(known_.begin(), known_.end(), key) == known_.end()) known_.push_back(key);
  if (object_ && object_->is_object()) {
    const auto it = object_->find(key);
    if (it != object_->end()) return &*it;
  }
  // a missing required key of an object that is itself missing was already reported above it
  if (required && object_) log_.error(pathOf(key), "expected " + what + ", got nothing (the key is required)");
  return nullptr;
}

bool ObjectReader::has(const std::string& key) { return fetch(key, false, "") != nullptr; }

const Json* ObjectReader::get(const std::string& key) { return fetch(key, false, ""); }

float ObjectReader::number(const std::string& key, std::optional<float> def, Range range) {
  const Json* v = fetch(key, !def, range.describe(false));
  if (!v) return def.value_or(0.0f);
  const auto d = readNumber(log_, *v, pathOf(key), range, false);
  return d ? float(*d) : def.value_or(0.0f);
}

int ObjectReader::integer(const std::string& key, std::optional<int> def, Range range) {
  const Json* v = fetch(key, !def, range.describe(true));
  if (!v) return def.value_or(0);
  const auto d = readNumber(log_, *v, pathOf(key), range, true);
  return d ? int(*d) : def.value_or(0);
}

bool ObjectReader::boolean(const std::string& key, std::optional<bool> def) {
  const Json* v = fetch(key, !def, "true or false");
  if (!v) return def.value_or(false);
  if (!v->is_boolean()) {
    log_.expected(pathOf(key), "true or false", *v);
    return def.value_or(false);
  }
  return v->get<bool>();
}

std::string ObjectReader::string(const std::string& key, std::optional<std::string> def) {
  const Json* v = fetch(key, !def, "a string");
  if (!v) return def.value_or("");
  if (!v->is_string()) {
    log_.expected(pathOf(key), "a string", *v);
    return def.value_or("");
  }
  return v->get<std::string>();
}

std::string ObjectReader::name(const std::string& key, std::optional<std::string> def) {
  const bool given = has(key);
  std::string s = string(key, def);
  if (!given) return s;
  if (const std::string problem = nameProblem(s); !problem.empty()) {
    log_.error(pathOf(key), fmt::format("expected a name of 1 to {} printable ASCII characters (no newline, tab or "
                                        "other control character), got {}",
                                        kMaxNameLength, problem));
    return def.value_or("");
  }
  return s;
}

Vec3 ObjectReader::vec3(const std::string& key, std::optional<Vec3> def, Range range) {
  const Json* v = fetch(key, !def, "an array of 3 numbers" + describeBound(range));
  if (!v) return def.value_or(Vec3::Zero());
  return readVec3(log_, *v, pathOf(key), range).value_or(def.value_or(Vec3::Zero()));
}

Vec3 ObjectReader::unitVec3(const std::string& key, std::optional<Vec3> def) {
  const std::string what = "a non-zero direction (an array of 3 numbers)";
  const Json* v = fetch(key, !def, what);
  const Vec3 fallback = def.value_or(Vec3::UnitY()).normalized();
  if (!v) return fallback;
  const auto d = readVec3(log_, *v, pathOf(key), Range::any());
  if (!d) return fallback;
  // a direction is normalised here; a near-zero one has no direction
  if (!(d->norm() > 1e-6f)) {
    log_.expected(pathOf(key), what, *v);
    return fallback;
  }
  return d->normalized();
}

std::vector<float> ObjectReader::numbers(const std::string& key, size_t n, std::optional<std::vector<float>> def,
                                         Range range) {
  const std::string what = fmt::format("an array of {} numbers{}", n, describeBound(range));
  const Json* v = fetch(key, !def, what);
  const std::vector<float> fallback = def.value_or(std::vector<float>(n, 0.0f));
  if (!v) return fallback;
  if (!v->is_array() || v->size() != n) {
    log_.expected(pathOf(key), what, *v);
    return fallback;
  }
  std::vector<float> out(n);
  for (size_t i = 0; i < n; ++i) {
    const auto d = readNumber(log_, (*v)[i], indexPath(pathOf(key), i), range, false);
    if (!d) return fallback;
    out[i] = float(*d);
  }
  return out;
}

std::vector<int> ObjectReader::integers(const std::string& key, size_t n, std::optional<std::vector<int>> def,
                                        Range range) {
  const std::string what = fmt::format("an array of {} integers{}", n, describeBound(range));
  const Json* v = fetch(key, !def, what);
  const std::vector<int> fallback = def.value_or(std::vector<int>(n, 0));
  if (!v) return fallback;
  if (!v->is_array() || v->size() != n) {
    log_.expected(pathOf(key), what, *v);
    return fallback;
  }
  std::vector<int> out(n);
  for (size_t i = 0; i < n; ++i) {
    const auto d = readNumber(log_, (*v)[i], indexPath(pathOf(key), i), range, true);
    if (!d) return fallback;
    out[i] = int(*d);
  }
  return out;
}

int ObjectReader::choice(const std::string& key, const std::vector<std::string>& allowed,
                         std::optional<std::string> def) {
  std::vector<std::string> quoted;
  for (const auto& a : allowed) quoted.push_back("\"" + a + "\"");
  const std::string what = "one of " + joinList(quoted);
  const Json* v = fetch(key, !def, what);
  const auto indexOf = [&](const std::string& s) {
    return int(std::find(allowed.begin(), allowed.end(), s) - allowed.begin());
  };
  if (!v) return def ? std::min(indexOf(*def), int(allowed.size()) - 1) : -1;
  if (!v->is_string() || indexOf(v->get<std::string>()) == int(allowed.size())) {
    log_.expected(pathOf(key), what, *v);
    return -1;
  }
  return indexOf(v->get<std::string>());
}

ObjectReader ObjectReader::object(const std::string& key, bool required) {
  const Json* v = fetch(key, required, "an object");
  if (v && !v->is_object()) {
    log_.expected(pathOf(key), "an object", *v);
    v = nullptr;
  }
  return ObjectReader(log_, v, pathOf(key));
}

const Json* ObjectReader::array(const std::string& key) {
  const Json* v = fetch(key, false, "an array");
  if (v && !v->is_array()) {
    log_.expected(pathOf(key), "an array", *v);
    return nullptr;
  }
  return v;
}

void ObjectReader::finish(const std::vector<std::string>& otherKinds, const std::string& kindName) {
  if (!object_ || !object_->is_object()) return;
  for (auto it = object_->begin(); it != object_->end(); ++it) {
    const std::string& key = it.key();
    if (std::find(known_.begin(), known_.end(), key) != known_.end()) continue;
    if (std::find(otherKinds.begin(), otherKinds.end(), key) != otherKinds.end()) {
      log_.error(pathOf(key), fmt::format("'{}' is not a key of {} (keys of {}: {})", key, kindName, kindName,
                                          joinList(known_)));
      continue;
    }
    std::string hint;
    size_t best = 3;
    for (const auto& k : known_) {
      const size_t d = editDistance(key, k);
      if (d < best) {
        best = d;
        hint = fmt::format("; did you mean '{}'?", k);
      }
    }
    log_.error(pathOf(key), fmt::format("unknown key '{}' (known: {}){}", key, joinList(known_), hint));
  }
}

}  // namespace soak
