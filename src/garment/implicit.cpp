// backward Euler step of Chen et al. 2012 Eq. 1-5 (Baraff & Witkin 1998) with KES springs,
// Rayleigh damping (Eq. 22-24), filtered constraints and wet-friction contact
#include "garment/implicit.hpp"
#include "garment/contact_rows.hpp"
#include "garment/strain_limit.hpp"

#include <soak/error.hpp>

#include "core/lap_clock.hpp"
#include "core/parallel.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace soak {

namespace {

void require(bool ok, const std::string& where, const std::string& key, const std::string& expected, double got) {
  if (!ok) throw Error(fmt::format("{}.{}: expected {}, got {}", where, key, expected, got));
}

}  // namespace

void checkGarmentParams(const GarmentParams& p, const std::string& where) {
  const std::pair<const char*, const KesLaw*> laws[] = {
      {"stretch", &p.laws.stretch}, {"shear", &p.laws.shear}, {"bend", &p.laws.bend}};
  for (const auto& [name, law] : laws) {
    require(law->a1 > 0.0f, where, std::string(name) + ".a1", "a number > 0 (N/m)", law->a1);
    require(law->a2 >= 0.0f, where, std::string(name) + ".a2", "a number >= 0", law->a2);
  }
  require(p.laws.strainLimit > 0.0f && p.laws.strainLimit < 1.0f, where, "strainLimit", "a number in (0, 1)",
          p.laws.strainLimit);
  require(p.laws.seamStiffness > 0.0f, where, "seams.stiffness", "a number > 0 (N/m)", p.laws.seamStiffness);
  require(p.seams.closeTime >= 0.0f, where, "seams.closeTime", "a number >= 0 (s)", p.seams.closeTime);
  require(p.seams.settleTime >= 0.0f, where, "seams.settleTime", "a number >= 0 (s)", p.seams.settleTime);
  require(p.build.bendStraightness >= 0.0f && p.build.bendStraightness <= 1.0f, where, "bendStraightness",
          "a number in [0, 1]", p.build.bendStraightness);
  require(p.saturation.delta >= 0.0f, where, "saturation.delta", "a number >= 0", p.saturation.delta);
  require(p.saturation.a3 > 0.0f, where, "saturation.a3", "a number > 0", p.saturation.a3);
  require(p.saturation.timeScale > 0.0f, where, "saturation.timeScale", "a number > 0 (s)", p.saturation.timeScale);
  const WetFrictionParams& f = p.friction;
  require(f.dry >= 0.0f, where, "friction.dry", "a number >= 0", f.dry);
  require(f.peak >= 0.0f, where, "friction.peak", "a number >= 0", f.peak);
  require(f.plateau >= 0.0f, where, "friction.plateau", "a number >= 0", f.plateau);
  require(f.peakSaturation > 0.0f && f.peakSaturation < 1.0f, where, "friction.peakSaturation", "a number in (0, 1)",
          f.peakSaturation);
  require(f.plateauSaturation > f.peakSaturation && f.plateauSaturation <= 1.0f, where, "friction.plateauSaturation",
          fmt::format("a number in (friction.peakSaturation ({}), 1]", f.peakSaturation), f.plateauSaturation);
  require(p.rayleighAlpha >= 0.0f, where, "rayleighAlpha",
          "a number >= 0 (1/s; a negative alpha adds energy: the paper's -9 is a typo)", p.rayleighAlpha);
  require(p.rayleighBeta >= 0.0f, where, "rayleighBeta", "a number >= 0 (s)", p.rayleighBeta);
  require(p.cgTolerance > 0.0f, where, "cgTolerance", "a number > 0", p.cgTolerance);
  require(p.cgMaxIterations >= 1, where, "cgMaxIterations", "an integer >= 1", p.cgMaxIterations);
  require(p.wrinkles.compressionThreshold > 0.0f, where, "wrinkles.compressionThreshold", "a number > 0",
          p.wrinkles.compressionThreshold);
  require(p.wrinkles.equilibriumSpeed >= 0.0f, where, "wrinkles.equilibriumSpeed", "a number >= 0 (m/s)",
          p.wrinkles.equilibriumSpeed);
  require(p.wrinkles.tieTolerance >= 0.0f, where, "wrinkles.tieTolerance", "a number >= 0", p.wrinkles.tieTolerance);
  require(p.wrinkles.interval >= 1, where, "wrinkles.interval", "an integer >= 1", p.wrinkles.interval);
  require(p.wrinkles.strength > 0.0f && p.wrinkles.strength <= 1.0f, where, "wrinkles.strength", "a number in (0, 1]",
          p.wrinkles.strength);
  require(p.wrinkles.dryStrength >= 0.0f && p.wrinkles.dryStrength <= p.wrinkles.strength, where,
          "wrinkles.dryStrength", fmt::format("a number in [0, wrinkles.strength ({})]", p.wrinkles.strength),
          p.wrinkles.dryStrength);
  require(p.wrinkles.patchSize >= 3, where, "wrinkles.patchSize", "an integer >= 3", p.wrinkles.patchSize);
}

