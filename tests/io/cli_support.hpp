// running the soak program in tests: a temp folder, the program's exit code, stdout and stderr, and
// the small scene the end-to-end tests run
#pragma once
#include "io/file.hpp"

#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

namespace soak::testing {

namespace fs = std::filesystem;

// a 10 x 10 cloth pinned at its corners under a 4 x 4 x 4 block of water, 3 frames of 2 steps
inline constexpr const char* kTinyScene = R"({
  "name": "tiny",
  "description": "cli test: a small cloth under a small block",
  "solver": {"dt": 0.01, "substeps": 1, "domain": {"min": [-1, -1, -1], "max": [1, 2, 1]}},
  "output": {"frames": 3, "stepsPerFrame": 2},
  "cloth": [{
    "name": "sheet",
    "mesh": {"type": "rectangle", "center": [0, 0.5, 0], "size": [0.2, 0.2], "resolution": [10, 10],
             "axisU": [1, 0, 0], "axisV": [0, 0, 1]},
    "pin": {"corners": [0, 1, 2, 3]}
  }],
  "emitters": [{"name": "cube", "type": "block", "min": [-0.04, 0.54, -0.04], "max": [0.04, 0.62, 0.04]}]
})";
inline constexpr int kTinyWater = 64;  // 4 x 4 x 4 lattice sites of 0.02 m

struct Result {
  int code = -1;
  std::string out, err;
};

class Cli {
 public:
  explicit Cli(const std::string& name)
      : dir_(fs::temp_directory_path() / ("soak_cli_test_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  ~Cli() { fs::remove_all(dir_); }
  fs::path dir() const { return dir_; }

  std::string writeScene(const std::string& name, const std::string& text) const {
    const std::string path = (dir_ / name).string();
    writeTextFile(path, text);
    return path;
  }

  // runs SOAK_BINARY with `args` (already shell-quoted where needed)
  Result run(const std::string& args) const {
    const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string cmd = std::string("'") + SOAK_BINARY + "' " + args + " > '" + out.string() + "' 2> '" +
                            err.string() + "'";
    const int status = std::system(cmd.c_str());
    Result r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = readTextFile(out.string());
    r.err = readTextFile(err.string());
    fs::remove(out);
    fs::remove(err);
    return r;
  }

 private:
  fs::path dir_;
};

inline std::vector<nlohmann::json> readJsonLines(const fs::path& path) {
  std::vector<nlohmann::json> lines;
  std::istringstream ss(readTextFile(path.string()));
  for (std::string l; std::getline(ss, l);) lines.push_back(nlohmann::json::parse(l));
  return lines;
}

}  // namespace soak::testing
