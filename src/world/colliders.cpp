// rigid colliders: keyframed poses, exact signed distance functions, contact projection with
// friction, restitution. Shapes live in the collider's local frame (see model.hpp).
#include "world/colliders.hpp"

#include "world/container.hpp"
#include "world/mesh_sdf.hpp"

#include "core/parallel.hpp"

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
  }
  *n = Vec3(0, 1, 0);
  return p.y();
}

}  // namespace

ColliderPose colliderPose(const Collider& c, double t) { return keyframedPose(c.keys, t); }

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
  const Vec3 local = pose.rotation.conjugate() * (p - pose.translation);
  Vec3 nLocal;
  const float d = localDistance(c, local, &nLocal);
  if (normal) *normal = pose.rotation * nLocal;
  return d;
}

namespace {

// the box sdf of boxDistance without its normal, in plain floats for omp simd
[[gnu::always_inline]] inline float boxSdf(float rx, float ry, float rz, float hx, float hy, float hz) {
  const float qx = std::fabs(rx) - hx, qy = std::fabs(ry) - hy, qz = std::fabs(rz) - hz;
  const float ox = std::max(qx, 0.0f), oy = std::max(qy, 0.0f), oz = std::max(qz, 0.0f);
  return std::sqrt(ox * ox + oy * oy + oz * oz) + std::min(std::max(qx, std::max(qy, qz)), 0.0f);
}

}  // namespace

void colliderDistanceBounds(const Collider& c, const ColliderPose& pose, const float* X, int64_t n, float* out) {
  if (c.shape == ColliderShape::Mesh) {
    parallelFor(n, [&](int64_t i) {
      out[i] = std::min(out[i], colliderDistance(c, pose, Vec3(X[3 * i], X[3 * i + 1], X[3 * i + 2]), nullptr));
    });
    return;
  }
  // local = R^T (x - t), R^T as a matrix
  const Eigen::Matrix3f rt = pose.rotation.normalized().toRotationMatrix().transpose();
  const float r00 = rt(0, 0), r01 = rt(0, 1), r02 = rt(0, 2), r10 = rt(1, 0), r11 = rt(1, 1), r12 = rt(1, 2),
              r20 = rt(2, 0), r21 = rt(2, 1), r22 = rt(2, 2);
  const float tx = pose.translation.x(), ty = pose.translation.y(), tz = pose.translation.z();
  const ColliderShape shape = c.shape;
  const float radius = c.radius, halfHeight = c.halfHeight;
  // a box is a container of one wall
  int walls = 1;
  float cx[kContainerWalls] = {}, cy[kContainerWalls] = {}, cz[kContainerWalls] = {};
  float hx[kContainerWalls] = {c.halfExtents.x()}, hy[kContainerWalls] = {c.halfExtents.y()},
        hz[kContainerWalls] = {c.halfExtents.z()};
  if (shape == ColliderShape::Container) {
    Vec3 centers[kContainerWalls], halves[kContainerWalls];
    containerWalls(c, centers, halves);
    walls = kContainerWalls;
    for (int k = 0; k < walls; ++k)
      cx[k] = centers[k].x(), cy[k] = centers[k].y(), cz[k] = centers[k].z(), hx[k] = halves[k].x(),
      hy[k] = halves[k].y(), hz[k] = halves[k].z();
  }
  constexpr int64_t kChunk = 256;
  parallelFor((n + kChunk - 1) / kChunk, [&](int64_t chunk) {
    const int64_t begin = chunk * kChunk, count = std::min(n, begin + kChunk) - begin;
    const float* const x = X + 3 * begin;
    float* const o = out + begin;
    // one plain loop per shape (a loop with an inner loop does not vectorise)
    alignas(64) float lx[kChunk], ly[kChunk], lz[kChunk], d[kChunk];
#pragma omp simd
    for (int64_t i = 0; i < count; ++i) {
      const float dx = x[3 * i] - tx, dy = x[3 * i + 1] - ty, dz = x[3 * i + 2] - tz;
      lx[i] = r00 * dx + r01 * dy + r02 * dz;
      ly[i] = r10 * dx + r11 * dy + r12 * dz;
      lz[i] = r20 * dx + r21 * dy + r22 * dz;
    }
    if (shape == ColliderShape::Plane) {
#pragma omp simd
      for (int64_t i = 0; i < count; ++i) d[i] = ly[i];
    } else if (shape == ColliderShape::Sphere) {
#pragma omp simd
      for (int64_t i = 0; i < count; ++i) d[i] = std::sqrt(lx[i] * lx[i] + ly[i] * ly[i] + lz[i] * lz[i]) - radius;
    } else if (shape == ColliderShape::Capsule) {
#pragma omp simd
      for (int64_t i = 0; i < count; ++i) {
        const float ay = ly[i] - std::clamp(ly[i], -halfHeight, halfHeight);
        d[i] = std::sqrt(lx[i] * lx[i] + ay * ay + lz[i] * lz[i]) - radius;
      }
    } else {
      for (int k = 0; k < walls; ++k) {
        const float ckx = cx[k], cky = cy[k], ckz = cz[k], hkx = hx[k], hky = hy[k], hkz = hz[k];
        const bool first = k == 0;
#pragma omp simd
        for (int64_t i = 0; i < count; ++i) {
          const float dk = boxSdf(lx[i] - ckx, ly[i] - cky, lz[i] - ckz, hkx, hky, hkz);
          d[i] = first || dk < d[i] ? dk : d[i];
        }
      }
    }
#pragma omp simd
    for (int64_t i = 0; i < count; ++i) {
      const float v = d[i] - kDistanceBoundSlack;
      o[i] = v < o[i] ? v : o[i];
    }
  });
}

}  // namespace soak
