#include "scene/clearance.hpp"

#include "world/colliders.hpp"

#include <fmt/format.h>

namespace soak {

namespace {

// the collider belongs to the body the piece is dressed on ("body" names it or its mannequin)
bool isBodyOf(const ClothSpec& piece, const Collider& c) {
  const std::string& body = piece.chen.body;
  return !body.empty() && (c.name == body || c.name.rfind(body + ".", 0) == 0);
}

}  // namespace

void checkClothClearOfColliders(ErrorLog& log, const std::vector<ClothSpec>& cloth,
                                const std::vector<Collider>& colliders) {
  for (const ClothSpec& piece : cloth) {
    for (const Collider& c : colliders) {
      if (isBodyOf(piece, c)) continue;
      const ColliderPose pose = colliderPose(c, 0.0);
      size_t inside = 0;
      int deepest = -1;
      float deepestDistance = 0.0f;
      for (size_t i = 0; i < piece.mesh.vertices.size(); ++i) {
        const float d = colliderDistance(c, pose, piece.mesh.vertices[i], nullptr);
        if (!(d < -kStartInsideTolerance)) continue;
        ++inside;
        if (d < deepestDistance) {
          deepestDistance = d;
          deepest = int(i);
        }
      }
      if (inside == 0) continue;
      log.error(joinPath(piece.path, "mesh"),
                fmt::format("expected cloth '{}' to start outside collider '{}', got {} of its {} particles inside it "
                            "at t = 0 (the deepest, vertex {}, {:.4g} m inside); the cloth would fall through it. "
                            "Move the cloth or the collider",
                            piece.name, c.name, inside, piece.mesh.vertices.size(), deepest, -deepestDistance));
    }
  }
}

}  // namespace soak
