#include "pbd/boundary.hpp"

#include "world/container.hpp"

#include <cmath>
#include <limits>

namespace soak {

namespace {

// the world box of the part at its pose (world/colliders.hpp colliderBox); a plane keeps the
// infinite one
void setBounds(BoundaryPart& part) {
  Vec3 lo, hi;
  if (!colliderBox(part.shape, part.pose, &lo, &hi)) return;
  // rounding of the rotation against colliderDistance's
  const Vec3 slack = 1e-5f * (hi - lo).cwiseAbs() + Vec3::Constant(1e-6f);
  part.lo = lo - slack;
  part.hi = hi + slack;
}

}  // namespace

void boundaryParts(const Model& model, const std::vector<ColliderPose>& poses, std::vector<BoundaryPart>& parts) {
  parts.clear();
  for (size_t c = 0; c < model.colliders.size(); ++c) {
    const Collider& col = model.colliders[c];
    if (col.shape != ColliderShape::Container) {
      parts.push_back({col, poses[c]});
      setBounds(parts.back());
      continue;
    }
    // an open container is concave: its walls are separate convex parts
    Vec3 centers[kContainerWalls], halves[kContainerWalls];
    containerWalls(col, centers, halves);
    for (int k = 0; k < kContainerWalls; ++k) {
      BoundaryPart part{col, poses[c]};
      part.shape.shape = ColliderShape::Box;
      part.shape.halfExtents = halves[k];
      part.pose.translation = poses[c].translation + poses[c].rotation * centers[k];
      setBounds(part);
      parts.push_back(part);
    }
  }
}

float boundaryFraction(const std::vector<BoundaryPart>& parts, const Vec3& x, const WallKernel& kernel,
                       Vec3* gradient) {
  const float h = kernel.h;
  float empty = 1.0f;  // prod (1 - phi_k)
  Vec3 gradEmpty = Vec3::Zero();
  for (const BoundaryPart& part : parts) {
    // more than h outside the part's box: d > h, as below (most walls of a container, for most water)
    if ((x.array() < part.lo.array() - h).any() || (x.array() > part.hi.array() + h).any()) continue;
    Vec3 n;
    const float d = colliderDistance(part.shape, part.pose, x, &n);
    if (d >= h) continue;
    float dphi = 0.0f;
    const float keep = 1.0f - wallKernelFraction(d, kernel, &dphi);
    gradEmpty = gradEmpty * keep - empty * dphi * n;  // product rule on prod (1 - phi_k)
    empty *= keep;
  }
  if (gradient) *gradient = -gradEmpty;
  return 1.0f - empty;
}

}  // namespace soak
