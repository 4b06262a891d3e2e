// small file helpers for the writers: every failure throws soak::Error naming the file
#pragma once
#include <soak/error.hpp>
#include <soak/output.hpp>

#include <fstream>
#include <string>
#include <string_view>

namespace soak {

// opens `path` for binary writing (truncating); throws soak::Error naming the file on failure
std::ofstream openForWrite(const std::string& path);

// opens `path` for appending (created when absent); throws soak::Error naming the file on failure
std::ofstream openForAppend(const std::string& path);

// flushes and closes `out`; throws soak::Error naming `path` when any write failed
void finishWrite(std::ofstream& out, const std::string& path);

// a file written under a temporary name (path + ".part", in the same folder) and renamed to `path`
// once complete, so no reader ever sees a half-written file under its real name (a full disk, a
// crash, a kill). The temporary is removed when the writer is destroyed without commit(). A path that
// exists and is not a regular file (/dev/stdout, a pipe) is written directly.
class AtomicFile {
 public:
  // opens path.part for binary writing; throws soak::Error naming `path` on failure
  explicit AtomicFile(std::string path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  std::ofstream& out() { return out_; }
  // flushes, closes and renames path.part to path (replacing it); throws soak::Error naming `path`
  // when a write failed, leaving neither file behind
  void commit();

 private:
  std::string path_, part_;
  std::ofstream out_;
  bool committed_ = false;
};

// "prefix_NNNN.ext" with a 4-digit (or longer) zero-padded frame number
std::string frameFileName(const std::string& prefix, int frame, const std::string& ext);

}  // namespace soak
