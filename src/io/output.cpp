#include "io/output.hpp"

#include "garment/stage.hpp"
#include "io/file.hpp"
#include "io/obj.hpp"
#include "wetting/wetting.hpp"

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

std::vector<std::string> writeFrame(const std::string& dir, const Model& model, const State& state,
                                    const OutputSettings& settings, int frame) {
  // the cloth's saturation (Eq. 10) as a PLY attribute and as the paper's colours in the OBJ
  std::vector<Vec3> colors = saturationColors(model, state, settings.colorRamp);
  std::vector<PlyFloatAttribute> extras;
  if (model.wetting.enabled) extras.push_back({"saturation", state.clothSaturation});
  std::vector<float> wetness;  // Chen 2012 pieces without Shao's wetting: the saturation Q / delta, same ramp
  if (!model.wetting.enabled && !state.clothWetStart.empty()) {
    wetness = clothWetness(model, state);
    extras.push_back({"wetness", wetness});
    colors = rampColors(wetness, 1.0f, settings.colorRamp);
  }
  return writeFrameFiles(dir, model, state, settings, frame, extras, colors);
}

}  // namespace soak
