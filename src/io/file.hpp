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

// flushes and closes `out`; throws soak::Error naming `path` when any write failed
void finishWrite(std::ofstream& out, const std::string& path);

// "prefix_NNNN.ext" with a 4-digit (or longer) zero-padded frame number
std::string frameFileName(const std::string& prefix, int frame, const std::string& ext);

}  // namespace soak