GarmentPiece buildGarmentPiece(const Model& model, int piece, const GarmentParams& params) {
  GarmentPiece g;
  const ClothPiece& pc = model.pieces[static_cast<size_t>(piece)];
  g.piece = piece;
  g.firstParticle = pc.firstParticle;
  g.count = pc.particleCount;
  g.springs = buildPieceSprings(model, piece, params.build);
  const SpringSet& sp = g.springs;
  g.rowStart.resize(static_cast<size_t>(g.count) + 1);
  for (int v = 0; v <= g.count; ++v) g.rowStart[v] = sp.vertexStart[v] + v;
  g.col.resize(static_cast<size_t>(g.rowStart[g.count]));
  for (int v = 0; v < g.count; ++v) {
    int k = g.rowStart[v];
    g.col[k++] = v;
    for (int e = sp.vertexStart[v]; e < sp.vertexStart[v + 1]; ++e) g.col[k++] = sp.other(sp.vertexSpring[e], v);
  }
  std::vector<std::array<int, 3>> tris(static_cast<size_t>(pc.triangleCount));
  for (int t = 0; t < pc.triangleCount; ++t)
    for (int k = 0; k < 3; ++k) tris[t][k] = model.triangles[pc.firstTriangle + t][k] - pc.firstParticle;
  g.subdomains = splitIntoPatches(g.count, tris, params.wrinkles.patchSize);
  g.mesh = buildSelfCollisionMesh(g.count, std::move(tris), pc.seams);
  return g;
}

