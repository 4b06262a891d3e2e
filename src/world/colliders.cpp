// colliders: keyframed poses, exact signed distance functions (a Body's: the smooth union of its
// parts'), surface velocities. Shapes live in the collider's local frame (see model.hpp).
#include "world/colliders.hpp"

#include "world/container.hpp"
#include "world/mesh_sdf.hpp"
#include "world/mesh_sequence.hpp"
#include "world/smooth_min.hpp"

#include "core/parallel.hpp"

#include <soak/error.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace soak {

namespace {

// rotation part of q1 * q0^-1 as a world-frame rotation vector (axis * angle), shortest way round
Vec3 rotationVector(const Quat& q0, const Quat& q1) {
  Quat rel = q1.normalized() * q0.normalized().conjugate();
  if (rel.w() < 0.0f) rel.coeffs() = -rel.coeffs();
  const Vec3 im = rel.vec();
  const float s = im.norm();
  // angle = 2 atan2(|v|, w); at small angles angle / |v| -> 2
  if (s < 1e-12f) return 2.0f * im;
  return im * (2.0f * std::atan2(s, rel.w()) / s);
}

// exact sdf of an axis-aligned box of half extents h centred at c (Quilez), with its gradient
float boxDistance(const Vec3& p, const Vec3& c, const Vec3& h, Vec3* n) {
  const Vec3 r = p - c;
  const Vec3 q = r.cwiseAbs() - h;
  const Vec3 out = q.cwiseMax(0.0f);
  const float outLen = out.norm();
  if (outLen > 0.0f) {
    // outside: gradient points from the nearest box point to p
    for (int a = 0; a < 3; ++a) (*n)[a] = r[a] < 0.0f ? -out[a] / outLen : out[a] / outLen;
    return outLen;
  }
  // inside (or on the surface): the nearest face is the axis of largest q; ties take the lower axis
  int axis = 0;
  if (q[1] > q[axis]) axis = 1;
  if (q[2] > q[axis]) axis = 2;
  *n = Vec3::Zero();
  (*n)[axis] = r[axis] < 0.0f ? -1.0f : 1.0f;
  return q[axis];
}

float localDistance(const Collider& c, const Vec3& p, Vec3* n) {
  switch (c.shape) {
    case ColliderShape::Plane:
      *n = Vec3(0, 1, 0);
      return p.y();
    case ColliderShape::Sphere: {
      const float len = p.norm();
      *n = len > 0.0f ? Vec3(p / len) : Vec3(0, 1, 0);
      return len - c.radius;
    }
    case ColliderShape::Capsule: {
      // distance to the segment (0, +-halfHeight, 0) minus the radius
      const Vec3 onAxis(0.0f, std::clamp(p.y(), -c.halfHeight, c.halfHeight), 0.0f);
      const Vec3 r = p - onAxis;
      const float len = r.norm();
      *n = len > 0.0f ? Vec3(r / len) : Vec3(1, 0, 0);
      return len - c.radius;
    }
    case ColliderShape::Box:
      return boxDistance(p, Vec3::Zero(), c.halfExtents, n);
    case ColliderShape::Container: {
      // open-top box: union (min) of a bottom slab and four side walls (world/container.hpp)
      Vec3 centers[kContainerWalls], halves[kContainerWalls];
      containerWalls(c, centers, halves);
      float best = boxDistance(p, centers[0], halves[0], n);
      for (int k = 1; k < kContainerWalls; ++k) {
        Vec3 nk;
        const float dk = boxDistance(p, centers[k], halves[k], &nk);
        if (dk < best) {
          best = dk;
          *n = nk;
        }
      }
      return best;
    }
    case ColliderShape::Mesh:
      // trilinear grid of the closed mesh (world/mesh_sdf.hpp); a mesh without a grid is far away
      if (c.sdf) return sampleSdf(*c.sdf, p, n);
      *n = Vec3(0, 1, 0);
      return 1.0e30f;
    case ColliderShape::Body:          // in world space, from its parts' poses (blendDistance)
    case ColliderShape::MeshSequence:  // from its pose's surface (sequenceDistance)
      break;
  }
  *n = Vec3(0, 1, 0);
  return 1.0e30f;
}

// the pose `local` given relative to `root`, in the world, with the velocities of both motions
ColliderPose composePose(const ColliderPose& root, const ColliderPose& local) {
  ColliderPose w;
  const Vec3 arm = root.rotation * local.translation;
  w.translation = root.translation + arm;
  w.rotation = (root.rotation * local.rotation).normalized();
  w.linearVelocity = root.linearVelocity + root.angularVelocity.cross(arm) + root.rotation * local.linearVelocity;
  w.angularVelocity = root.angularVelocity + root.rotation * local.angularVelocity;
  return w;
}

// a MeshSequence at world point p: the exact distance to its surface at the pose's time (local
// frame), the surface's velocity on top of the rigid motion; a pose without its surface is far
float sequenceDistance(const ColliderPose& pose, const Vec3& p, Vec3* normal, Vec3* velocity) {
  if (!pose.mesh) {
    if (normal) *normal = Vec3(0, 1, 0);
    if (velocity) *velocity = pose.velocityAt(p);
    return 1.0e30f;
  }
  const Vec3 local = pose.rotation.conjugate() * (p - pose.translation);
  Vec3 n, v;
  const float d = pose.mesh->distance(local, normal ? &n : nullptr, velocity ? &v : nullptr);
  if (normal) *normal = pose.rotation * n;
  if (velocity) *velocity = pose.velocityAt(p) + pose.rotation * v;
  return d;
}

// a Body's smooth union at world point p: the parts' distances folded by smoothMin in part order,
// their normals and surface velocities blended with the same weights (the gradient's chain rule);
// `slope`: the gradient's length (<= 1)
float blendDistance(const Collider& c, const ColliderPose& pose, const Vec3& p, Vec3* normal, Vec3* velocity,
                    float* slope = nullptr, std::vector<float>* weights = nullptr) {
  const size_t count = c.parts ? c.parts->size() : 0;
  if (count == 0 || pose.parts.size() != count) {
    if (normal) *normal = Vec3(0, 1, 0);
    if (velocity) *velocity = Vec3::Zero();
    return 1.0e30f;
  }
  Vec3 grad, vel = Vec3::Zero();
  float d = colliderDistance((*c.parts)[0], pose.parts[0], p, &grad);
  if (velocity) vel = pose.parts[0].velocityAt(p);
  if (weights) weights->assign(count, 0.0f), (*weights)[0] = 1.0f;
  for (size_t k = 1; k < count; ++k) {
    Vec3 nk;
    const float dk = colliderDistance((*c.parts)[k], pose.parts[k], p, &nk);
    if (dk - d >= c.blendRadius) continue;  // smoothMin is d here, with weight 0
    float w = 0.0f;
    d = smoothMin(d, dk, c.blendRadius, &w);
    grad += w * (nk - grad);
    if (velocity) vel += w * (pose.parts[k].velocityAt(p) - vel);
    if (weights) {  // each part's share of the blend: the same step for every part so far
      for (size_t j = 0; j < k; ++j) (*weights)[j] *= 1.0f - w;
      (*weights)[k] = w;
    }
  }
  if (normal) {
    // the gradient of a blend of unit normals is shorter than 1, and vanishes only where two
    // opposite normals blend equally (deep inside, or midway across a gap narrower than the blend
    // radius): any unit normal will do there
    const float len = grad.norm();
    *normal = len > 1e-6f ? Vec3(grad / len) : Vec3(0, 1, 0);
    if (slope) *slope = len;
  }
  if (velocity) *velocity = vel;
  return d;
}

}  // namespace

