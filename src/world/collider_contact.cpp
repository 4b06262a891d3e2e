// contact of particles with the rigid colliders: push-out to a margin along the path the particle
// came by, Coulomb friction (core/friction.hpp), restitution (docs/models.md, "Colliders")
#include "world/colliders.hpp"

#include "core/friction.hpp"
#include "world/container.hpp"
#include "world/mesh_sdf.hpp"
#include "world/mesh_sequence.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

namespace soak {

namespace {

// a convex piece of a collider that the contact treats on its own: the collider itself, or one wall
// of a container (an open container is concave: against its single distance a particle in a corner
// would be pushed out of the floor on one substep and out of the wall on the next, and jitter)
struct ContactPart {
  Collider shape;     // the collider, or one wall of a container as a box
  ColliderPose pose;  // of the shape (for a wall, its centre); the velocity field is the owner's
  size_t owner = 0;   // index of the collider in the model and in poses
  float thickness = 0.0f;  // m, the thinnest the part is (a plane: infinite)
  bool posedAhead = false;  // posed `ahead` seconds after the step's end (kPosedAhead, projectColliders)
};

float thicknessOf(const Collider& c) {
  switch (c.shape) {
    case ColliderShape::Plane: return std::numeric_limits<float>::infinity();
    case ColliderShape::Sphere:
    case ColliderShape::Capsule: return 2.0f * c.radius;
    case ColliderShape::Box: return 2.0f * c.halfExtents.minCoeff();
    case ColliderShape::Container: return c.wallThickness;
    case ColliderShape::Mesh: return c.sdf ? 2.0f * c.sdf->cellSize : std::numeric_limits<float>::infinity();
    case ColliderShape::MeshSequence: return c.sequence ? c.sequence->thickness : std::numeric_limits<float>::infinity();
    case ColliderShape::Body: {
      float thinnest = std::numeric_limits<float>::infinity();
      if (c.parts)
        for (const Collider& part : *c.parts) thinnest = std::min(thinnest, thicknessOf(part));
      return thinnest;
    }
  }
  return 0.0f;
}

std::vector<ContactPart> contactParts(const Model& model, const std::vector<ColliderPose>& poses, size_t count) {
  std::vector<ContactPart> parts;
  for (size_t c = 0; c < count; ++c) {
    const Collider& col = model.colliders[c];
    if (col.shape != ColliderShape::Container) {
      parts.push_back({col, poses[c], c, thicknessOf(col)});
      continue;
    }
    Vec3 centers[kContainerWalls], halves[kContainerWalls];
    containerWalls(col, centers, halves);
    for (int k = 0; k < kContainerWalls; ++k) {
      ContactPart wall;
      wall.shape.shape = ColliderShape::Box;
      wall.shape.halfExtents = halves[k];
      wall.pose = poses[c];
      wall.pose.translation = poses[c].translation + poses[c].rotation * centers[k];
      wall.owner = c;
      wall.thickness = thicknessOf(wall.shape);
      parts.push_back(wall);
    }
  }
  return parts;
}

// the Coulomb coefficients of a particle of `phase` against collider c: the collider's mixed with the
// water's boundaryFriction or the cloth material's (mixFriction, sqrt(a b))
FrictionCoefficients frictionOf(const Model& model, const Collider& c, int32_t phase) {
  const FrictionCoefficients collider{c.staticFriction, c.friction};
  if (isWater(phase)) return mixFriction(collider, FrictionCoefficients{model.water.boundaryFriction, model.water.boundaryFriction});
  const int k = clothPiece(phase);
  if (k < 0 || k >= static_cast<int>(model.pieces.size())) return collider;
  const ClothMaterial& m = model.pieces[k].material;
  return mixFriction(collider, FrictionCoefficients{m.staticFriction, m.friction});
}

// the first point of the path from -> to within `margin` of the part, found by samples closer than
// the part is thick (plus the two margins) and 12 bisections; false when the whole path stays clear
bool firstEntry(const ContactPart& part, const Vec3& from, const Vec3& to, float margin, Vec3* entry) {
  const float length = (to - from).norm();
  const float step = 0.9f * (part.thickness + 2.0f * margin);
  const int samples = std::isfinite(step) && step > 0.0f ? std::max(1, static_cast<int>(std::ceil(length / step))) : 1;
  float outside = 0.0f;
  for (int k = 1; k <= samples; ++k) {
    const float s = static_cast<float>(k) / static_cast<float>(samples);
    if (colliderDistance(part.shape, part.pose, from + s * (to - from), nullptr) >= margin) {
      outside = s;
      continue;
    }
    float inside = s;
    for (int b = 0; b < 12; ++b) {
      const float mid = 0.5f * (outside + inside);
      (colliderDistance(part.shape, part.pose, from + mid * (to - from), nullptr) >= margin ? outside : inside) = mid;
    }
    *entry = from + outside * (to - from);
    return true;
  }
  return false;
}

constexpr int kContactPasses = 3;
constexpr float kRestingBand = 1.01f;  // a start within 1% beyond the margin rests on its nearest face

struct ContactResult {
  bool touched = false;
  bool putBack = false;  // x* was inside the part's surface, or its path went through the part
};

// one particle against one part: x* is put on the tangent plane, at the margin, of the face its path
// entered by (a particle already within the margin at the start of the substep: of the face it rests
// on; one found inside: out along the nearest normal), then Coulomb friction acts on its slip
// relative to the surface. `repeat`: a later pass over the parts, which only pushes out what the
// other parts pushed in (the friction of this substep's contacts has acted)
ContactResult contactWith(const ContactPart& part, const Collider& owner, const ColliderPose& ownerPose, const Vec3& x,
                          Vec3& xp, float margin, float dt, FrictionCoefficients mu, bool repeat, Vec3* normal) {
  ContactResult r;
  Vec3 nrm;
  const float rawEnd = colliderDistance(part.shape, part.pose, xp, &nrm);
  const Vec3 from = x + colliderVelocity(owner, ownerPose, x) * dt;  // the start, carried with the collider
  const float length = (xp - from).norm();
  float d = rawEnd - margin;
  // clear at the end and shorter than the part is thick: it cannot have passed through it
  if (d >= 0.0f && length < part.thickness) return r;
  Vec3 n0;
  const float startDistance = colliderDistance(part.shape, part.pose, from, &n0);
  if (startDistance >= 0.0f) {  // started outside: back on the face the path entered by
    // within the margin at the start (or on it, to 1% of it: a particle resting in contact): the face
    // nearest the start; else the face where the path entered the margin
    Vec3 entry = from;
    float entryDistance = startDistance;
    nrm = n0;
    if (startDistance >= kRestingBand * margin) {
      if (!firstEntry(part, from, xp, margin, &entry)) return r;
      entryDistance = colliderDistance(part.shape, part.pose, entry, &nrm);
    }
    d = (xp - entry).dot(nrm) + entryDistance - margin;  // x*'s height over the entry face's tangent plane, less the margin
    if (d >= (repeat ? -1e-6f * margin : 0.0f)) return r;  // grazed the margin and left it again
    r.putBack = rawEnd < 0.0f || d < -(part.thickness + 2.0f * margin);
  } else if (d >= (repeat ? -1e-6f * margin : 0.0f)) {
    return r;
  } else {
    r.putBack = true;  // found inside: out along the nearest normal
  }
  xp -= d * nrm;
  // still within the margin (a concave mesh, a box's edge that the start's face did not cover, a
  // body's blend that one push along the normal falls short of): the nearest face as well
  const float after = colliderDistance(part.shape, part.pose, xp, &n0);
  if (after < margin - 1e-6f) pushOutOf(part.shape, part.pose, margin, xp, &n0);
  if (!repeat) {
    const Vec3 slip = (xp - x) - colliderVelocity(owner, ownerPose, xp) * dt;  // motion relative to the surface
    xp += coulombFriction(slip, nrm, mu, -d) - slip;                // the normal push -d limits the friction
  }
  *normal = nrm;
  r.touched = true;
  return r;
}

}  // namespace

float contactMargin(const Model& model, int32_t phase) {
  if (isWater(phase)) return 0.5f * model.water.spacing;
  const int k = clothPiece(phase);
  if (k < 0 || k >= static_cast<int>(model.pieces.size())) return 1e-4f;
  return std::max(0.5f * model.pieces[k].material.thickness, 1e-4f);
}

uint64_t projectColliders(const Model& model, const std::vector<ColliderPose>& poses, Particles& p, float dt,
                          std::vector<Vec3>& contactNormal) {
  std::vector<float> distanceBound;
  return projectColliders(model, poses, p, {{0, static_cast<int64_t>(p.size())}}, dt, contactNormal, distanceBound);
}

namespace {

// the contact parts of the colliders that take part (include empty: all) at `poses`
struct ContactSet {
  std::vector<ContactPart> parts;
  std::span<const uint8_t> include;  // the colliders that take part (empty: all)
  bool anyMoves = false;
};

ContactSet contactSet(const Model& model, const std::vector<ColliderPose>& poses, std::span<const uint8_t> include) {
  const size_t count = std::min(model.colliders.size(), poses.size());
  const auto takesPart = [&](size_t c) { return include.empty() || (c < include.size() && include[c]); };
  ContactSet set;
  set.include = include;
  set.parts = contactParts(model, poses, count);
  std::erase_if(set.parts, [&](const ContactPart& part) { return !takesPart(part.owner); });
  for (ContactPart& part : set.parts)
    part.posedAhead = part.owner < include.size() && include[part.owner] == kPosedAhead;
  for (size_t c = 0; c < count; ++c) set.anyMoves = set.anyMoves || (takesPart(c) && poses[c].moving());
  return set;
}

// particle i's step from x to p.xPred[i] against the set (bound: a lower bound of x*'s distance to it,
// 0 for none): x* put out and its friction applied, normal the last contact's; returns whether it was
// put back. A part posed ahead is met `ahead` seconds on (projectColliders)
bool contactParticle(const Model& model, const std::vector<ColliderPose>& poses, const ContactSet& set, Particles& p,
                     int64_t i, const Vec3& x, float dt, float bound, Vec3& normal, float ahead = 0.0f) {
  const float margin = contactMargin(model, p.phase[i]);
  Vec3 xp = p.xPred[i];
  if (bound >= margin) {  // else nothing below can skip the particle
    const float carried = set.anyMoves ? colliderCarry(model, poses, set.include, x, dt) : 0.0f;  // the start's
    if (bound >= margin + (xp - x).norm() + carried) return false;
  }
  // a push out of one part can put x* into another met before it (a container's wall after its
  // neighbour's): up to three passes, each later one over the parts before the last that pushed,
  // only pushing out
  int caught = 0;
  size_t end = set.parts.size();
  for (int pass = 0; pass < kContactPasses && end > 0; ++pass) {
    size_t lastPush = 0;
    for (size_t k = 0; k < end; ++k) {
      const ContactPart& part = set.parts[k];
      const Collider& owner = model.colliders[part.owner];
      // a surface posed ahead: the step carried to it by the surface's velocity, and back after
      const bool carried = part.posedAhead && ahead > 0.0f;
      const Vec3 carry = carried ? Vec3(colliderVelocity(owner, poses[part.owner], xp) * ahead) : Vec3::Zero();
      xp += carry;
      const ContactResult r = contactWith(part, owner, poses[part.owner], x + carry, xp, margin, dt,
                                          frictionOf(model, owner, p.phase[i]), pass > 0, &normal);
      xp -= carry;
      caught += r.putBack ? 1 : 0;
      if (r.touched) lastPush = k;
    }
    end = lastPush;
  }
  p.xPred[i] = xp;
  return caught > 0;
}

}  // namespace

uint64_t projectColliders(const Model& model, const std::vector<ColliderPose>& poses, Particles& p,
                          const std::vector<IndexRange>& moved, float dt, std::vector<Vec3>& contactNormal,
                          std::vector<float>& distanceBound) {
  const int64_t n = static_cast<int64_t>(p.size());
  contactNormal.assign(p.size(), Vec3::Zero());
  const size_t numColliders = std::min(model.colliders.size(), poses.size());
  if (numColliders == 0 || n == 0) return 0;
  // most particles are far from every collider: a vectorised lower bound of the distance of x* first;
  // a point of the path is at most |x* - start| nearer, so beyond margin + that nothing is touched
  distanceBound.assign(p.size(), std::numeric_limits<float>::max());
  for (size_t c = 0; c < numColliders; ++c)
    colliderDistanceBounds(model.colliders[c], poses[c], p.xPred[0].data(), n, distanceBound.data());
  const ContactSet set = contactSet(model, poses, {});
  std::atomic<uint64_t> putBack{0};
  parallelForRanges(moved, [&](int64_t i) {
    if (!(p.invMass[i] > 0.0f)) return;
    if (contactParticle(model, poses, set, p, i, p.x[i], dt, distanceBound[i], contactNormal[i]))
      putBack.fetch_add(1, std::memory_order_relaxed);
  });
  return putBack.load();
}

uint64_t projectColliders(const Model& model, const std::vector<ColliderPose>& poses, Particles& p,
                          std::span<const int> particles, const Vec3* start, std::span<const uint8_t> include,
                          float dt, float ahead) {
  if (particles.empty() || model.colliders.empty() || poses.empty()) return 0;
  const ContactSet set = contactSet(model, poses, include);
  std::atomic<uint64_t> putBack{0};
  parallelFor(static_cast<int64_t>(particles.size()), [&](int64_t k) {
    const int i = particles[k];
    Vec3 normal = Vec3::Zero();
    if (p.invMass[i] > 0.0f && contactParticle(model, poses, set, p, i, start[i], dt, 0.0f, normal, ahead))
      putBack.fetch_add(1, std::memory_order_relaxed);
  });
  return putBack.load();
}

// the collider that made the contact is re-found as the one closest to x* (smallest distance minus
// margin, lowest index on ties), so no per-particle collider index has to be carried
void applyColliderRestitution(const Model& model, const std::vector<ColliderPose>& poses,
                              const std::vector<Vec3>& contactNormal, Particles& p) {
  const size_t numColliders = std::min(model.colliders.size(), poses.size());
  if (numColliders == 0) return;
  const int64_t n = static_cast<int64_t>(std::min(p.size(), contactNormal.size()));
  parallelFor(n, [&](int64_t i) {
    const Vec3& nrm = contactNormal[i];
    if (nrm.squaredNorm() == 0.0f || !(p.invMass[i] > 0.0f)) return;
    const Vec3 xp = p.xPred[i];
    size_t best = 0;
    float bestDist = colliderDistance(model.colliders[0], poses[0], xp, nullptr);
    for (size_t c = 1; c < numColliders; ++c) {
      const float d = colliderDistance(model.colliders[c], poses[c], xp, nullptr);
      if (d < bestDist) {
        bestDist = d;
        best = c;
      }
    }
    const Vec3 vCol = colliderVelocity(model.colliders[best], poses[best], xp);
    const float vn = (p.v[i] - vCol).dot(nrm);
    if (vn >= 0.0f) return;
    // new relative normal velocity = -e vn
    const float e = std::clamp(model.colliders[best].restitution, 0.0f, 1.0f);
    p.v[i] -= (1.0f + e) * vn * nrm;
  });
}

}  // namespace soak
