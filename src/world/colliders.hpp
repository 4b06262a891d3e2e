// colliders (plane, box, open container, sphere, capsule, mesh, and a body: a smooth union of parts
// that move on their own) with kinematic keyframed motion;
// contact with Coulomb friction and restitution (collider_contact.cpp). Shared by both cloth solvers and the water.
#pragma once
#include <soak/model.hpp>
#include <soak/state.hpp>

#include "core/parallel.hpp"

#include <memory>
#include <span>
#include <string>
#include <vector>

namespace soak {

class MeshSnapshot;  // world/mesh_sequence.hpp

// world pose of a collider at time t and its rigid velocity field
struct ColliderPose {
  Vec3 translation{0, 0, 0};
  Quat rotation{1, 0, 0, 0};
  Vec3 linearVelocity{0, 0, 0};   // m/s of the local origin
  Vec3 angularVelocity{0, 0, 0};  // rad/s, world frame
  Vec3 velocityAt(const Vec3& p) const { return linearVelocity + angularVelocity.cross(p - translation); }
  // a Body collider: the world pose of each of its parts (the body's pose composed with the part's)
  std::vector<ColliderPose> parts;
  // a MeshSequence collider: its surface at this time (local frame), shared by copies of the pose
  std::shared_ptr<const MeshSnapshot> mesh;
  bool moving() const;  // a velocity, its own or a part's, is not zero
};

// pose at time t: translation interpolated linearly between keyframes, rotation by slerp, the ends
// held; velocities from the keyframe segment containing t. A MeshSequence's pose holds its surface
// at t (a tree over its triangles is built: pose it once per substep, not per point)
ColliderPose colliderPose(const Collider& c, double t);
// the same with the collider's keys replaced by `keys` (a Body's parts keep theirs, relative to them)
ColliderPose colliderPose(const Collider& c, std::span<const Keyframe> keys, double t);
// the same for keyframes given apart from a collider (a caller's, step.hpp)
ColliderPose keyframedPose(std::span<const Keyframe> keys, double t);

// signed distance (m, negative inside the solid) from world point p to the collider, and the unit
// outward normal of the nearest surface in `normal` (world frame). A Body blends its parts' distances
// by smoothMin (world/smooth_min.hpp), its normal is the blend's normalised gradient; a Body pose
// without its parts' poses (not from colliderPose) is far from everything
float colliderDistance(const Collider& c, const ColliderPose& pose, const Vec3& p, Vec3* normal);

// moves x out along the collider's normal to a distance >= margin; true when x was within the margin,
// *normal the last push's normal, *velocity (may be null) the collider's surface velocity at the new x
// (colliderVelocity; a mesh sequence's from the same search as the push). One push for the exact distances; a Body's smooth distance changes
// by |gradient| <= 1 per metre moved, so a push by the distance falls short where parts blend: its
// push is found along the normal by a bracketed root search (kBodyPushes doublings, 4 kBodyPushes
// regula falsi steps at most) and ends within 1e-3 margin beyond the margin
constexpr int kBodyPushes = 4;
bool pushOutOf(const Collider& c, const ColliderPose& pose, float margin, Vec3& x, Vec3* normal,
               Vec3* velocity = nullptr);

// velocity (m/s) of the collider's surface material at world point p: the rigid field of the pose,
// or for a Body its parts' fields blended with the weights of its normal (a point of the skin between
// two bones moves as a mix of both); a MeshSequence adds its nearest surface point's own motion
Vec3 colliderVelocity(const Collider& c, const ColliderPose& pose, const Vec3& p);
// a Body's distance at p and each part's share of its blend there (they sum to 1; the weights of its
// normal and of its skin velocity, colliderVelocity); another shape: its distance and no weights
float bodyPartWeights(const Collider& c, const ColliderPose& pose, const Vec3& p, std::vector<float>& weights);

// an upper bound of |colliderVelocity(c, pose, p)| that costs no distance (a Body: its fastest part;
// a MeshSequence: its fastest vertex on top of the rigid motion)
float colliderSpeedBound(const Collider& c, const ColliderPose& pose, const Vec3& p);

// how far the moving colliders may carry a surface point near p in dt: the largest colliderSpeedBound
// times dt over the colliders whose `include` flag is set (empty: all) and that move
float colliderCarry(const Model& model, const std::vector<ColliderPose>& poses, std::span<const uint8_t> include,
                    const Vec3& p, float dt);

// a Body collider joining `parts` (sphere, capsule or box colliders, their keys in the body's frame)
// by smoothMin of radius blendRadius (m); it rests at the identity (one key) and takes the first
// part's friction and restitution. Throws soak::Error naming `source` on another part shape, no parts
// or a radius that is not > 0
Collider makeBodyCollider(const std::string& name, std::vector<Collider> parts, float blendRadius,
                          const std::string& source);

// a lower bound of colliderDistance(c, pose, x_i) for the n points x_i = X[3i .. 3i+2], min-ed into
// out[i] (out[i] = min(out[i], bound)): exact up to kDistanceBoundSlack for planes, spheres, capsules,
// boxes, containers and bodies, in a vectorised loop without normals; a mesh collider gets its exact
// distance, a mesh sequence the distance to its box (which holds it, so is nearer).
// For skipping the points that cannot be within some distance of the collider
constexpr float kDistanceBoundSlack = 1e-4f;  // m, covers the rounding of the matrix against the quaternion
void colliderDistanceBounds(const Collider& c, const ColliderPose& pose, const float* X, int64_t n, float* out);

// the world box that holds the collider's solid at `pose` (its exact box for the convex shapes, its
// grid's for a mesh, its parts' grown by the blend radius for a body, its vertices' for a mesh
// sequence); false for a plane and a shape without its data (a mesh without a grid)
bool colliderBox(const Collider& c, const ColliderPose& pose, Vec3* lo, Vec3* hi);

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
// the same for the listed particles over a step that started at start[i] instead of x (the PBD
// cloth's small steps, pbd/cloth_steps.cpp), against the colliders whose `include` flag is set (empty:
// all); no contact normals are kept. A collider flagged kPosedAhead is posed `ahead` seconds after the
// step's end (a moving mesh sequence posed once a substep): the particle meets it carried that far by
// the surface's velocity where it is, and is carried back after
constexpr uint8_t kPosedAhead = 2;
uint64_t projectColliders(const Model& model, const std::vector<ColliderPose>& poses, Particles& p,
                          std::span<const int> particles, const Vec3* start, std::span<const uint8_t> include,
                          float dt, float ahead = 0.0f);
// the same for every particle
uint64_t projectColliders(const Model& model, const std::vector<ColliderPose>& poses, Particles& p, float dt,
                      std::vector<Vec3>& contactNormal);

// after v = (x* - x)/dt: a particle in contact that moves into the collider along the normal gets
// its relative normal velocity reversed and scaled by the collider's restitution
void applyColliderRestitution(const Model& model, const std::vector<ColliderPose>& poses,
                              const std::vector<Vec3>& contactNormal, Particles& p);

}  // namespace soak
