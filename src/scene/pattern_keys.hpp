// a cloth mesh of "type": "pattern" (docs/scene-format.md, "Sewing patterns"): a garment sewn from
// 2-D panels (world/pattern.hpp) given inline or in a pattern file
#pragma once
#include "scene/chen_keys.hpp"
#include "scene/limits.hpp"
#include "scene/reader.hpp"
#include "world/pattern.hpp"

#include <optional>
#include <string>
#include <vector>

namespace soak {

inline constexpr int kMaxPatternPanels = 256;
inline constexpr int kMaxPatternCorners = 100000;  // over all panels
inline constexpr int kMaxPatternSeams = 4096;

extern const std::vector<std::string> kPatternMeshKeys;

// reads the pattern ("pattern": inline, or "path": a JSON file relative to baseDir), checks it,
// bounds its vertex count by limit before meshing, sews it at "edgeLength" and, with "body" (a
// mannequin), moves it with the body's position and yaw. nullopt when invalid (logged; errors in a
// pattern file name that file)
std::optional<SewnGarment> readPatternMesh(ObjectReader& m, const std::string& baseDir, const Bodies& bodies,
                                           const ParticleLimit& limit);

}  // namespace soak