namespace {

// forces and stiffness per spring (Eq. 12-13; a seam's pull towards `seamOpen` times its starting
// gap), each spring writes only its own slot; the strain range of the stretch springs to stats
void springForces(const GarmentPiece& g, const GarmentParams& params, float seamOpen, const Particles& p,
                  ImplicitScratch& w, ImplicitStats& stats) {
  const SpringSet& sp = g.springs;
  const int ns = sp.size();
  const size_t first = static_cast<size_t>(g.firstParticle);
  w.springForce.resize(static_cast<size_t>(ns));
  w.springStiffness.resize(static_cast<size_t>(ns));
  w.strain.resize(static_cast<size_t>(ns));
  parallelFor(ns, [&](int64_t s) {
    const Vec3& xi = p.x[first + sp.ids[s][0]];
    const Vec3& xj = p.x[first + sp.ids[s][1]];
    if (s >= sp.kindStart[3]) {
      seamForce(params.laws.seamStiffness, seamOpen * sp.restLength[s], xi, xj, w.springForce[s], &w.springStiffness[s]);
      w.strain[s] = 0.0f;
      return;
    }
    w.strain[s] = springForce(sp, params.laws, static_cast<int>(s), xi, xj, w.springForce[s], &w.springStiffness[s]);
  });
  if (sp.kindStart[1] > 0) {
    const auto [lo, hi] = std::minmax_element(w.strain.begin(), w.strain.begin() + sp.kindStart[1]);
    stats.minStrain = *lo;
    stats.maxStrain = *hi;
  }
}

// constrained rows: pinned vertices stay (dv = -v0, constrained 1), disturbed vertices reach their
// target (constrained 2)
void constrainRows(const Model& model, const GarmentPiece& g, const std::vector<PositionConstraint>& constraints,
                   const Particles& p, double hd, ImplicitScratch& w, ImplicitStats& stats) {
  const int n = g.count;
  const size_t first = static_cast<size_t>(g.firstParticle);
  w.constrained.assign(static_cast<size_t>(n), 0);
  w.dv.assign(static_cast<size_t>(n), Vec3d::Zero());
  for (int v = 0; v < n; ++v)
    if (model.clothPinned[first + v]) {
      w.constrained[v] = 1;
      w.dv[v] = -p.v[first + v].cast<double>();
    }
  for (const PositionConstraint& c : constraints) {
    if (c.vertex < 0 || c.vertex >= n || w.constrained[c.vertex] == 1) continue;
    w.constrained[c.vertex] = 2;
    const size_t i = first + c.vertex;
    w.dv[c.vertex] = ((c.target - p.x[i]).cast<double>() / hd) - p.v[i].cast<double>();
  }
  for (uint8_t c : w.constrained) stats.constrainedVertices += c ? 1 : 0;
}

// A = M (1 + h alpha) + (h beta + h^2) K, b = h (f0 + h df/dx v0), gathered per row (Eq. 3-4);
// gravityScale 0 while a sewn garment's seams close (SeamParams::gravityWhileClosing)
void assembleSystem(const Model& model, const GarmentPiece& g, const GarmentParams& params, const Particles& p,
                    double hd, double gravityScale, ImplicitScratch& w) {
  const SpringSet& sp = g.springs;
  const size_t first = static_cast<size_t>(g.firstParticle);
  const double alpha = params.rayleighAlpha, beta = params.rayleighBeta;
  const double kScale = hd * beta + hd * hd;  // coefficient of K in A: h beta (damping) + h^2 (df/dx)
  const Vec3d gravity = gravityScale * model.solver.gravity.cast<double>();
  w.A.rows = g.count;
  w.A.rowStart = g.rowStart;
  w.A.col = g.col;
  w.A.block.resize(g.col.size());
  w.rhs.resize(static_cast<size_t>(g.count));
  parallelFor(g.count, [&](int64_t v) {
    const size_t i = first + static_cast<size_t>(v);
    const double m = p.mass[i];
    const Vec3d v0 = p.v[i].cast<double>();
    Vec3d f = m * gravity - alpha * m * v0;  // gravity and the mass part of the damping (Eq. 24)
    Eigen::Matrix3d kDiag = Eigen::Matrix3d::Zero();
    Vec3d kv = Vec3d::Zero();  // (K v0)_v
    int slot = g.rowStart[v] + 1;
    for (int e = sp.vertexStart[v]; e < sp.vertexStart[v + 1]; ++e, ++slot) {
      const int s = sp.vertexSpring[e];
      const int o = sp.other(s, static_cast<int>(v));
      const Eigen::Matrix3d& K = w.springStiffness[s];
      f += (sp.ids[s][0] == v) ? w.springForce[s] : Vec3d(-w.springForce[s]);
      kDiag += K;
      kv += K * (v0 - p.v[first + o].cast<double>());
      w.A.block[slot] = -kScale * K;
    }
    w.A.block[g.rowStart[v]] = (m * (1.0 + hd * alpha)) * Eigen::Matrix3d::Identity() + kScale * kDiag;
    // f0 includes the stiffness damping -beta K v0; h df/dx v0 = -h K v0
    w.rhs[v] = hd * (f - (beta + hd) * kv);
  });
}

// a vertex at x, just pushed out by `pushed` along the outward normal nrm of collider c (its surface
// moving at vCol): the velocity into the collider is removed and Coulomb friction (the fabric's mixed
// with the collider's) acts on the slip, with the removed normal velocity as its impulse; x gives back
// the slip friction removed while in contact. The vertex was in contact for the part of the step the
// push undid, pushed / (inward speed), not the whole step: a vertex that arrived mid-step had slipped
// for only that long (docs/garment.md departure 9; the whole step moved a landing patch's vertices
// inward by h v_t and compressed its springs by h v / R, which bounced the Fig. 8 silk off the ball)
void contactResponse(const Collider& collider, const Vec3& vCol, const Vec3& nrm, float muFabric, float h, float pushed,
                     Vec3& x, Vec3& vel) {
  Vec3 rel = vel - vCol;
  const float dvn = std::max(-rel.dot(nrm), 0.0f);
  rel += dvn * nrm;  // the inward velocity is removed
  const Vec3 after = coulombFriction(rel, nrm, mixFriction(muFabric, collider.friction), dvn);
  const float inContact = dvn * h > pushed ? pushed / dvn : h;
  x += inContact * (after - rel);  // friction acted while in contact: the slip it removed is not travelled
  vel = vCol + after;
}

// v1 = v0 + dv, x1 = x0 + h v1 to p.xPred and p.v; then a vertex that ends within the margin of a
// collider is put back out to it, with the fabric's wet friction (w.fabricMu) against any collider but
// its contact row's (whose friction was in the solve); marks the vertices in contact with 3 in
// w.constrained
void integrateWithContact(const Model& model, const GarmentPiece& g, float h, const std::vector<ColliderPose>& poses,
                          Particles& p, ImplicitScratch& w) {
  const size_t first = static_cast<size_t>(g.firstParticle);
  const size_t numColliders = std::min(model.colliders.size(), poses.size());
  const float margin = contactMargin(model, static_cast<int32_t>(g.piece + 1));
  std::vector<uint8_t>& touched = w.constrained;  // reused: 3 = in contact this step
  parallelFor(g.count, [&](int64_t v) {
    const size_t i = first + static_cast<size_t>(v);
    if (w.constrained[v] == 1) {  // pinned: never moves
      p.xPred[i] = p.x[i];
      p.v[i].setZero();
      return;
    }
    Vec3 vel = (p.v[i].cast<double>() + w.dv[v]).cast<float>();
    Vec3 x = p.x[i] + h * vel;
    if (w.constrained[v] == 2) {  // disturbed: reaches its target exactly, keeps its velocity (departure 14)
      p.xPred[i] = x;
      return;
    }
    const float muFabric = w.fabricMu[static_cast<size_t>(v)];
    const int held = isContactRow(w.constrained[v]) ? w.contactCollider[v] : -1;  // friction was in the solve
    if (held >= 0 && w.frictionImpulse[v].squaredNorm() > 0.0) {  // sliding: friction never reverses the slip
      const Vec3 n = w.contactNormal[v].cast<float>(), along = w.frictionImpulse[v].normalized().cast<float>();
      const Vec3 rel = vel - w.contactVelocity[v];
      if (rel.dot(along) > 0.0f) {  // the last round's friction overshot: the vertex stops on the surface
        const Vec3 stopped = rel.dot(n) * n;
        x += h * (stopped - rel);
        vel = w.contactVelocity[v] + stopped;
      }
    }
    bool contact = held >= 0;
    for (size_t c = 0; c < numColliders; ++c) {
      Vec3 nrm, vCol;
      const Vec3 inside = x;
      if (!pushOutOf(model.colliders[c], poses[c], margin, x, &nrm, &vCol)) continue;  // project out to the margin
      contact = true;
      contactResponse(model.colliders[c], vCol, nrm, static_cast<int>(c) == held ? 0.0f : muFabric, h,
                      (x - inside).dot(nrm), x, vel);
    }
    p.xPred[i] = x;
    p.v[i] = vel;
    if (contact) touched[v] = 3;
  });
}

// contact of the mesh edges between the vertices (garment.edgeContact): a body part narrower than an
// edge, or a curve of one, passes between two vertices that are both outside it. Each edge's midpoint
// within the margin of a collider is moved out to it along the normal, the edge's free vertices alike
// (one free vertex moves twice as far, so the midpoint still reaches the margin), and their velocity
// into the collider is removed (no friction: the vertices' own contact has it). Gauss-Seidel over the
// edges in spring order, serial: the same result for any thread count. Only edges whose midpoint's
// distance lower bound (colliderDistanceBounds, vectorised) is under twice the margin are visited (a
// neighbour's push moves a midpoint by about the margin). Returns the edges pushed.
int pushEdgesOut(const Model& model, const GarmentPiece& g, const std::vector<ColliderPose>& poses, Particles& p,
                 ImplicitScratch& w) {
  const float margin = contactMargin(model, static_cast<int32_t>(g.piece + 1));
  const size_t first = static_cast<size_t>(g.firstParticle);
  const size_t numColliders = std::min(model.colliders.size(), poses.size());
  const int edges = g.springs.kindStart[1];  // the stretch springs: every mesh edge
  if (numColliders == 0 || edges == 0) return 0;
  Vec3* x = p.xPred.data() + first;
  Vec3* v = p.v.data() + first;
  w.edgeMid.resize(static_cast<size_t>(edges));
  w.edgeBound.assign(static_cast<size_t>(edges), std::numeric_limits<float>::max());
  for (int e = 0; e < edges; ++e) w.edgeMid[e] = 0.5f * (x[g.springs.ids[e][0]] + x[g.springs.ids[e][1]]);
  for (size_t c = 0; c < numColliders; ++c)
    colliderDistanceBounds(model.colliders[c], poses[c], w.edgeMid[0].data(), edges, w.edgeBound.data());
  const auto moves = [&](int u) { return w.constrained[u] != 1 && w.constrained[u] != 2; };  // not pinned, not disturbed
  int pushed = 0;
  for (int e = 0; e < edges; ++e) {
    if (w.edgeBound[e] >= 2.0f * margin) continue;
    const int a = g.springs.ids[e][0], b = g.springs.ids[e][1];
    const bool ma = moves(a), mb = moves(b);
    if (!ma && !mb) continue;
    for (size_t c = 0; c < numColliders; ++c) {
      const Vec3 mid = 0.5f * (x[a] + x[b]);
      Vec3 nrm, out = mid;
      if (!pushOutOf(model.colliders[c], poses[c], margin, out, &nrm)) continue;  // the midpoint's push
      const Vec3 push = (out - mid) * (ma && mb ? 1.0f : 2.0f);
      for (const auto& [u, free] : {std::pair{a, ma}, std::pair{b, mb}}) {
        if (!free) continue;
        x[u] += push;
        contactResponse(model.colliders[c], colliderVelocity(model.colliders[c], poses[c], x[u]), nrm, 0.0f, 0.0f, 0.0f,
                        x[u], v[u]);  // frictionless: no slip removed
      }
      ++pushed;
    }
  }
  return pushed;
}

// 1/m of each vertex of the piece into w.invMass, 0 for pinned and disturbed vertices (they keep their
// place): the weights of the strain limiting and the self-collision
void fillInverseMasses(const GarmentPiece& g, const Particles& p, ImplicitScratch& w) {
  const size_t first = static_cast<size_t>(g.firstParticle);
  w.invMass.resize(static_cast<size_t>(g.count));
  for (int v = 0; v < g.count; ++v)
    w.invMass[v] = (w.constrained[v] == 1 || w.constrained[v] == 2) ? 0.0f : 1.0f / p.mass[first + v];
}

// the vertices marked in `moved` (and free) are put back out of the colliders, position only, no
// friction: their contact this step already had it
void pushMovedOut(const Model& model, const GarmentPiece& g, const std::vector<ColliderPose>& poses,
                  const std::vector<uint8_t>& moved, Particles& p, const ImplicitScratch& w) {
  const size_t first = static_cast<size_t>(g.firstParticle);
  const float margin = contactMargin(model, static_cast<int32_t>(g.piece + 1));
  const size_t numColliders = std::min(model.colliders.size(), poses.size());
  for (int v = 0; v < g.count; ++v) {
    if (!moved[v] || w.invMass[v] == 0.0f) continue;
    for (size_t c = 0; c < numColliders; ++c) {
      Vec3 nrm, vCol;
      if (!pushOutOf(model.colliders[c], poses[c], margin, p.xPred[first + v], &nrm, &vCol)) continue;
      contactResponse(model.colliders[c], vCol, nrm, 0.0f, 0.0f, 0.0f, p.xPred[first + v], p.v[first + v]);
    }
  }
}

// strain limiting (strain_limit.hpp), then the vertices it moved are put back out of the colliders;
// returns the springs shortened
int strainLimitStep(const Model& model, const GarmentPiece& g, const GarmentParams& params, float h,
                    const std::vector<ColliderPose>& poses, Particles& p, ImplicitScratch& w) {
  const size_t first = static_cast<size_t>(g.firstParticle), n = static_cast<size_t>(g.count);
  const int shortened = limitStrain(g.springs, params.laws, w.invMass, h, std::span(p.xPred).subspan(first, n),
                                    std::span(p.v).subspan(first, n), w.strainMoved);
  if (shortened > 0) pushMovedOut(model, g, poses, w.strainMoved, p, w);
  return shortened;
}

// self-collision of the piece (self_collision.hpp), then the vertices it moved are put back out of
// the colliders
SelfCollisionPushes selfCollisionStep(const Model& model, const GarmentPiece& g, const std::vector<ColliderPose>& poses,
                                      Particles& p, ImplicitScratch& w) {
  const float thickness = model.pieces[static_cast<size_t>(g.piece)].material.thickness;
  const SelfCollisionPushes pushes = selfCollide(g.mesh, g.firstParticle, g.count, w.invMass, thickness, p, w.self);
  if (pushes.vertexTriangle + pushes.edgeEdge + pushes.reverted > 0) pushMovedOut(model, g, poses, w.self.moved, p, w);
  return pushes;
}

// the share of its starting gap a seam's rest length still has at `time`
float seamOpenFraction(const SeamParams& seams, double time) {
  return seams.closeTime > 0.0f ? static_cast<float>(std::max(0.0, 1.0 - time / seams.closeTime)) : 0.0f;
}

}  // namespace

