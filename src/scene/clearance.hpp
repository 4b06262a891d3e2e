// cloth that starts inside a collider: the contact projection pushes each particle out through the
// nearest face, which for a particle deep inside is the far one, so the cloth falls through the solid.
// The scene loader refuses such a scene (docs/scene-format.md, "Cloth and colliders at t = 0").
#pragma once
#include <soak/model.hpp>

#include "scene/cloth_keys.hpp"
#include "scene/reader.hpp"

#include <vector>

namespace soak {

// how far inside a collider's surface (m) a cloth vertex may start: rounding of a sheet laid on a
// face, not an overlap
inline constexpr float kStartInsideTolerance = 1e-4f;

// logs an error at <piece>.mesh for every pair of a cloth piece and a collider where vertices of the
// piece start (t = 0) more than kStartInsideTolerance inside the collider, naming both, the count and
// the deepest vertex. The colliders of a piece's own "body" are left to its body check (chen_keys).
void checkClothClearOfColliders(ErrorLog& log, const std::vector<ClothSpec>& cloth,
                                const std::vector<Collider>& colliders);

}  // namespace soak