bool ColliderPose::moving() const {
  if (!linearVelocity.isZero() || !angularVelocity.isZero()) return true;
  if (mesh && mesh->maxSpeed > 0.0f) return true;
  return std::any_of(parts.begin(), parts.end(), [](const ColliderPose& q) { return q.moving(); });
}

Collider makeBodyCollider(const std::string& name, std::vector<Collider> parts, float blendRadius,
                          const std::string& source) {
  if (parts.empty()) throw errorAt(source, name, "a body needs at least one part");
  if (!(blendRadius > 0.0f) || !std::isfinite(blendRadius))
    throw errorAt(source, name, fmt::format("expected a blend radius > 0 m, got {}", blendRadius));
  for (const Collider& part : parts)
    if (part.shape != ColliderShape::Sphere && part.shape != ColliderShape::Capsule && part.shape != ColliderShape::Box)
      throw errorAt(source, part.name, "expected a sphere, capsule or box as a part of a body");
  Collider body;
  body.name = name;
  body.shape = ColliderShape::Body;
  body.friction = parts.front().friction;
  body.staticFriction = parts.front().staticFriction;
  body.restitution = parts.front().restitution;
  body.keys = {Keyframe{}};
  body.blendRadius = blendRadius;
  body.parts = std::make_shared<const std::vector<Collider>>(std::move(parts));
  return body;
}

