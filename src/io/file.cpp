#include "io/file.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cstring>
#include <sstream>

namespace soak {

static std::string reason() { return errno != 0 ? std::string(std::strerror(errno)) : std::string("I/O error"); }

std::ofstream openForWrite(const std::string& path) {
  errno = 0;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(path + ": cannot open for writing: " + reason());
  return out;
}

void finishWrite(std::ofstream& out, const std::string& path) {
  // a write that already failed (a block larger than the stream's buffer goes out at once) left its
  // reason in errno: kept for the message
  if (out.good()) errno = 0;
  out.flush();
  const bool ok = out.good();
  out.close();
  if (!ok || out.fail()) throw Error(path + ": write failed: " + reason());
}

void writeTextFile(const std::string& path, std::string_view text) {
  std::ofstream out = openForWrite(path);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  finishWrite(out, path);
}

std::string readTextFile(const std::string& path) {
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open for reading: " + reason());
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw Error(path + ": read failed: " + reason());
  return ss.str();
}

std::string frameFileName(const std::string& prefix, int frame, const std::string& ext) {
  return fmt::format("{}_{:04d}.{}", prefix, frame, ext);
}

}  // namespace soak
