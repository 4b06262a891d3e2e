#include "io/output.hpp"

#include "io/file.hpp"
#include "io/obj.hpp"

#include <filesystem>

namespace soak {

std::vector<std::string> writeFrameFiles(const std::string& dir, const Model& model, const State& state,
                                         const OutputSettings& settings, int frame,
                                         std::span<const PlyFloatAttribute> clothExtras,
                                         std::span<const Vec3> clothColors) {
  namespace fs = std::filesystem;
  std::vector<std::string> written;
  const bool cloth = model.numCloth > 0 && (settings.clothObj || settings.clothPly);
  // one normal computation serves both cloth files
  const std::vector<Vec3> normals = cloth ? clothVertexNormals(model, state.particles.x) : std::vector<Vec3>{};
  if (model.numCloth > 0 && settings.clothObj) {
    const std::string path = (fs::path(dir) / frameFileName("cloth", frame, "obj")).string();
    writeClothObj(path, model, state, normals, clothColors);
    written.push_back(path);
  }
  if (model.numCloth > 0 && settings.clothPly) {
    const std::string path = (fs::path(dir) / frameFileName("cloth", frame, "ply")).string();
    writeClothPly(path, model, state, normals, clothExtras);
    written.push_back(path);
  }
  if (settings.water) {
    const std::string path = (fs::path(dir) / frameFileName("water", frame, "ply")).string();
    writeWaterPly(path, state);
    written.push_back(path);
  }
  return written;
}

}  // namespace soak