ColliderPose colliderPose(const Collider& c, double t) { return colliderPose(c, c.keys, t); }

ColliderPose colliderPose(const Collider& c, std::span<const Keyframe> keys, double t) {
  ColliderPose pose = keyframedPose(keys, t);
  if (c.shape == ColliderShape::Body && c.parts) {
    pose.parts.reserve(c.parts->size());
    for (const Collider& part : *c.parts) pose.parts.push_back(composePose(pose, keyframedPose(part.keys, t)));
  }
  if (c.shape == ColliderShape::MeshSequence && c.sequence) pose.mesh = std::make_shared<const MeshSnapshot>(c.sequence, t);
  return pose;
}

ColliderPose keyframedPose(std::span<const Keyframe> keys, double t) {
  ColliderPose pose;
  if (keys.empty()) return pose;
  if (keys.size() == 1 || t < keys.front().time) {
    pose.translation = keys.front().translation;
    pose.rotation = keys.front().rotation.normalized();
    return pose;
  }
  if (t >= keys.back().time) {
    pose.translation = keys.back().translation;
    pose.rotation = keys.back().rotation.normalized();
    return pose;
  }
  // first key strictly after t; the segment is [k - 1, k] with time0 <= t < time1, so the first
  // key already moves with its segment's velocity
  const auto it = std::upper_bound(keys.begin(), keys.end(), t,
                                   [](double tt, const Keyframe& k) { return tt < k.time; });
  const Keyframe& k1 = *it;
  const Keyframe& k0 = *(it - 1);
  const double span = static_cast<double>(k1.time) - static_cast<double>(k0.time);
  if (span <= 0.0) {
    pose.translation = k1.translation;
    pose.rotation = k1.rotation.normalized();
    return pose;
  }
  const float s = static_cast<float>((t - k0.time) / span);
  const Quat q0 = k0.rotation.normalized();
  const Quat q1 = k1.rotation.normalized();
  pose.translation = (1.0f - s) * k0.translation + s * k1.translation;
  pose.rotation = q0.slerp(s, q1).normalized();
  pose.linearVelocity = (k1.translation - k0.translation) / static_cast<float>(span);
  pose.angularVelocity = rotationVector(q0, q1) / static_cast<float>(span);
  return pose;
}

float colliderDistance(const Collider& c, const ColliderPose& pose, const Vec3& p, Vec3* normal) {
  if (c.shape == ColliderShape::Body) return blendDistance(c, pose, p, normal, nullptr);
  if (c.shape == ColliderShape::MeshSequence) return sequenceDistance(pose, p, normal, nullptr);
  const Vec3 local = pose.rotation.conjugate() * (p - pose.translation);
  Vec3 nLocal;
  const float d = localDistance(c, local, &nLocal);
  if (normal) *normal = pose.rotation * nLocal;
  return d;
}