ImplicitStats implicitStep(const Model& model, const GarmentPiece& g, const GarmentParams& params, float h, double time,
                           const std::vector<ColliderPose>& poses, std::span<const float> saturation,
                           const std::vector<PositionConstraint>& constraints, Particles& p, ImplicitScratch& w,
                           std::span<Vec3> velocityChange) {
  ImplicitStats stats;
  LapClock clock;  // the step's parts, ImplicitStats::ms*
  const double hd = h;
  const bool sewn = g.springs.kindStart[4] > g.springs.kindStart[3];
  const bool sewing = sewn && time < params.seams.closeTime;
  // the panels slide into place without friction until settleTime after the seams close: the contact
  // rows' Coulomb friction would hold the seams' last millimetres open (docs/garment.md departure 9)
  const bool frictionless = sewn && time < params.seams.closeTime + params.seams.settleTime;
  springForces(g, params, seamOpenFraction(params.seams, time), p, w, stats);
  constrainRows(model, g, constraints, p, hd, w, stats);
  const bool warm = params.cgWarmStart && velocityChange.size() == static_cast<size_t>(g.count);
  for (int v = 0; warm && v < g.count; ++v)  // the free rows start from the last step's dv (warm start)
    if (w.constrained[v] == kFreeRow) w.dv[v] = velocityChange[v].cast<double>();
  assembleSystem(model, g, params, p, hd, sewing && !params.seams.gravityWhileClosing ? 0.0 : 1.0, w);
  w.fabricMu.assign(static_cast<size_t>(g.count), 0.0f);
  for (int v = 0; !frictionless && v < g.count; ++v)
    w.fabricMu[v] = wetFriction(static_cast<size_t>(v) < saturation.size() ? saturation[v] : 0.0f, params.friction);
  contactRows(model, g, poses, p, h, w.fabricMu, w);
  stats.msAssemble += clock.lap();
  const std::span<const Vec3> v0(p.v.data() + g.firstParticle, static_cast<size_t>(g.count));
  solveWithContact(params, v0, w, stats);
  stats.msCg += clock.lap();
  if (velocityChange.size() == static_cast<size_t>(g.count))
    for (int v = 0; v < g.count; ++v) velocityChange[v] = w.dv[v].cast<float>();
  integrateWithContact(model, g, h, poses, p, w);
  fillInverseMasses(g, p, w);
  if (params.strainLimiting) stats.strainLimited = strainLimitStep(model, g, params, h, poses, p, w);  // departure 2
  if (params.edgeContact) stats.edgeContacts = pushEdgesOut(model, g, poses, p, w);
  stats.msIntegrate += clock.lap();
  if (model.pieces[static_cast<size_t>(g.piece)].material.selfCollision) {
    const SelfCollisionPushes pushes = selfCollisionStep(model, g, poses, p, w);
    stats.selfContacts = pushes.vertexTriangle;
    stats.selfEdgeContacts = pushes.edgeEdge;
    stats.selfReverted = pushes.reverted;
  }
  stats.msSelfContact += clock.lap();
  for (uint8_t c : w.constrained) stats.contacts += c == 3 ? 1 : 0;
  return stats;
}

