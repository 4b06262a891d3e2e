#include "scene/overrides.hpp"

#include "scene/limits.hpp"

#include <soak/error.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <set>
#include <vector>

namespace soak {

namespace {

bool isIndex(const std::string& s) {
  return !s.empty() && s.size() < 10 && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

std::vector<std::string> splitPath(const std::string& s) {
  std::vector<std::string> parts;
  size_t begin = 0;
  while (true) {
    const size_t dot = s.find('.', begin);
    parts.push_back(s.substr(begin, dot == std::string::npos ? std::string::npos : dot - begin));
    if (dot == std::string::npos) return parts;
    begin = dot + 1;
  }
}

const char* typeName(const Json& v) {
  if (v.is_boolean()) return "a boolean";
  if (v.is_number()) return "a number";
  if (v.is_string()) return "a string";
  return "a value";
}

}  // namespace

namespace {

// the parser's path through the document, to name a key that an object repeats: nlohmann keeps the
// last value of a repeated key, so a scene that sets a key twice would lose the first silently
struct DuplicateKeys {
  struct Frame {
    bool array = false;
    int index = 0;          // arrays: elements started so far
    std::string key;        // objects: the key being read
    std::set<std::string> keys;
  };
  std::vector<Frame> frames;
  std::string duplicate;    // the JSON path of the first repeated key, empty if none

  // `pending`: the innermost array's next element is the one being read (a value that failed to parse)
  std::string path(bool pending = false) const {
    std::string out;
    for (const Frame& f : frames) {
      if (f.array) out += fmt::format("[{}]", f.index - (pending && &f == &frames.back() ? 0 : 1));
      else if (!f.key.empty()) out += (out.empty() ? "" : ".") + f.key;
    }
    return out;
  }
  void element() {  // a value starts: in an array it is the next element
    if (!frames.empty() && frames.back().array) ++frames.back().index;
  }
  bool operator()(int, Json::parse_event_t event, Json& parsed) {
    switch (event) {
      case Json::parse_event_t::object_start:
      case Json::parse_event_t::array_start:
        element();
        frames.push_back({event == Json::parse_event_t::array_start, 0, {}, {}});
        break;
      case Json::parse_event_t::object_end:
      case Json::parse_event_t::array_end:
        if (!frames.empty()) frames.pop_back();
        break;
      case Json::parse_event_t::key: {
        Frame& f = frames.back();
        f.key = parsed.get<std::string>();
        if (!f.keys.insert(f.key).second && duplicate.empty()) duplicate = path();
        break;
      }
      case Json::parse_event_t::value:
        element();
        break;
    }
    return true;
  }
};

}  // namespace

Json parseSceneJson(const std::string& text, const std::string& file) {
  checkJsonText(text, file);
  DuplicateKeys keys;
  Json doc;
  try {
    doc = Json::parse(text, std::ref(keys), true, true);
  } catch (const Json::out_of_range& e) {
    // a number beyond double range (1e400): the parser stops at it, the key being read names it
    const std::string what = e.what();
    const size_t token = what.find("parsing ");
    throw errorAt(file, keys.path(true).empty() ? "(top level)" : keys.path(true),
                  "expected a number within double range (about 1.8e308), got " +
                      (token == std::string::npos ? what : what.substr(token + 8)));
  } catch (const Json::parse_error& e) {
    // e.byte is the 1-based offset of the offending character; count lines up to it ourselves
    const size_t end = std::min(text.size(), e.byte > 0 ? size_t(e.byte - 1) : size_t(0));
    size_t line = 1, column = 1;
    for (size_t i = 0; i < end; ++i) {
      if (text[i] == '\n') {
        ++line;
        column = 1;
      } else {
        ++column;
      }
    }
    std::string what = e.what();
    const size_t syntax = what.find("syntax error");
    if (syntax != std::string::npos) what = what.substr(syntax);
    throw errorAt(file, fmt::format("line {}, column {}", line, column), "invalid JSON: " + what);
  }
  if (!keys.duplicate.empty())
    throw errorAt(file, keys.duplicate, "expected each key once in its object, got it twice (JSON keeps only the last)");
  return doc;
}

void applyOverrides(Json& doc, const std::vector<std::string>& overrides, const std::string& file) {
  for (const std::string& text : overrides) {
    const auto fail = [&](const std::string& what) { return errorAt(file, "override '" + text + "'", what); };
    const size_t eq = text.find('=');
    if (eq == std::string::npos) throw fail("expected \"path=value\" (e.g. solver.substeps=3), got no '='");
    const std::string key = text.substr(0, eq);
    const std::string valueText = text.substr(eq + 1);
    const std::vector<std::string> parts = splitPath(key);
    Json* cur = &doc;
    std::string walked;
    for (const std::string& part : parts) {
      if (part.empty()) throw fail("expected a path of non-empty components separated by '.', got '" + key + "'");
      const std::string where = walked.empty() ? "the top level" : "'" + walked + "'";
      if (cur->is_array()) {
        if (!isIndex(part))
          throw fail(fmt::format("{} is an array: expected an index, got '{}'", where, part));
        const size_t index = std::stoul(part);
        if (index >= cur->size())
          throw fail(fmt::format("index {} is past the end of {} ({} elements)", index, where, cur->size()));
        cur = &(*cur)[index];
      } else if (cur->is_object() || cur->is_null()) {
        if (cur->is_null() && isIndex(part))
          throw fail(fmt::format("index {} is past the end of {} (it does not exist)", part, where));
        cur = &(*cur)[part];
      } else {
        throw fail(fmt::format("{} is {}, it has no key '{}'", where, typeName(*cur), part));
      }
      walked += (walked.empty() ? "" : ".") + part;
    }
    checkJsonText(valueText, file + ": override '" + text + "'");
    try {
      *cur = Json::parse(valueText);
    } catch (const Json::out_of_range&) {
      throw fail("expected a number within double range (about 1.8e308), got " + valueText);
    } catch (const Json::parse_error&) {
      *cur = valueText;  // not JSON: a bare string such as a file name
    }
  }
}

}  // namespace soak
