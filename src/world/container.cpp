#include "world/container.hpp"

namespace soak {

void containerWalls(const Collider& c, Vec3 centers[kContainerWalls], Vec3 halves[kContainerWalls]) {
  const Vec3& h = c.halfExtents;
  const float w = c.wallThickness;
  const float hw = 0.5f * w;
  centers[0] = {0.0f, -h.y() - hw, 0.0f};
  centers[1] = {h.x() + hw, -hw, 0.0f};
  centers[2] = {-h.x() - hw, -hw, 0.0f};
  centers[3] = {0.0f, -hw, h.z() + hw};
  centers[4] = {0.0f, -hw, -h.z() - hw};
  halves[0] = {h.x() + w, hw, h.z() + w};
  halves[1] = {hw, h.y() + hw, h.z() + w};
  halves[2] = {hw, h.y() + hw, h.z() + w};
  halves[3] = {h.x() + w, h.y() + hw, hw};
  halves[4] = {h.x() + w, h.y() + hw, hw};
}

}  // namespace soak