ImplicitStats garmentSubstep(const Model& model, const GarmentPiece& g, const GarmentParams& params,
                             std::span<const float> saturation, float h, double time, uint64_t stepIndex,
                             const std::vector<ColliderPose>& poses, Particles& p, ImplicitScratch& scratch,
                             std::span<Vec3> velocityChange) {
  LapClock clock;
  if (params.saturationMass) applySaturationMass(model, g.piece, saturation, params.saturation, p);  // Eq. 15-19
  const std::vector<PositionConstraint> wrinkles = computeDisturbances(model, g.piece, g.springs, g.subdomains, p, poses,
                                                                       params.wrinkles, stepIndex, saturation);  // 3.5
  const double msBefore = clock.lap();  // part of the assembly
  ImplicitStats s =
      implicitStep(model, g, params, h, time, poses, saturation, wrinkles, p, scratch, velocityChange);  // Eq. 1-5
  s.msAssemble += msBefore;
  s.disturbances = static_cast<int>(wrinkles.size());
  return s;
}

double garmentEnergy(const Model& model, const GarmentPiece& g, const GarmentParams& params, const Particles& p) {
  const size_t first = static_cast<size_t>(g.firstParticle);
  const Vec3d gravity = model.solver.gravity.cast<double>();
  double e = elasticEnergy(g.springs, params.laws, p.x.data() + first);
  for (int v = 0; v < g.count; ++v) {
    const size_t i = first + static_cast<size_t>(v);
    const double m = p.mass[i];
    e += 0.5 * m * p.v[i].cast<double>().squaredNorm() - m * gravity.dot(p.x[i].cast<double>());
  }
  return e;
}

}  // namespace soak
