// text that is safe to write into a line of another file format (a comment of a POV-Ray scene, an
// OBJ object name, a PLY header line): names come from scene files, and a newline in one would end
// the comment and let the rest run as scene code or add geometry. The writers escape whatever they
// are given, whatever the loader checked.
#pragma once
#include <string>
#include <string_view>

namespace soak {

// every byte outside printable ASCII (0x20..0x7e) as \xNN, and a backslash as \\ so the escape
// cannot be forged
inline std::string printableText(std::string_view s) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(s.size());
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '\\') {
      out += "\\\\";
    } else if (c >= 0x20 && c < 0x7f) {
      out += ch;
    } else {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  return out;
}

}  // namespace soak
