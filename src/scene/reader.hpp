// checked reader for JSON scene files: walks the document keeping the current path
// ("cloth[0].material.thickness"), reads typed values with defaults and ranges, remembers which keys
// each object was asked for and refuses every other key. Errors are collected (not thrown) so one
// load reports all of them; the caller throws once at the end of validation.
#pragma once
#include <soak/math.hpp>

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace soak {

using Json = nlohmann::json;

// closed or open bounds on a number; infinite bounds are left out of the description
struct Range {
  double lo = -1e300, hi = 1e300;
  bool loOpen = false, hiOpen = false;

  static Range any() { return {}; }
  static Range positive() { return {0.0, 1e300, true, false}; }      // > 0
  static Range nonNegative() { return {0.0, 1e300, false, false}; }  // >= 0
  static Range unit() { return {0.0, 1.0, false, false}; }           // [0, 1]
  static Range atLeast(double v) { return {v, 1e300, false, false}; }
  static Range between(double a, double b) { return {a, b, false, false}; }
  bool contains(double v) const;
  // "a number > 0", "an integer >= 1", "a number in [0, 1]"
  std::string describe(bool integer) const;
};

// a short description of a JSON value for "got ..." ("the string \"abc\"", "-1", "an array of 2")
std::string describeJson(const Json& v);

// "a.b" / "a[0]" path composition; the top level is the empty path
std::string joinPath(const std::string& parent, const std::string& key);
std::string indexPath(const std::string& parent, size_t index);

// where errors are collected; names the file in every message
class ErrorLog {
 public:
  explicit ErrorLog(std::string file) : file_(std::move(file)) {}
  const std::string& file() const { return file_; }
  // "<file>: at <path>: <what>"
  void error(const std::string& path, const std::string& what);
  // "<file>: at <path>: expected <expected>, got <describeJson(got)>"
  void expected(const std::string& path, const std::string& expected, const Json& got);
  // a message already formatted for another file (a pattern file the scene names), kept as it is
  void add(std::string message) { messages_.push_back(std::move(message)); }
  bool ok() const { return messages_.empty(); }
  const std::vector<std::string>& messages() const { return messages_; }
  // throws soak::Error with the messages, one a line (the first 50, then a count), when any was recorded
  void throwIfAny() const;

 private:
  std::string file_;
  std::vector<std::string> messages_;
};

// reads the keys of one JSON object. A missing object (nullptr) reads as empty: every key takes its
// default, a required key is reported missing. Call finish() after the last read to refuse the
// keys that were never asked for.
class ObjectReader {
 public:
  ObjectReader(ErrorLog& log, const Json* object, std::string path);

  const std::string& path() const { return path_; }
  std::string pathOf(const std::string& key) const { return joinPath(path_, key); }
  ErrorLog& log() const { return log_; }
  bool present() const { return object_ != nullptr; }
  // true when the key is given; marks the key as known
  bool has(const std::string& key);
  // the raw value of a key or nullptr; marks the key as known
  const Json* get(const std::string& key);

  // typed reads: `def` empty means the key is required. On error the default (or a zero value) is
  // returned and the error is logged.
  float number(const std::string& key, std::optional<float> def, Range range = Range::any());
  int integer(const std::string& key, std::optional<int> def, Range range = Range::any());
  bool boolean(const std::string& key, std::optional<bool> def);
  std::string string(const std::string& key, std::optional<std::string> def);
  // a name (scene, cloth, collider, emitter): a string of 1 to 256 printable ASCII characters, since
  // names are written into comments of the output files and POV-Ray scenes
  std::string name(const std::string& key, std::optional<std::string> def);
  Vec3 vec3(const std::string& key, std::optional<Vec3> def, Range range = Range::any());
  // a direction: any non-zero vec3, returned normalised
  Vec3 unitVec3(const std::string& key, std::optional<Vec3> def);
  // an array of exactly n numbers / integers each in range
  std::vector<float> numbers(const std::string& key, size_t n, std::optional<std::vector<float>> def,
                             Range range = Range::any());
  std::vector<int> integers(const std::string& key, size_t n, std::optional<std::vector<int>> def,
                            Range range = Range::any());
  // one of `allowed`; returns its index, or -1 when the value is wrong or a required key is missing
  // (both logged), so the caller can skip the keys that depend on it
  int choice(const std::string& key, const std::vector<std::string>& allowed, std::optional<std::string> def);

  // a nested object; an absent key gives a reader of an empty object (every key at its default); a
  // wrong type, or an absent required object, is logged
  ObjectReader object(const std::string& key, bool required = false);
  // an array of anything (nullptr when absent or not an array; the latter is logged)
  const Json* array(const std::string& key);

  // refuses keys that were never asked for: "unknown key 'substep' (known: dt, substeps, ...)".
  // Keys listed in `otherKinds` belong to other variants of this object: "'radius' is not a key of a
  // box collider (keys of a box collider: ...)", with `kindName` = "a box collider".
  void finish(const std::vector<std::string>& otherKinds = {}, const std::string& kindName = "");

 private:
  const Json* fetch(const std::string& key, bool required, const std::string& what);

  ErrorLog& log_;
  const Json* object_;
  std::string path_;
  std::vector<std::string> known_;
};

// reads one number / vec3 / integer value at an arbitrary path (array elements)
std::optional<double> readNumber(ErrorLog& log, const Json& v, const std::string& path, Range range, bool integer);
std::optional<Vec3> readVec3(ErrorLog& log, const Json& v, const std::string& path, Range range);

}  // namespace soak
