// rigid colliders (plane, box, open container, sphere, capsule, mesh) with kinematic keyframed motion;
// contact with Coulomb friction and restitution (collider_contact.cpp). Shared by both cloth solvers and the water.
#pragma once
#include <soak/model.hpp>
#include <soak/state.hpp>

#include "core/parallel.hpp"

#include <span>
#include <vector>

namespace soak {

// world pose of a collider at time t and its rigid velocity field
struct ColliderPose {
  Vec3 translation{0, 0, 0};
  Quat rotation{1, 0, 0, 0};
  Vec3 linearVelocity{0, 0, 0};   // m/s of the local origin
  Vec3 angularVelocity{0, 0, 0};  // rad/s, world frame
  Vec3 velocityAt(const Vec3& p) const { return linearVelocity + angularVelocity.cross(p - translation); }
};

// pose at time t: translation interpolated linearly between keyframes, rotation by slerp, the ends
// held; velocities from the keyframe segment containing t
ColliderPose colliderPose(const Collider& c, double t);
// the same for keyframes given apart from a collider (a caller's, step.hpp)
ColliderPose keyframedPose(std::span<const Keyframe> keys, double t);

// signed distance (m, negative inside the solid) from world point p to the collider, and the unit
// outward normal of the nearest surface in `normal` (world frame)
float colliderDistance(const Collider& c, const ColliderPose& pose, const Vec3& p, Vec3* normal);

// a lower bound of colliderDistance(c, pose, x_i) for the n points x_i = X[3i .. 3i+2], min-ed into
// out[i] (out[i] = min(out[i], bound)): exact up to kDistanceBoundSlack for planes, spheres, capsules,
// boxes and containers, in a vectorised loop without normals; a mesh collider gets its exact distance.
// For skipping the points that cannot be within some distance of the collider
constexpr float kDistanceBoundSlack = 1e-4f;  // m, covers the rounding of the matrix against the quaternion
void colliderDistanceBounds(const Collider& c, const ColliderPose& pose, const float* X, int64_t n, float* out);

// contact margin of a particle against colliders: water keeps half its spacing, cloth half its
// thickness
float contactMargin(const Model& model, int32_t phase);

// pushes the predicted position x* of every particle in `moved` (but kinematic ones) out of every
// collider (distance >= margin; a container wall by wall) and applies Coulomb friction to its motion
// relative to the collider over this substep (collider_contact.cpp). A particle that started clear
// is put on the face its path x -> x* entered by, found along the path, so no speed carries it
// through a wall. contactNormal[i] is set to the world normal of the last contact of particle i, or
// zero. distanceBound: scratch, a lower bound of each particle's distance to the nearest collider, so
// that the particles far from every collider skip the exact test. Returns the number of particles
// put back: x* inside a collider's surface, its path through one, or its start inside one
uint64_t projectColliders(const Model& model, const std::vector<ColliderPose>& poses, Particles& p,
                      const std::vector<IndexRange>& moved, float dt, std::vector<Vec3>& contactNormal,
                      std::vector<float>& distanceBound);
// the same for every particle
uint64_t projectColliders(const Model& model, const std::vector<ColliderPose>& poses, Particles& p, float dt,
                      std::vector<Vec3>& contactNormal);

// after v = (x* - x)/dt: a particle in contact that moves into the collider along the normal gets
// its relative normal velocity reversed and scaled by the collider's restitution
void applyColliderRestitution(const Model& model, const std::vector<ColliderPose>& poses,
                              const std::vector<Vec3>& contactNormal, Particles& p);

}  // namespace soak
