// helpers of the scene tests (tests/scene/*_test.cpp): a small valid scene, loading from a string as
// "test.json", the load error, and a temp folder removed with the test
#pragma once
#include <soak/error.hpp>
#include <soak/scene.hpp>

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace soak::testing {

namespace fs = std::filesystem;

// a small valid scene: one 4 x 3 rectangle, one block emitter
inline const char* kSmall = R"({
  "cloth": [{"name": "sheet", "mesh": {"type": "rectangle", "center": [0, 1, 0], "size": [0.3, 0.2],
                                      "resolution": [4, 3]}}],
  "emitters": [{"type": "block", "min": [-0.05, 1.2, -0.05], "max": [0.05, 1.3, 0.05]}]
})";

inline Scene fromString(const std::string& text, const std::vector<std::string>& overrides = {},
                 const std::string& baseDir = ".") {
  return loadSceneFromString(text, "test.json", baseDir, overrides);
}

// the message of the soak::Error thrown by loading `text`, or "" when it loads
inline std::string loadError(const std::string& text, const std::vector<std::string>& overrides = {},
                      const std::string& baseDir = ".") {
  try {
    fromString(text, overrides, baseDir);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// the error of loading kSmall with one "path=value" override applied
inline std::string errorWith(const std::string& override_) { return loadError(kSmall, {override_}); }

// a fresh directory under the system temp dir, removed at the end of the test
struct TempDir {
  fs::path path;
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path = fs::temp_directory_path() / ("soak_scene_" + std::string(info->name()) + "_" + std::to_string(getpid()));
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(path / name) << text;
    return (path / name).string();
  }
};

#ifndef EXPECT_HAS
#define EXPECT_HAS(haystack, needle) EXPECT_NE(std::string(haystack).find(needle), std::string::npos) << (haystack)
#endif

}  // namespace soak::testing
