// test helpers for meshes and files: a temp file removed with the test, the message of a thrown
// soak::Error, and the edges of a triangle list with their use counts
#pragma once
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <soak/error.hpp>
#include <string>
#include <vector>

namespace soak::testing {

// a temp file removed when the test ends
struct TempFile {
  std::filesystem::path path;
  TempFile(const std::string& stem, const std::string& text) {
    path = std::filesystem::temp_directory_path() /
           (stem + "_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".obj");
    std::ofstream(path) << text;
  }
  ~TempFile() { std::filesystem::remove(path); }
};

inline std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return {};
}

// unique undirected edges of a triangle list with the number of triangles using each
inline std::map<std::pair<int, int>, int> edgeUse(const std::vector<std::array<int, 3>>& tris) {
  std::map<std::pair<int, int>, int> use;
  for (const auto& t : tris)
    for (int k = 0; k < 3; ++k) ++use[{std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])}];
  return use;
}

}  // namespace soak::testing
