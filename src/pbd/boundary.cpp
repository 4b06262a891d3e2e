#include "pbd/boundary.hpp"

#include "world/container.hpp"

#include <cmath>
#include <limits>

namespace soak {

namespace {

// the world half extents of a sphere, capsule or box at rotation r; false for other shapes
bool halfExtents(const Collider& c, const Eigen::Matrix3f& r, Vec3* half) {
  switch (c.shape) {
    case ColliderShape::Sphere: *half = Vec3::Constant(c.radius); return true;
    case ColliderShape::Capsule: *half = r.col(1).cwiseAbs() * c.halfHeight + Vec3::Constant(c.radius); return true;
    case ColliderShape::Box: *half = r.cwiseAbs() * c.halfExtents; return true;
    default: return false;
  }
}

// the world box of a sphere, capsule, box or body part at its pose (boundaryParts); planes and
// meshes keep the infinite one. A body's surface is within its blend radius of its parts' union
// (smoothMin.hpp: the fold of any number of parts is >= their min - k)
void setBounds(BoundaryPart& part) {
  const Collider& c = part.shape;
  Vec3 lo = Vec3::Constant(std::numeric_limits<float>::max()), hi = -lo;
  if (c.shape == ColliderShape::Body) {
    if (!c.parts || part.pose.parts.size() != c.parts->size()) return;
    for (size_t k = 0; k < c.parts->size(); ++k) {
      const ColliderPose& pose = part.pose.parts[k];
      Vec3 half;
      if (!halfExtents((*c.parts)[k], pose.rotation.normalized().toRotationMatrix(), &half)) return;
      lo = lo.cwiseMin(pose.translation - half);
      hi = hi.cwiseMax(pose.translation + half);
    }
    const Vec3 pad = Vec3::Constant(c.blendRadius);
    lo -= pad;
    hi += pad;
  } else {
    Vec3 half;
    if (!halfExtents(c, part.pose.rotation.normalized().toRotationMatrix(), &half)) return;
    lo = part.pose.translation - half;
    hi = part.pose.translation + half;
  }
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
