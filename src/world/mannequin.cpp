// procedural mannequin: joint positions from segment lengths (fractions of the height) and joint
// angles, then one capsule or sphere per body part. A motion is sampled into collider keyframes at a
// fixed interval, so each part's keys follow the joint chain (linear keys between samples).
#include "world/mannequin.hpp"

#include "world/colliders.hpp"

#include <soak/error.hpp>

#include <cmath>

namespace soak {

namespace {

// segment lengths and landmark heights as fractions of the height (Winter Fig. 4.1)
constexpr float kHeadTop = 1.0f;
constexpr float kAcromion = 0.818f;  // top of the shoulder
constexpr float kNeckBase = 0.80f;
constexpr float kNeckTop = 0.90f;
constexpr float kUpperArm = 0.186f;
constexpr float kForearm = 0.146f;
constexpr float kHandCenter = 0.045f;  // wrist to the middle of the hand
constexpr float kHipJoint = 0.52f;
constexpr float kThigh = 0.245f;
constexpr float kFootBack = 0.03f;     // heel behind the ankle
constexpr float kFootFront = 0.10f;    // toes in front of the ankle
// torso stack: horizontal capsules (along x) from the shoulders down
constexpr float kChestY = 0.70f, kWaistY = 0.61f, kPelvisY = 0.53f;
constexpr float kYokeRadius = 0.04f;
constexpr float kWaistRadius = 0.055f, kPelvisRadius = 0.06f;

Quat axisAngle(float angle, const Vec3& axis) { return Quat(Eigen::AngleAxisf(angle, axis)); }

// the rotations of the limb segments; each maps the hanging direction -y to the segment's direction
struct LimbFrames {
  std::array<Quat, 2> upperArm, forearm, thigh, shank;
};

LimbFrames limbFrames(const MannequinPose& pose) {
  LimbFrames f;
  for (int s = 0; s < 2; ++s) {
    const float side = s == kLeft ? 1.0f : -1.0f;
    // abduction about +z (left arm towards +x), flexion about -x (towards +z)
    f.upperArm[s] = axisAngle(side * pose.shoulderAbduction[s], Vec3::UnitZ()) *
                    axisAngle(-pose.shoulderFlexion[s], Vec3::UnitX());
    f.forearm[s] = f.upperArm[s] * axisAngle(-pose.elbowFlexion[s], Vec3::UnitX());
    f.thigh[s] = axisAngle(-pose.hipFlexion[s], Vec3::UnitX());
    f.shank[s] = f.thigh[s] * axisAngle(pose.kneeFlexion[s], Vec3::UnitX());
  }
  return f;
}

struct Part {
  std::string name;
  ColliderShape shape;
  float radius, halfHeight;
  Vec3 center;    // body frame, m
  Quat rotation;  // body frame; local +y is the capsule axis
};

// every part in the body frame (origin between the soles, before yaw and position)
std::vector<Part> bodyParts(const MannequinParams& mp, const MannequinPose& pose) {
  const float H = mp.height;
  const LimbFrames f = limbFrames(pose);
  const Vec3 down(0, -1, 0);
  const Quat alongX = axisAngle(-0.5f * kPi, Vec3::UnitZ());  // local y -> +x
  const Quat flipY = axisAngle(kPi, Vec3::UnitX());            // local y -> -y
  const Quat yToZ = axisAngle(0.5f * kPi, Vec3::UnitX());      // local y -> +z
  const float shoulderX = (0.5f * mp.shoulderWidth - mp.upperArmRadius) * H;
  const float shoulderY = (kAcromion - mp.upperArmRadius) * H;
  const float hipX = (0.5f * mp.hipWidth - mp.thighRadius) * H;
  const float shank = (kHipJoint - kThigh - mp.footRadius) * H;  // ankle at the foot's axis height

  std::vector<Part> parts;
  auto capsule = [&](const std::string& name, float r, const Vec3& a, const Vec3& b, const Quat& q) {
    parts.push_back({name, ColliderShape::Capsule, r, 0.5f * (b - a).norm(), 0.5f * (a + b), q});
  };
  auto horizontal = [&](const std::string& name, float r, float halfWidth, float y) {
    parts.push_back({name, ColliderShape::Capsule, r, std::max(halfWidth - r, 1e-3f * H), Vec3(0, y, 0), alongX});
  };
  parts.push_back({"head", ColliderShape::Sphere, mp.headRadius * H, 0.0f,
                   Vec3(0, (kHeadTop - mp.headRadius) * H, 0), Quat::Identity()});
  capsule("neck", mp.neckRadius * H, Vec3(0, kNeckBase * H, 0), Vec3(0, kNeckTop * H, 0), Quat::Identity());
  // the yoke spans both shoulder joints, its top at the acromion
  parts.push_back({"yoke", ColliderShape::Capsule, kYokeRadius * H, shoulderX,
                   Vec3(0, (kAcromion - kYokeRadius) * H, 0), alongX});
  horizontal("chest", 0.5f * mp.chestDepth * H, 0.5f * mp.chestWidth * H, kChestY * H);
  horizontal("waist", kWaistRadius * H, 0.5f * mp.waistWidth * H, kWaistY * H);
  horizontal("pelvis", kPelvisRadius * H, 0.5f * mp.hipWidth * H, kPelvisY * H);
  for (int s = 0; s < 2; ++s) {
    const float side = s == kLeft ? 1.0f : -1.0f;
    const std::string tag = s == kLeft ? "_l" : "_r";
    const Vec3 shoulder(side * shoulderX, shoulderY, 0);
    const Vec3 elbow = shoulder + kUpperArm * H * (f.upperArm[s] * down);
    const Vec3 wrist = elbow + kForearm * H * (f.forearm[s] * down);
    capsule("upper_arm" + tag, mp.upperArmRadius * H, shoulder, elbow, f.upperArm[s] * flipY);
    capsule("forearm" + tag, mp.forearmRadius * H, elbow, wrist, f.forearm[s] * flipY);
    parts.push_back({"hand" + tag, ColliderShape::Sphere, mp.handRadius * H, 0.0f,
                     wrist + kHandCenter * H * (f.forearm[s] * down), Quat::Identity()});
  }
  for (int s = 0; s < 2; ++s) {
    const float side = s == kLeft ? 1.0f : -1.0f;
    const std::string tag = s == kLeft ? "_l" : "_r";
    const Vec3 hip(side * hipX, kHipJoint * H, 0);
    const Vec3 knee = hip + kThigh * H * (f.thigh[s] * down);
    const Vec3 ankle = knee + shank * (f.shank[s] * down);
    const Vec3 forward = f.shank[s] * Vec3::UnitZ();
    capsule("thigh" + tag, mp.thighRadius * H, hip, knee, f.thigh[s] * flipY);
    // a shank thicker than the foot stops short of the ankle so it does not reach below the sole
    const Vec3 shankEnd = ankle - std::max(mp.shankRadius - mp.footRadius, 0.0f) * H * (f.shank[s] * down);
    capsule("shank" + tag, mp.shankRadius * H, knee, shankEnd, f.shank[s] * flipY);
    capsule("foot" + tag, mp.footRadius * H, ankle - kFootBack * H * forward, ankle + kFootFront * H * forward,
            f.shank[s] * yToZ);
  }
  return parts;
}

Quat rootRotation(const MannequinParams& mp) { return axisAngle(mp.yaw, Vec3::UnitY()); }

Vec3 rootTranslation(const MannequinParams& mp, const MannequinPose& pose) { return mp.position + pose.rootOffset; }

template <class T>
T mix(const T& a, const T& b, float s) {
  return a + s * (b - a);
}

MannequinPose mixPose(const MannequinPose& a, const MannequinPose& b, float s) {
  MannequinPose p;
  for (int k = 0; k < 2; ++k) {
    p.shoulderAbduction[k] = mix(a.shoulderAbduction[k], b.shoulderAbduction[k], s);
    p.shoulderFlexion[k] = mix(a.shoulderFlexion[k], b.shoulderFlexion[k], s);
    p.elbowFlexion[k] = mix(a.elbowFlexion[k], b.elbowFlexion[k], s);
    p.hipFlexion[k] = mix(a.hipFlexion[k], b.hipFlexion[k], s);
    p.kneeFlexion[k] = mix(a.kneeFlexion[k], b.kneeFlexion[k], s);
  }
  p.rootOffset = mix<Vec3>(a.rootOffset, b.rootOffset, s);
  return p;
}

void checkParams(const MannequinParams& mp, const std::vector<PoseKey>& keys, const std::string& source) {
  const std::string where = "mannequin";
  if (!(mp.height > 0.0f) || !std::isfinite(mp.height))
    throw errorAt(source, where + ".height", "must be a positive height in m");
  const std::pair<const char*, float> fractions[] = {
      {"shoulderWidth", mp.shoulderWidth}, {"hipWidth", mp.hipWidth},         {"chestWidth", mp.chestWidth},
      {"chestDepth", mp.chestDepth},       {"waistWidth", mp.waistWidth},     {"headRadius", mp.headRadius},
      {"neckRadius", mp.neckRadius},       {"upperArmRadius", mp.upperArmRadius}, {"forearmRadius", mp.forearmRadius},
      {"handRadius", mp.handRadius},       {"thighRadius", mp.thighRadius},   {"shankRadius", mp.shankRadius},
      {"footRadius", mp.footRadius}};
  for (const auto& [name, value] : fractions)
    if (!(value > 0.0f && value < 0.5f))
      throw errorAt(source, where + "." + name, "must be a fraction of the height in (0, 0.5)");
  if (!(mp.blend >= 0.0f && mp.blend <= 0.1f))
    throw errorAt(source, where + ".blend", "must be a fraction of the height in [0, 0.1]");
  if (!(mp.sampleInterval > 0.0f)) throw errorAt(source, where + ".sampleInterval", "must be > 0 s");
  for (size_t k = 1; k < keys.size(); ++k)
    if (!(keys[k].time >= keys[k - 1].time))
      throw errorAt(source, where + ".keyframes[" + std::to_string(k) + "].time",
                    "keyframe times must not decrease");
  if (keys.size() > 1) {
    const double samples = (keys.back().time - keys.front().time) / mp.sampleInterval;
    if (samples > 1e5)
      throw errorAt(source, where + ".sampleInterval", "the motion would need more than 1e5 samples; raise it");
  }
}

}  // namespace

MannequinPose poseAt(const MannequinParams& params, const std::vector<PoseKey>& keys, double t) {
  if (keys.empty()) return params.pose;
  if (t <= keys.front().time) return keys.front().pose;
  if (t >= keys.back().time) return keys.back().pose;
  size_t k = 1;
  while (keys[k].time <= t) ++k;
  const double span = keys[k].time - keys[k - 1].time;
  const float s = span > 0.0 ? static_cast<float>((t - keys[k - 1].time) / span) : 1.0f;
  return mixPose(keys[k - 1].pose, keys[k].pose, s);
}

MannequinJoints mannequinJoints(const MannequinParams& mp, const MannequinPose& pose) {
  const float H = mp.height;
  const LimbFrames f = limbFrames(pose);
  const Quat root = rootRotation(mp);
  const Vec3 origin = rootTranslation(mp, pose);
  auto world = [&](const Vec3& b) { return Vec3(origin + root * b); };
  const Vec3 down(0, -1, 0);
  MannequinJoints j;
  j.headCenter = world(Vec3(0, (kHeadTop - mp.headRadius) * H, 0));
  j.neckBase = world(Vec3(0, kNeckBase * H, 0));
  j.neckTop = world(Vec3(0, kNeckTop * H, 0));
  const float shoulderX = (0.5f * mp.shoulderWidth - mp.upperArmRadius) * H;
  const float hipX = (0.5f * mp.hipWidth - mp.thighRadius) * H;
  const float shank = (kHipJoint - kThigh - mp.footRadius) * H;
  for (int s = 0; s < 2; ++s) {
    const float side = s == kLeft ? 1.0f : -1.0f;
    const Vec3 sh(side * shoulderX, (kAcromion - mp.upperArmRadius) * H, 0);
    const Vec3 el = sh + kUpperArm * H * (f.upperArm[s] * down);
    const Vec3 hip(side * hipX, kHipJoint * H, 0);
    const Vec3 knee = hip + kThigh * H * (f.thigh[s] * down);
    j.shoulder[s] = world(sh);
    j.elbow[s] = world(el);
    j.wrist[s] = world(el + kForearm * H * (f.forearm[s] * down));
    j.hip[s] = world(hip);
    j.knee[s] = world(knee);
    j.ankle[s] = world(knee + shank * (f.shank[s] * down));
  }
  j.pelvis = 0.5f * (j.hip[0] + j.hip[1]);
  return j;
}

std::vector<Collider> buildMannequin(const MannequinParams& params, const std::vector<PoseKey>& keys, float friction,
                                     const std::string& prefix, const std::string& source) {
  checkParams(params, keys, source);
  // sample times: the rest pose alone, or the keys' span every sampleInterval (and its end)
  std::vector<double> times;
  if (keys.size() <= 1) {
    times.push_back(keys.empty() ? 0.0 : keys.front().time);
  } else {
    const double t0 = keys.front().time, t1 = keys.back().time;
    const int64_t n = static_cast<int64_t>(std::ceil((t1 - t0) / params.sampleInterval - 1e-6));
    for (int64_t k = 0; k < n; ++k) times.push_back(t0 + static_cast<double>(k) * params.sampleInterval);
    times.push_back(t1);
  }
  std::vector<Collider> colliders;
  const Quat root = rootRotation(params);
  for (size_t s = 0; s < times.size(); ++s) {
    const MannequinPose pose = poseAt(params, keys, times[s]);
    const std::vector<Part> parts = bodyParts(params, pose);
    const Vec3 origin = rootTranslation(params, pose);
    if (s == 0) {
      colliders.resize(parts.size());
      for (size_t p = 0; p < parts.size(); ++p) {
        Collider& c = colliders[p];
        c.name = prefix + "." + parts[p].name;
        c.shape = parts[p].shape;
        c.radius = parts[p].radius;
        c.halfHeight = parts[p].halfHeight;
        c.friction = friction;
        c.staticFriction = friction;
        c.restitution = 0.0f;
      }
    }
    for (size_t p = 0; p < parts.size(); ++p) {
      Keyframe key;
      key.time = static_cast<float>(times[s]);
      key.translation = origin + root * parts[p].center;
      key.rotation = (root * parts[p].rotation).normalized();
      colliders[p].keys.push_back(key);
    }
  }
  return colliders;
}

std::vector<Collider> mannequinColliders(const MannequinParams& params, const std::vector<PoseKey>& keys,
                                         float friction, const std::string& prefix, const std::string& source) {
  std::vector<Collider> parts = buildMannequin(params, keys, friction, prefix, source);
  if (params.blend == 0.0f) return parts;
  return {makeBodyCollider(prefix, std::move(parts), params.blend * params.height, source)};
}

}  // namespace soak
