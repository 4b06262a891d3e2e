// contact of particles with colliders: the margin, the push-out along the path the particle came by
// (no tunnelling at any speed), Coulomb friction the same for any substep, restitution
#include "world/colliders.hpp"

#include "core/friction.hpp"

#include "world/mesh_sdf.hpp"
#include "world/mesh_sequence.hpp"

#include "support/colliders.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

namespace soak {
namespace {

using testing::cubeMesh;
using testing::expectVec;
using testing::makeCollider;

Model planeModel(float friction) {
  Model m;
  m.water.spacing = 0.02f;
  Collider c = makeCollider(ColliderShape::Plane);
  c.friction = c.staticFriction = friction;
  m.colliders.push_back(c);
  ClothPiece piece;
  piece.material.thickness = 0.01f;
  piece.material.friction = piece.material.staticFriction = 0.0f;
  m.pieces.push_back(piece);
  return m;
}

std::vector<ColliderPose> posesAt(const Model& m, double t) {
  std::vector<ColliderPose> poses;
  for (const Collider& c : m.colliders) poses.push_back(colliderPose(c, t));
  return poses;
}

TEST(ColliderContact, MarginsOfWaterAndCloth) {
  Model m = planeModel(0.0f);
  EXPECT_FLOAT_EQ(contactMargin(m, kWaterPhase), 0.01f);
  EXPECT_FLOAT_EQ(contactMargin(m, 1), 0.005f);
  m.pieces[0].material.thickness = 0.0f;
  EXPECT_FLOAT_EQ(contactMargin(m, 1), 1e-4f);
}

TEST(ColliderContact, ParticleBelowPlaneEndsAtMargin) {
  const Model m = planeModel(0.0f);
  Particles p;
  p.add(kWaterPhase, 0, 0.008f, 0.04f, Vec3(0, 0.05f, 0), Vec3::Zero());
  p.add(kWaterPhase, 1, 0.008f, 0.04f, Vec3(1, 0.05f, 0), Vec3::Zero());
  p.add(1, 2, 0.006f, 0.0f, Vec3(2, 0.05f, 0), Vec3::Zero());
  p.xPred[0] = Vec3(0, -0.03f, 0);
  p.xPred[1] = Vec3(1, 0.04f, 0);  // clear of the plane
  p.xPred[2] = Vec3(2, -0.1f, 0);  // cloth: margin is half its thickness
  std::vector<Vec3> normals;
  projectColliders(m, posesAt(m, 0.0), p, 0.01f, normals);
  ASSERT_EQ(normals.size(), 3u);
  EXPECT_NEAR(p.xPred[0].y(), contactMargin(m, kWaterPhase), 1e-6f);
  expectVec(normals[0], Vec3(0, 1, 0), 0.0f);
  expectVec(p.xPred[1], Vec3(1, 0.04f, 0), 0.0f);
  expectVec(normals[1], Vec3::Zero(), 0.0f);
  EXPECT_NEAR(p.xPred[2].y(), 0.005f, 1e-6f);
}

TEST(ColliderContact, PinnedParticlesAreUntouched) {
  const Model m = planeModel(1.0f);
  Particles p;
  p.add(1, 0, 0.0f, 0.0f, Vec3(0, 0.05f, 0), Vec3::Zero());  // mass 0 -> invMass 0
  ASSERT_EQ(p.invMass[0], 0.0f);
  p.xPred[0] = Vec3(0.1f, -0.3f, 0);
  std::vector<Vec3> normals;
  projectColliders(m, posesAt(m, 0.0), p, 0.01f, normals);
  expectVec(p.xPred[0], Vec3(0.1f, -0.3f, 0), 0.0f);
  expectVec(normals[0], Vec3::Zero(), 0.0f);
}

// a container wall crossed past its middle within one substep is nearer its far face: the particle
// goes back out through the face it came in by, from inside the container and from outside alike
TEST(ColliderContact, ThinWallCrossedPastItsMiddleSendsTheParticleBack) {
  Model m = planeModel(0.0f);
  m.colliders[0] = makeCollider(ColliderShape::Container);
  m.colliders[0].halfExtents = Vec3(0.5f, 0.25f, 0.5f);
  m.colliders[0].wallThickness = 0.04f;  // the +x wall spans x = 0.50 .. 0.54, its middle 0.52
  m.colliders[0].friction = 0.0f;
  const float margin = contactMargin(m, kWaterPhase);
  Particles p;
  p.add(kWaterPhase, 0, 0.008f, 0.04f, Vec3(0.49f, 0.0f, 0.1f), Vec3::Zero());  // inside, 0.01 from the wall
  p.add(kWaterPhase, 1, 0.008f, 0.04f, Vec3(0.56f, 0.0f, 0.1f), Vec3::Zero());  // outside
  p.add(kWaterPhase, 2, 0.008f, 0.04f, Vec3(0.49f, 0.0f, -0.1f), Vec3::Zero());  // inside, not past the middle
  p.xPred[0] = Vec3(0.525f, 0.0f, 0.1f);
  p.xPred[1] = Vec3(0.515f, 0.0f, 0.1f);
  p.xPred[2] = Vec3(0.515f, 0.0f, -0.1f);
  std::vector<Vec3> normals;
  projectColliders(m, posesAt(m, 0.0), p, 0.015f, normals);
  expectVec(p.xPred[0], Vec3(0.5f - margin, 0.0f, 0.1f), 1e-6f);
  expectVec(normals[0], Vec3(-1, 0, 0), 0.0f);
  expectVec(p.xPred[1], Vec3(0.54f + margin, 0.0f, 0.1f), 1e-6f);
  expectVec(normals[1], Vec3(1, 0, 0), 0.0f);
  expectVec(p.xPred[2], Vec3(0.5f - margin, 0.0f, -0.1f), 1e-6f);
  // a particle driven at the wall at 2 m/s, a 0.03 m substep: it stays in the container
  Particles q;
  q.add(kWaterPhase, 0, 0.008f, 0.04f, Vec3(0.40f, 0.0f, 0.0f), Vec3(2.0f, 0.0f, 0.0f));
  const float dt = 0.015f;
  for (int step = 0; step < 10; ++step) {
    q.v[0] = Vec3(2.0f, 0.0f, 0.0f);
    q.xPred[0] = q.x[0] + dt * q.v[0];
    projectColliders(m, posesAt(m, step * dt), q, dt, normals);
    q.x[0] = q.xPred[0];
    ASSERT_LE(q.x[0].x(), 0.5f - margin + 1e-6f) << "step " << step;
  }
}

// the step's order for the particles of p: gravity, x* = x + h v, the colliders at the substep's end,
// v = (x* - x) / h, x = x*
void simulate(const Model& m, Particles& p, float h, int substeps, uint64_t* putBack = nullptr) {
  std::vector<Vec3> normals;
  for (int s = 0; s < substeps; ++s) {
    for (size_t i = 0; i < p.size(); ++i) {
      p.v[i] += h * m.solver.gravity;
      p.xPred[i] = p.x[i] + h * p.v[i];
    }
    const uint64_t back = projectColliders(m, posesAt(m, (s + 1) * double(h)), p, h, normals);
    if (putBack) *putBack += back;
    for (size_t i = 0; i < p.size(); ++i) {
      p.v[i] = (p.xPred[i] - p.x[i]) / h;
      p.x[i] = p.xPred[i];
    }
  }
}

// a plane through the origin tilted about z so that it rises towards -x at tan(theta) = slope, with
// the collider's and the cloth's coefficients equal (their mix, sqrt(a b), is the same)
Model slopeModel(float slope, FrictionCoefficients mu) {
  Model m = planeModel(0.0f);
  m.colliders[0].keys[0].rotation = Quat(Eigen::AngleAxisf(std::atan(slope), Vec3(0, 0, 1)));
  m.colliders[0].friction = m.pieces[0].material.friction = mu.kinetic;
  m.colliders[0].staticFriction = m.pieces[0].material.staticFriction = mu.staticCoef;
  return m;
}

// Coulomb's law at position level: a particle resting on a slope holds while tan(theta) <= mu_s and
// slides with a = g (sin theta - mu_k cos theta) above it, for any substep (within 2%, past the
// integrator's own a T h / 2)
TEST(ColliderFriction, SlopeHoldsBelowMuStaticAndSlidesWithMuKineticAtAnySubstep) {
  const FrictionCoefficients mu{0.5f, 0.3f};
  const float g = 9.81f, time = 0.5f;
  for (int perSecond : {60, 120, 480, 1920}) {
    const float h = 1.0f / static_cast<float>(perSecond);
    const int n = static_cast<int>(std::lround(time / h));
    for (float slope : {0.4f, 0.7f}) {
      const Model m = slopeModel(slope, mu);
      const Vec3 normal = m.colliders[0].keys[0].rotation * Vec3(0, 1, 0);
      Particles p;
      p.add(1, 0, 0.006f, 0.0f, 0.005f * normal, Vec3::Zero());  // resting at the margin
      simulate(m, p, h, n);
      const float travelled = (p.x[0] - 0.005f * normal).norm();
      const float theta = std::atan(slope);
      // symplectic Euler travels h a (1 + 2 + ... + n) = a T (T + h) / 2
      const float a = g * (std::sin(theta) - mu.kinetic * std::cos(theta));
      const float expected = slope <= mu.staticCoef ? 0.0f : 0.5f * a * time * (time + h);
      EXPECT_NEAR(travelled, expected, 0.02f * expected + 1e-5f) << "slope " << slope << ", " << perSecond << " substeps/s";
      EXPECT_NEAR(p.x[0].dot(normal), 0.005f, 1e-5f);  // stays on the surface
    }
  }
}

// a particle sliding on a floor at v0 stops after v0^2 / (2 mu_k g), less the v0 h / 2 of symplectic
// Euler (the displacement of substep k is h (v0 - k mu_k g h))
TEST(ColliderFriction, SlidingParticleStopsAfterTheCoulombDistance) {
  const float v0 = 1.0f, muK = 0.3f, g = 9.81f;
  for (int perSecond : {60, 240, 960}) {
    const float h = 1.0f / static_cast<float>(perSecond);
    const Model m = slopeModel(0.0f, {muK, muK});
    Particles p;
    p.add(1, 0, 0.006f, 0.0f, Vec3(0, 0.005f, 0), Vec3(v0, 0, 0));
    simulate(m, p, h, perSecond);  // 1 s: it stopped after 0.34 s
    EXPECT_NEAR(p.x[0].x(), v0 * v0 / (2.0f * muK * g) - 0.5f * v0 * h, 0.01f * v0 * v0 / (2.0f * muK * g)) << perSecond;
    EXPECT_NEAR(p.v[0].x(), 0.0f, 1e-6f);
  }
}

// water's coefficient is water.boundaryFriction mixed with the collider's: 0 makes any collider slippery
TEST(ColliderFriction, WaterMixesBoundaryFrictionWithTheCollider) {
  for (float water : {0.0f, 1.0f}) {
    Model m = slopeModel(0.4f, {1.0f, 1.0f});
    m.water.boundaryFriction = water;
    const Vec3 normal = m.colliders[0].keys[0].rotation * Vec3(0, 1, 0);
    Particles p;
    p.add(kWaterPhase, 0, 0.008f, 0.04f, 0.01f * normal, Vec3::Zero());
    simulate(m, p, 0.005f, 100);
    const float theta = std::atan(0.4f);
    const float expected = water > 0.0f ? 0.0f : 0.5f * 9.81f * std::sin(theta) * 0.25f;
    EXPECT_NEAR((p.x[0] - 0.01f * normal).norm(), expected, 0.02f * expected + 1e-5f) << "boundaryFriction " << water;
  }
}

// a particle resting on the floor of m, which slides along x at 0.5 m/s from t = 0, after 0.5 s: on
// the floor, dragged at mu times that speed after losing the distance of catching up at mu g
void expectDraggedAtMuG(const Model& m, float mu) {
  Particles p;
  p.add(1, 0, 0.006f, 0.0f, Vec3(0, 0.005f, 0), Vec3::Zero());
  const float h = 0.002f;
  simulate(m, p, h, 250);  // 0.5 s
  EXPECT_NEAR(p.x[0].y(), 0.005f, 1e-5f);
  const float lag = 0.5f * 0.5f / (2.0f * 9.81f);  // distance lost while catching up
  EXPECT_NEAR(p.x[0].x(), mu * (0.25f - lag), 0.5f * h * 0.5f + 1e-5f) << "mu " << mu;
  EXPECT_NEAR(p.v[0].x(), mu * 0.5f, 1e-3f) << "mu " << mu;
}

// a plane that starts sliding at 0.5 m/s under a resting particle: friction mu = 1 accelerates it at
// most at g, so it catches up after 0.5 / g s and then moves with the plane; mu = 0 leaves it behind
TEST(ColliderFriction, MovingColliderDragsParticleAtMostAtMuG) {
  for (float mu : {0.0f, 1.0f}) {
    Model m = slopeModel(0.0f, {mu, mu});
    m.colliders[0].keys.clear();
    m.colliders[0].keys.push_back(Keyframe{0.0f, Vec3(0, 0, 0), Quat::Identity()});
    m.colliders[0].keys.push_back(Keyframe{1.0f, Vec3(0.5f, 0, 0), Quat::Identity()});
    expectDraggedAtMuG(m, mu);
  }
}

// a mesh sequence's surface carries what rests on it by its vertices' motion, not a rigid pose: a
// slab whose frames slide it along x at 0.5 m/s drags a particle on it up to its speed (mu = 1, as
// MovingColliderDragsParticleAtMostAtMuG), and a slab whose frames lift it lifts the particle
TEST(ColliderFriction, AMeshSequenceCarriesWhatRestsOnIt) {
  TriangleMesh slab = cubeMesh(1.0f);
  for (Vec3& x : slab.vertices) x = Vec3(x.x(), 0.05f * (x.y() - 1.0f), x.z());  // top face at y = 0
  std::vector<TriangleMesh> frames;
  for (int f = 0; f <= 10; ++f) {
    frames.push_back(slab);
    for (Vec3& x : frames.back().vertices) x += Vec3(0.05f * f, 0.0f, 0.0f);  // 0.5 m/s at 10 fps
  }
  Model m = slopeModel(0.0f, {1.0f, 1.0f});
  m.colliders[0] = makeCollider(ColliderShape::MeshSequence);
  m.colliders[0].friction = m.colliders[0].staticFriction = 1.0f;
  m.colliders[0].sequence = std::make_shared<const MeshSequence>(makeMeshSequence(frames, {}, 10.0, 0.0));
  expectDraggedAtMuG(m, 1.0f);
  const float h = 0.002f;
  // lifted at 0.4 m/s for 0.5 s: the particle rides on the top face, at its margin
  for (size_t f = 0; f < frames.size(); ++f)
    for (size_t v = 0; v < slab.vertices.size(); ++v) frames[f].vertices[v] = slab.vertices[v] + Vec3(0, 0.04f * f, 0);
  m.colliders[0].sequence = std::make_shared<const MeshSequence>(makeMeshSequence(frames, {}, 10.0, 0.0));
  Particles q;
  q.add(1, 0, 0.006f, 0.0f, Vec3(0, 0.005f, 0), Vec3::Zero());
  simulate(m, q, h, 250);
  EXPECT_NEAR(q.x[0].y(), 0.2f + 0.005f, 1e-4f);
  EXPECT_NEAR(q.v[0].y(), 0.4f, 1e-2f);
}

// a particle in a container's floor-wall edge, within the margin of both, is pushed out of both in one
// projection, so at rest under gravity it stays still (against the container's single nearest face it
// was pushed out of the floor and the wall in turn and jittered at 0.5 m/s)
TEST(ColliderContact, ContainerEdgePushesOutOfFloorAndWallAtOnce) {
  Model m = planeModel(0.0f);
  m.colliders[0] = makeCollider(ColliderShape::Container);
  m.colliders[0].halfExtents = Vec3(0.2f, 0.3f, 0.2f);
  m.colliders[0].keys[0].translation = Vec3(0, 0.3f, 0);  // floor at y = 0, a wall at x = 0.2
  m.colliders[0].friction = m.colliders[0].staticFriction = 0.0f;
  Particles p;
  p.add(kWaterPhase, 0, 0.008f, 0.04f, Vec3(0.193f, 0.005f, 0.0f), Vec3::Zero());
  std::vector<Vec3> normals;
  projectColliders(m, posesAt(m, 0.0), p, 0.0075f, normals);
  expectVec(p.xPred[0], Vec3(0.19f, 0.01f, 0.0f), 1e-6f);
  p.x[0] = p.xPred[0];
  simulate(m, p, 0.0075f, 40);
  EXPECT_LT(p.v[0].norm(), 1e-4f);
  expectVec(p.x[0], Vec3(0.19f, 0.01f, 0.0f), 1e-5f);
}

// no speed up to solver.maxSpeed carries a particle through a collider in one substep: fired at a
// container wall, a box, a sphere, a capsule, a mesh cube and a mesh sequence's cube at 3 to 50 m/s (0.045 to 0.75 m a
// substep), straight and at 30 degrees to the flat faces, it ends on the near side at the margin, and
// is counted
TEST(ColliderContact, NoSpeedCarriesAParticleThroughAnyCollider) {
  std::vector<Collider> shapes;
  Collider wall = makeCollider(ColliderShape::Container);  // its +x wall spans x = 0.50 .. 0.54
  wall.halfExtents = Vec3(0.5f, 0.5f, 0.5f);
  wall.wallThickness = 0.04f;
  wall.keys[0].translation = Vec3(0, 0.5f, 0);
  Collider box = makeCollider(ColliderShape::Box);
  box.halfExtents = Vec3(0.01f, 0.3f, 0.3f);
  box.keys[0].translation = Vec3(0.51f, 0.4f, 0);
  Collider sphere = makeCollider(ColliderShape::Sphere);
  sphere.radius = 0.03f;
  sphere.keys[0].translation = Vec3(0.53f, 0.4f, 0);
  Collider capsule = makeCollider(ColliderShape::Capsule);
  capsule.radius = 0.02f;
  capsule.halfHeight = 0.3f;
  capsule.keys[0].translation = Vec3(0.52f, 0.4f, 0);
  capsule.keys[0].rotation = Quat(Eigen::AngleAxisf(0.5f * float(M_PI), Vec3(1, 0, 0)));  // along z
  Collider mesh = makeCollider(ColliderShape::Mesh);
  mesh.sdf = std::make_shared<SdfGrid>(buildSdfGrid(cubeMesh(0.1f), 0.01f, 0.05f, "cube"));
  mesh.keys[0].translation = Vec3(0.6f, 0.4f, 0);  // faces at x = 0.5 and 0.7
  Collider sequence = makeCollider(ColliderShape::MeshSequence);  // the same cube, exact, as an animation's frame
  sequence.sequence = std::make_shared<const MeshSequence>(makeMeshSequence({cubeMesh(0.1f)}, {}, 24.0, 0.0));
  sequence.keys[0].translation = Vec3(0.6f, 0.4f, 0);
  for (Collider c : {wall, box, sphere, capsule, mesh, sequence}) {
    c.friction = c.staticFriction = 0.0f;
    const bool flat = c.shape != ColliderShape::Sphere && c.shape != ColliderShape::Capsule;
    for (float speed : {3.0f, 10.0f, 50.0f}) {
      for (float angle : flat ? std::vector<float>{0.0f, 30.0f} : std::vector<float>{0.0f}) {
        Model m = planeModel(0.0f);
        m.colliders = {c};
        const Vec3 dir(std::cos(angle * float(M_PI) / 180.0f), 0.0f, std::sin(angle * float(M_PI) / 180.0f));
        Particles p;
        p.add(kWaterPhase, 0, 0.008f, 0.04f, Vec3(0.48f, 0.4f, 0.0f) - 0.01f * dir, speed * dir);
        const float h = 0.015f;
        p.xPred[0] = p.x[0] + h * p.v[0];
        std::vector<Vec3> normals;
        const uint64_t back = projectColliders(m, posesAt(m, 0.0), p, h, normals);
        const std::string what = "shape " + std::to_string(int(c.shape)) + " at " + std::to_string(speed) +
                                 " m/s, " + std::to_string(angle) + " deg";
        EXPECT_LT(p.xPred[0].x(), 0.5f) << what;  // on the near side
        EXPECT_GE(colliderDistance(c, posesAt(m, 0.0)[0], p.xPred[0], nullptr), 0.01f - 2e-4f) << what;
        EXPECT_EQ(back, 1u) << what;
      }
    }
  }
}

TEST(ColliderRestitution, ZeroKillsAndOneReversesInwardNormalVelocity) {
  for (float e : {0.0f, 1.0f}) {
    Model m = planeModel(0.0f);
    m.colliders[0].restitution = e;
    Particles p;
    p.add(kWaterPhase, 0, 0.008f, 0.04f, Vec3(0, 0.01f, 0), Vec3(1, -2, 0));
    p.add(kWaterPhase, 1, 0.008f, 0.04f, Vec3(1, 0.01f, 0), Vec3(1, 2, 0));   // leaving: kept
    p.add(kWaterPhase, 2, 0.008f, 0.04f, Vec3(2, 0.01f, 0), Vec3(1, -2, 0));  // no contact: kept
    const std::vector<Vec3> normals = {Vec3(0, 1, 0), Vec3(0, 1, 0), Vec3::Zero()};
    applyColliderRestitution(m, posesAt(m, 0.0), normals, p);
    expectVec(p.v[0], Vec3(1, 2 * e, 0), 1e-6f);
    expectVec(p.v[1], Vec3(1, 2, 0), 0.0f);
    expectVec(p.v[2], Vec3(1, -2, 0), 0.0f);
  }
}

TEST(ColliderRestitution, RelativeToAMovingColliderAndItsOwnCoefficient) {
  Model m = planeModel(0.0f);
  m.colliders[0].keys.clear();
  m.colliders[0].keys.push_back(Keyframe{0.0f, Vec3(0, 0, 0), Quat::Identity()});
  m.colliders[0].keys.push_back(Keyframe{1.0f, Vec3(0, 1, 0), Quat::Identity()});  // rises at 1 m/s
  m.colliders[0].restitution = 0.0f;
  Collider far = makeCollider(ColliderShape::Sphere);  // not the contact: its restitution is unused
  far.restitution = 1.0f;
  far.keys[0].translation = Vec3(5, 5, 5);
  m.colliders.push_back(far);
  Particles p;
  p.add(kWaterPhase, 0, 0.008f, 0.04f, Vec3(0, 0.51f, 0), Vec3::Zero());
  const std::vector<Vec3> normals = {Vec3(0, 1, 0)};
  applyColliderRestitution(m, posesAt(m, 0.5), normals, p);
  expectVec(p.v[0], Vec3(0, 1, 0), 1e-6f);  // now moves with the floor
}

}  // namespace
}  // namespace soak
