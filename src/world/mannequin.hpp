// a procedural virtual human (Chen 2012's "virtual human", section 4) made of sphere and capsule
// colliders, posed by joint angles and animated by keyframed poses
#pragma once
#include <soak/model.hpp>

#include <array>
#include <string>
#include <vector>

namespace soak {

// side index of the per-side angles: 0 is the body's left (+x), 1 its right (-x)
constexpr int kLeft = 0, kRight = 1;

// joint angles in rad; zero is standing straight, arms hanging, facing +z with y up
struct MannequinPose {
  std::array<float, 2> shoulderAbduction{0.0f, 0.0f};  // arm raised sideways in the frontal plane (pi/2: T-pose)
  std::array<float, 2> shoulderFlexion{0.0f, 0.0f};    // arm raised forwards (towards +z)
  std::array<float, 2> elbowFlexion{0.0f, 0.0f};       // forearm bent forwards from the upper arm
  std::array<float, 2> hipFlexion{0.0f, 0.0f};         // thigh raised forwards
  std::array<float, 2> kneeFlexion{0.0f, 0.0f};        // shank bent backwards from the thigh
  Vec3 rootOffset{0, 0, 0};                            // m, added to MannequinParams::position
};

struct PoseKey {
  float time = 0.0f;  // s
  MannequinPose pose;
};

// body proportions as fractions of the height (Winter, Biomechanics and Motor Control of Human
// Movement, 4th ed., Fig. 4.1, for lengths; widths and radii of an average adult), so one number
// scales the whole body
struct MannequinParams {
  float height = 1.75f;          // m, soles to the top of the head
  Vec3 position{0, 0, 0};        // m, point between the soles (the body's origin)
  float yaw = 0.0f;              // rad, rotation about +y (0: facing +z)
  MannequinPose pose;            // used when no pose keys are given
  float shoulderWidth = 0.23f;   // biacromial width / height (0.40 m at 1.75 m)
  float hipWidth = 0.19f;        // hip width / height (0.33 m)
  float chestWidth = 0.18f;      // chest width below the armpits / height (0.32 m)
  float chestDepth = 0.13f;      // front-to-back depth of the chest / height (0.23 m)
  float waistWidth = 0.15f;      // / height (0.26 m)
  float headRadius = 0.065f;     // / height (0.114 m)
  float neckRadius = 0.032f;
  float upperArmRadius = 0.025f;
  float forearmRadius = 0.021f;
  float handRadius = 0.03f;
  float thighRadius = 0.045f;
  float shankRadius = 0.032f;
  float footRadius = 0.025f;
  float sampleInterval = 1.0f / 30.0f;  // s between generated collider keys of a motion
  float blend = 0.02f;           // radius of the smooth union of the parts / height (0.035 m); 0: separate parts
};

// the world positions of the joints of a posed body (m), for tests, garments and users
struct MannequinJoints {
  Vec3 headCenter, neckBase, neckTop;
  std::array<Vec3, 2> shoulder, elbow, wrist, hip, knee, ankle;
  Vec3 pelvis;  // midpoint of the hips
};

MannequinJoints mannequinJoints(const MannequinParams& params, const MannequinPose& pose);

// the body as colliders named "<prefix>.<part>" (head, neck, chest, waist, pelvis, upper_arm_l,
// forearm_l, hand_l, thigh_l, shank_l, foot_l and their _r twins, in that order). Without keys the
// body stands in params.pose; with keys (sorted by time) the joint angles and root offset are
// interpolated linearly between keys and every collider gets a keyframe each sampleInterval, so the
// parts stay joined as they move. Throws soak::Error (naming `source`) on a non-positive height or
// radius, or keys out of order.
std::vector<Collider> buildMannequin(const MannequinParams& params, const std::vector<PoseKey>& keys, float friction,
                                     const std::string& prefix = "mannequin", const std::string& source = "mannequin");

// the body as a scene holds it: with params.blend > 0 one Body collider named `prefix` whose parts are
// buildMannequin's colliders joined by a smooth minimum of radius blend * height (a smooth skin that
// the joints move), else buildMannequin's separate parts. Throws as buildMannequin does, and on a
// blend outside [0, 0.1]
std::vector<Collider> mannequinColliders(const MannequinParams& params, const std::vector<PoseKey>& keys,
                                         float friction, const std::string& prefix, const std::string& source);

// the pose at time t of a key list (linear between keys, ends held); params.pose when empty
MannequinPose poseAt(const MannequinParams& params, const std::vector<PoseKey>& keys, double t);

}  // namespace soak