bool pushOutOf(const Collider& c, const ColliderPose& pose, float margin, Vec3& x, Vec3* normal, Vec3* velocity) {
  Vec3 nrm;
  if (c.shape == ColliderShape::MeshSequence) {
    // one search for both: the push along the nearest point's normal keeps that nearest point
    Vec3 v;
    const float d = sequenceDistance(pose, x, &nrm, velocity ? &v : nullptr) - margin;
    if (d >= 0.0f) return false;
    x -= d * nrm;
    *normal = nrm;
    if (velocity) *velocity = v + pose.angularVelocity.cross(-d * nrm);  // the rigid field at the pushed x
    return true;
  }
  if (c.shape != ColliderShape::Body) {
    const float d = colliderDistance(c, pose, x, &nrm) - margin;
    if (d >= 0.0f) return false;
    x -= d * nrm;
    *normal = nrm;
    if (velocity) *velocity = colliderVelocity(c, pose, x);
    return true;
  }
  // a Body: the root of s(x + t n) = margin along the start's normal n, bracketed from the Newton
  // step (margin - s) / |grad s| (doubled until outside) and closed by regula falsi (Illinois); x ends
  // on the bracket's outside end, so at a distance in [margin, margin + 1e-3 margin] once it converges
  float slope = 1.0f;
  const float f0 = blendDistance(c, pose, x, &nrm, nullptr, &slope) - margin;
  if (f0 >= 0.0f) return false;
  const auto f = [&](float t) { return colliderDistance(c, pose, x + t * nrm, nullptr) - margin; };
  float tIn = 0.0f, fIn = f0, tOut = -f0 / std::max(slope, 0.25f), fOut = f(tOut);
  for (int k = 0; k < kBodyPushes && fOut < 0.0f; ++k) {
    tIn = tOut, fIn = fOut;
    tOut *= 2.0f;
    fOut = f(tOut);
  }
  int side = 0;           // Illinois: halve the stale end's value when the same end moves twice
  float outside = fOut;   // the outside end's true value (fOut may be halved)
  for (int k = 0; k < 4 * kBodyPushes && outside > 1e-3f * margin; ++k) {
    const float t = tIn - fIn * (tOut - tIn) / (fOut - fIn);
    const float ft = f(t);
    if (ft >= 0.0f) {
      tOut = t, fOut = outside = ft;
      if (side == 1) fIn *= 0.5f;
      side = 1;
    } else {
      tIn = t, fIn = ft;
      if (side == -1) fOut *= 0.5f;
      side = -1;
    }
  }
  x += tOut * nrm;
  *normal = nrm;
  if (velocity) *velocity = colliderVelocity(c, pose, x);
  return true;
}

Vec3 colliderVelocity(const Collider& c, const ColliderPose& pose, const Vec3& p) {
  Vec3 v = pose.velocityAt(p);
  if (c.shape == ColliderShape::Body) blendDistance(c, pose, p, nullptr, &v);
  if (c.shape == ColliderShape::MeshSequence) sequenceDistance(pose, p, nullptr, &v);
  return v;
}

float bodyPartWeights(const Collider& c, const ColliderPose& pose, const Vec3& p, std::vector<float>& weights) {
  if (c.shape != ColliderShape::Body) {
    weights.clear();
    return colliderDistance(c, pose, p, nullptr);
  }
  return blendDistance(c, pose, p, nullptr, nullptr, nullptr, &weights);
}

float colliderSpeedBound(const Collider& c, const ColliderPose& pose, const Vec3& p) {
  float speed = pose.velocityAt(p).norm();
  if (c.shape == ColliderShape::Body)
    for (const ColliderPose& part : pose.parts) speed = std::max(speed, part.velocityAt(p).norm());
  if (pose.mesh) speed += pose.mesh->maxSpeed;
  return speed;
}

float colliderCarry(const Model& model, const std::vector<ColliderPose>& poses, std::span<const uint8_t> include,
                    const Vec3& p, float dt) {
  float carried = 0.0f;
  for (size_t c = 0; c < model.colliders.size() && c < poses.size(); ++c)
    if ((include.empty() || (c < include.size() && include[c])) && poses[c].moving())
      carried = std::max(carried, colliderSpeedBound(model.colliders[c], poses[c], p) * dt);
  return carried;
}

namespace {

// the box sdf of boxDistance without its normal, in plain floats for omp simd
[[gnu::always_inline]] inline float boxSdf(float rx, float ry, float rz, float hx, float hy, float hz) {
  const float qx = std::fabs(rx) - hx, qy = std::fabs(ry) - hy, qz = std::fabs(rz) - hz;
  const float ox = std::max(qx, 0.0f), oy = std::max(qy, 0.0f), oz = std::max(qz, 0.0f);
  return std::sqrt(ox * ox + oy * oy + oz * oz) + std::min(std::max(qx, std::max(qy, qz)), 0.0f);
}

}  // namespace

