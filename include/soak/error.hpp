// errors at the edges: scene loading, mesh checks, output. The message names the file, the place
// (a JSON path or a line) and what was expected.
#pragma once
#include <stdexcept>
#include <string>

namespace soak {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// "file: at path: message"
inline Error errorAt(const std::string& file, const std::string& where, const std::string& what) {
  std::string msg = file;
  if (!where.empty()) msg += ": at " + where;
  return Error(msg + ": " + what);
}

}  // namespace soak
