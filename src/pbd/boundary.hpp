// rigid colliders as boundaries of the water's density: the continuous limit of Akinci et al. 2012's
// boundary particles. Each convex part of a collider contributes the fraction of the kernel's mass
// that lies inside it (the half-space integral at the part's distance); parts combine as a union,
// 1 - prod(1 - phi_k), so water in a corner sees both walls.
#pragma once
#include <soak/model.hpp>

#include "core/kernels.hpp"
#include "world/colliders.hpp"

#include <limits>
#include <vector>

namespace soak {

// a convex solid the density sees: a collider or one wall of a container, with its world pose
struct BoundaryPart {
  Collider shape;
  ColliderPose pose;
  // a world box that holds the part (infinite for a plane): a point more than h outside it
  // is farther than h from the part, whose distance then need not be computed
  Vec3 lo = Vec3::Constant(-std::numeric_limits<float>::infinity());
  Vec3 hi = Vec3::Constant(std::numeric_limits<float>::infinity());
};

// the convex parts of every collider at the given poses
void boundaryParts(const Model& model, const std::vector<ColliderPose>& poses, std::vector<BoundaryPart>& parts);

// the solid fraction phi of the kernel of a particle at x with support kernel.h, and its gradient wrt x
float boundaryFraction(const std::vector<BoundaryPart>& parts, const Vec3& x, const WallKernel& kernel,
                       Vec3* gradient);

}  // namespace soak