namespace {

constexpr int64_t kBoundChunk = 256;

// the distances of the `count` points x[3i .. 3i+2] to a plane, sphere, capsule, box or container,
// without normals, into d[i]: one plain loop per shape (a loop with an inner loop does not vectorise)
void chunkDistances(const Collider& c, const ColliderPose& pose, const float* x, int64_t count, float* d) {
  // local = R^T (x - t), R^T as a matrix
  const Eigen::Matrix3f rt = pose.rotation.normalized().toRotationMatrix().transpose();
  const float r00 = rt(0, 0), r01 = rt(0, 1), r02 = rt(0, 2), r10 = rt(1, 0), r11 = rt(1, 1), r12 = rt(1, 2),
              r20 = rt(2, 0), r21 = rt(2, 1), r22 = rt(2, 2);
  const float tx = pose.translation.x(), ty = pose.translation.y(), tz = pose.translation.z();
  const float radius = c.radius, halfHeight = c.halfHeight;
  alignas(64) float lx[kBoundChunk], ly[kBoundChunk], lz[kBoundChunk];
#pragma omp simd
  for (int64_t i = 0; i < count; ++i) {
    const float dx = x[3 * i] - tx, dy = x[3 * i + 1] - ty, dz = x[3 * i + 2] - tz;
    lx[i] = r00 * dx + r01 * dy + r02 * dz;
    ly[i] = r10 * dx + r11 * dy + r12 * dz;
    lz[i] = r20 * dx + r21 * dy + r22 * dz;
  }
  if (c.shape == ColliderShape::Plane) {
#pragma omp simd
    for (int64_t i = 0; i < count; ++i) d[i] = ly[i];
  } else if (c.shape == ColliderShape::Sphere) {
#pragma omp simd
    for (int64_t i = 0; i < count; ++i) d[i] = std::sqrt(lx[i] * lx[i] + ly[i] * ly[i] + lz[i] * lz[i]) - radius;
  } else if (c.shape == ColliderShape::Capsule) {
#pragma omp simd
    for (int64_t i = 0; i < count; ++i) {
      const float ay = ly[i] - std::clamp(ly[i], -halfHeight, halfHeight);
      d[i] = std::sqrt(lx[i] * lx[i] + ay * ay + lz[i] * lz[i]) - radius;
    }
  } else {
    // a box is a container of one wall
    int walls = 1;
    Vec3 centers[kContainerWalls] = {Vec3::Zero()}, halves[kContainerWalls] = {c.halfExtents};
    if (c.shape == ColliderShape::Container) {
      containerWalls(c, centers, halves);
      walls = kContainerWalls;
    }
    for (int k = 0; k < walls; ++k) {
      const float ckx = centers[k].x(), cky = centers[k].y(), ckz = centers[k].z();
      const float hkx = halves[k].x(), hky = halves[k].y(), hkz = halves[k].z();
      const bool first = k == 0;
#pragma omp simd
      for (int64_t i = 0; i < count; ++i) {
        const float dk = boxSdf(lx[i] - ckx, ly[i] - cky, lz[i] - ckz, hkx, hky, hkz);
        d[i] = first || dk < d[i] ? dk : d[i];
      }
    }
  }
}

// a Body's parts folded by smoothMin, as blendDistance does (smoothMin is non-decreasing in both
// arguments, so parts' lower bounds fold into a lower bound); a Body without its parts' poses is far
void bodyChunkDistances(const Collider& c, const ColliderPose& pose, const float* x, int64_t count, float* d) {
  const size_t parts = c.parts ? c.parts->size() : 0;
  if (parts == 0 || pose.parts.size() != parts) {
    std::fill(d, d + count, 1.0e30f);
    return;
  }
  chunkDistances((*c.parts)[0], pose.parts[0], x, count, d);
  alignas(64) float dk[kBoundChunk];
  const float k = c.blendRadius;
  for (size_t p = 1; p < parts; ++p) {
    chunkDistances((*c.parts)[p], pose.parts[p], x, count, dk);
#pragma omp simd
    for (int64_t i = 0; i < count; ++i) {
      float w;
      d[i] = smoothMin(d[i], dk[i], k, &w);
    }
  }
}

}  // namespace

