#include "scene/overrides.hpp"

#include <soak/error.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cctype>

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

Json parseSceneJson(const std::string& text, const std::string& file) {
  try {
    return Json::parse(text, nullptr, true, true);
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
    try {
      *cur = Json::parse(valueText);
    } catch (const Json::parse_error&) {
      *cur = valueText;  // not JSON: a bare string such as a file name
    }
  }
}

}  // namespace soak
