#include "io/file.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>

namespace soak {

static std::string reason() { return errno != 0 ? std::string(std::strerror(errno)) : std::string("I/O error"); }

std::ofstream openForWrite(const std::string& path) {
  errno = 0;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(path + ": cannot open for writing: " + reason());
  return out;
}

std::ofstream openForAppend(const std::string& path) {
  errno = 0;
  std::ofstream out(path, std::ios::binary | std::ios::app);
  if (!out) throw Error(path + ": cannot open for appending: " + reason());
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

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)) {
  // a device, a pipe or a folder is opened as itself: a rename would replace it (or fail)
  std::error_code ec;
  const auto type = std::filesystem::status(path_, ec).type();
  const bool direct = !ec && type != std::filesystem::file_type::not_found && type != std::filesystem::file_type::regular;
  part_ = direct ? std::string() : path_ + ".part";
  errno = 0;
  out_.open(direct ? path_ : part_, std::ios::binary | std::ios::trunc);
  if (!out_) throw Error(path_ + ": cannot open for writing: " + reason());
}

AtomicFile::~AtomicFile() {
  if (committed_ || part_.empty()) return;
  out_.close();
  std::remove(part_.c_str());
}

void AtomicFile::commit() {
  finishWrite(out_, path_);
  errno = 0;
  if (!part_.empty() && std::rename(part_.c_str(), path_.c_str()) != 0)
    throw Error(path_ + ": cannot rename " + part_ + " to it: " + reason());
  committed_ = true;
}

void writeTextFile(const std::string& path, std::string_view text) {
  AtomicFile file(path);
  file.out().write(text.data(), static_cast<std::streamsize>(text.size()));
  file.commit();
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
