// geometry of the open-top container collider: a bottom slab and four side walls around the free
// cavity |x| <= halfExtents (local frame). Shared by the distance function and the boundary density.
#pragma once
#include <soak/model.hpp>

namespace soak {

constexpr int kContainerWalls = 5;

// centres and half extents of the five wall boxes, in the container's local frame; the slabs overlap
// at the edges so a particle entering a wall near a corner sees the real inner face as its nearest
void containerWalls(const Collider& c, Vec3 centers[kContainerWalls], Vec3 halves[kContainerWalls]);

}  // namespace soak
