// the paper's saturation colours for the cloth OBJ: dry cloth in a bright colour fading to black as it
// saturates (red in Fig. 3, green in Fig. 4)
#include "wetting/wetting.hpp"

#include <algorithm>

namespace soak {

std::vector<Vec3> saturationColors(const Model& model, const State& state, const std::string& ramp) {
  const size_t nc = static_cast<size_t>(model.numCloth);
  if (!model.wetting.enabled || state.clothSaturation.size() != nc) return {};
  return rampColors(state.clothSaturation, model.wetting.saturationMax, ramp);
}

Vec3 rampColor(const std::string& ramp, float value, float valueMax) {
  const Vec3 dry = ramp == "green" ? Vec3(0.0f, 1.0f, 0.0f) : Vec3(1.0f, 0.0f, 0.0f);
  const float t = valueMax > 0.0f ? std::clamp(value / valueMax, 0.0f, 1.0f) : 0.0f;
  return (1.0f - t) * dry;
}

std::vector<Vec3> rampColors(const std::vector<float>& value, float valueMax, const std::string& ramp) {
  if (ramp != "red" && ramp != "green") return {};
  std::vector<Vec3> colors(value.size());
  for (size_t i = 0; i < value.size(); ++i) colors[i] = rampColor(ramp, value[i], valueMax);
  return colors;
}

}  // namespace soak
