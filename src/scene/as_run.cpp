// the scene as a run uses it (soak/scene.hpp: sceneAsRun)
#include <soak/output.hpp>
#include <soak/scene.hpp>

#include "scene/limits.hpp"
#include "scene/overrides.hpp"

#include <filesystem>

namespace soak {

namespace {

namespace fs = std::filesystem;

// relative file paths in the scene ("mesh": {"path": ...}) made absolute against baseDir: an existing
// file, or a mesh sequence's pattern ('#' for the frame number) in an existing folder
void resolvePaths(nlohmann::json& v, const fs::path& baseDir) {
  if (v.is_object()) {
    for (auto it = v.begin(); it != v.end(); ++it) {
      if (it.key() == "path" && it->is_string()) {
        const fs::path p = it->get<std::string>();
        const bool pattern = p.filename().string().find('#') != std::string::npos;
        const bool found = fs::exists(baseDir / p) || (pattern && fs::is_directory((baseDir / p).parent_path()));
        if (p.is_relative() && found) *it = fs::absolute(baseDir / p).lexically_normal().string();
      } else {
        resolvePaths(*it, baseDir);
      }
    }
  } else if (v.is_array()) {
    for (auto& e : v) resolvePaths(e, baseDir);
  }
}

}  // namespace

std::string sceneAsRun(const std::string& path, const std::vector<std::string>& overrides) {
  nlohmann::json doc = parseSceneJson(readSceneText(path), path);
  applyOverrides(doc, overrides, path);
  resolvePaths(doc, fs::absolute(path).parent_path());
  return doc.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

}  // namespace soak
