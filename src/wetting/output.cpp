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

std::vector<Vec3> rampColors(const std::vector<float>& value, float valueMax, const std::string& ramp) {
  const size_t nc = value.size();
  Vec3 dry;
  if (ramp == "red")
    dry = Vec3(1.0f, 0.0f, 0.0f);
  else if (ramp == "green")
    dry = Vec3(0.0f, 1.0f, 0.0f);
  else
    return {};
  std::vector<Vec3> colors(nc);
  for (size_t i = 0; i < nc; ++i) {
    const float t = valueMax > 0.0f ? std::clamp(value[i] / valueMax, 0.0f, 1.0f) : 0.0f;
    colors[i] = (1.0f - t) * dry;
  }
  return colors;
}

}  // namespace soak