void colliderDistanceBounds(const Collider& c, const ColliderPose& pose, const float* X, int64_t n, float* out) {
  if (c.shape == ColliderShape::Mesh) {
    parallelFor(n, [&](int64_t i) {
      out[i] = std::min(out[i], colliderDistance(c, pose, Vec3(X[3 * i], X[3 * i + 1], X[3 * i + 2]), nullptr));
    });
    return;
  }
  // a mesh sequence is bounded by its box: the box's distance (negative inside) is the nearer
  Collider box;
  ColliderPose boxPose = pose;
  if (c.shape == ColliderShape::MeshSequence) {
    if (!pose.mesh) return;
    box.shape = ColliderShape::Box;
    box.halfExtents = 0.5f * (pose.mesh->hi - pose.mesh->lo);
    boxPose.translation = pose.translation + pose.rotation * (0.5f * (pose.mesh->hi + pose.mesh->lo));
  }
  parallelFor((n + kBoundChunk - 1) / kBoundChunk, [&](int64_t chunk) {
    const int64_t begin = chunk * kBoundChunk, count = std::min(n, begin + kBoundChunk) - begin;
    alignas(64) float d[kBoundChunk];
    if (c.shape == ColliderShape::Body)
      bodyChunkDistances(c, pose, X + 3 * begin, count, d);
    else if (c.shape == ColliderShape::MeshSequence)
      chunkDistances(box, boxPose, X + 3 * begin, count, d);
    else
      chunkDistances(c, pose, X + 3 * begin, count, d);
    float* const o = out + begin;
#pragma omp simd
    for (int64_t i = 0; i < count; ++i) {
      const float v = d[i] - kDistanceBoundSlack;
      o[i] = v < o[i] ? v : o[i];
    }
  });
}

namespace {

// the world box of the local box [lo, hi] at `pose`: centre moved, half extents through |R|
void worldBox(const Vec3& lo, const Vec3& hi, const ColliderPose& pose, Vec3* worldLo, Vec3* worldHi) {
  const Eigen::Matrix3f r = pose.rotation.normalized().toRotationMatrix();
  const Vec3 centre = pose.translation + r * (0.5f * (lo + hi)), half = r.cwiseAbs() * (0.5f * (hi - lo));
  *worldLo = centre - half;
  *worldHi = centre + half;
}

}  // namespace

bool colliderBox(const Collider& c, const ColliderPose& pose, Vec3* lo, Vec3* hi) {
  switch (c.shape) {
    case ColliderShape::Plane: return false;
    case ColliderShape::Sphere:
      *lo = pose.translation - Vec3::Constant(c.radius);
      *hi = pose.translation + Vec3::Constant(c.radius);
      return true;
    case ColliderShape::Capsule: {
      const Vec3 axis = pose.rotation.normalized() * Vec3(0, 1, 0);
      const Vec3 half = axis.cwiseAbs() * c.halfHeight + Vec3::Constant(c.radius);
      *lo = pose.translation - half;
      *hi = pose.translation + half;
      return true;
    }
    case ColliderShape::Box: worldBox(-c.halfExtents, c.halfExtents, pose, lo, hi); return true;
    case ColliderShape::Container: {
      Vec3 centres[kContainerWalls], halves[kContainerWalls];
      containerWalls(c, centres, halves);
      Vec3 l = centres[0] - halves[0], h = centres[0] + halves[0];
      for (int k = 1; k < kContainerWalls; ++k) {
        l = l.cwiseMin(centres[k] - halves[k]);
        h = h.cwiseMax(centres[k] + halves[k]);
      }
      worldBox(l, h, pose, lo, hi);
      return true;
    }
    case ColliderShape::Mesh: {
      if (!c.sdf) return false;
      const Vec3 far = c.sdf->cellSize * Vec3(float(c.sdf->dims[0] - 1), float(c.sdf->dims[1] - 1), float(c.sdf->dims[2] - 1));
      worldBox(c.sdf->origin, c.sdf->origin + far, pose, lo, hi);
      return true;
    }
    case ColliderShape::MeshSequence:
      if (!pose.mesh) return false;
      worldBox(pose.mesh->lo, pose.mesh->hi, pose, lo, hi);
      return true;
    case ColliderShape::Body: {
      // its parts' boxes grown by the blend radius: the skin is within it of the parts' union
      // (smooth_min.hpp: the fold of any number of parts is >= their min - k)
      if (!c.parts || c.parts->empty() || pose.parts.size() != c.parts->size()) return false;
      *lo = Vec3::Constant(std::numeric_limits<float>::max());
      *hi = -*lo;
      for (size_t k = 0; k < c.parts->size(); ++k) {
        Vec3 l, h;
        if (!colliderBox((*c.parts)[k], pose.parts[k], &l, &h)) return false;
        *lo = lo->cwiseMin(l);
        *hi = hi->cwiseMax(h);
      }
      *lo -= Vec3::Constant(c.blendRadius);
      *hi += Vec3::Constant(c.blendRadius);
      return true;
    }
  }
  return false;
}

}  // namespace soak
