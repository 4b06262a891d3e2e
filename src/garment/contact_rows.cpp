// contact rows of the implicit step (contact_rows.hpp): which vertices the solve holds on a
// collider, and Coulomb friction on them as an active set over the solve
#include "garment/contact_rows.hpp"

#include "core/friction.hpp"
#include "core/parallel.hpp"

#include <algorithm>

namespace soak {

namespace {

constexpr float kContactBand = 1.25f;  // contactRows' reach, in contact margins (contact_rows.hpp)

// the velocity after the step of a vertex sticking to a surface moving at vCol: the surface's along
// the tangent plane, normalSpeed along the unit normal n
Vec3d stickingVelocity(const Vec3d& n, double normalSpeed, const Vec3& vCol) {
  const Vec3d vc = vCol.cast<double>();
  return normalSpeed * n + (vc - vc.dot(n) * n);
}

// vertex v (in w.contactNormal's band) becomes a contact row: sticking first, moving with the surface,
// where it has friction; else sliding with the prescribed normal speed w.contactSpeed, the tangential
// part of its dv kept as the guess
void holdOnCollider(int v, const Vec3d& v0, ImplicitScratch& w) {
  const Vec3d& n = w.contactNormal[v];
  const double vn = w.contactSpeed[v];
  if (w.contactMu[v].staticCoef > 0.0f || w.contactMu[v].kinetic > 0.0f) {
    w.constrained[v] = kStickRow;
    w.dv[v] = stickingVelocity(n, vn, w.contactVelocity[v]) - v0;
  } else {
    w.constrained[v] = kContactRow;
    w.dv[v] = (vn - v0.dot(n)) * n + (w.dv[v] - w.dv[v].dot(n) * n);
  }
}

// the watched vertices (free, within the band of a collider at the step's start, their own forces
// holding them off it) that the last solve drove into the collider, past its surface, become contact
// rows: the push-out after the solve would otherwise put them back alone, and the springs to their
// neighbours, solved for where they would have gone, end stretched. Returns whether any was added.
bool addDrivenRows(std::span<const Vec3> v0, ImplicitScratch& w) {
  bool added = false;
  for (int v = 0; v < w.A.rows; ++v) {
    if (w.constrained[v] != kFreeRow || w.watchedCollider[v] < 0) continue;
    const Vec3d start = v0[static_cast<size_t>(v)].cast<double>();
    if ((start + w.dv[v]).dot(w.contactNormal[v]) >= w.throughSpeed[v]) continue;
    w.contactCollider[v] = w.watchedCollider[v];
    w.watchedCollider[v] = -1;
    holdOnCollider(v, start, w);
    added = true;
  }
  return added;
}

// (A dv - b) of row v: the impulse the row's constraint applies (zero on a free row)
Vec3d rowResidual(const BlockMatrix& A, const std::vector<Vec3d>& dv, const std::vector<Vec3d>& b, int v) {
  Vec3d sum = -b[v];
  for (int k = A.rowStart[v]; k < A.rowStart[v + 1]; ++k) sum += A.block[k] * dv[A.col[k]];
  return sum;
}

// m/s: a sliding row's slip along its friction after the solve must exceed this to count as reversed; a
// round whose solve did not move the row (zero iterations at the loose round tolerance) leaves it at
// the sticking velocity it had, slip zero, which rounding made flip between sticking and sliding
constexpr double kSlipReversed = 1e-6;

// Coulomb friction inside the solve, as an active set over the contact rows (Baraff & Witkin 1998
// section 5.3 release a row by the sign of its force; friction applied after the solve moved held
// vertices back against neighbours the solve had let them drag: docs/garment.md departure 10). After
// a solve each row's constraint impulse r = A dv - b (b holding a sliding row's friction) is split
// into its support N = n . r and its tangential part T:
//   N < 0 (the row pulls the vertex into the collider): released, a free vertex, watched (addDrivenRows);
//   sticking, |T| > mu_s N: it slides, with the kinetic impulse mu_k N T/|T| added to its b;
//   sliding, its slip after the solve along its friction (friction reversed the slip, by more than
//   kSlipReversed): it sticks;
//   sliding otherwise: its friction impulse follows the new support, mu_k N.
// v0: the piece's velocities at the start of the step; impulseChange receives each row's change of
// friction impulse. Returns whether a row changed kind.
bool updateContactRows(std::span<const Vec3> v0, ImplicitScratch& w, std::vector<Vec3d>& impulseChange) {
  bool changed = false;
  for (int v = 0; v < w.A.rows; ++v) {
    impulseChange[v].setZero();
    if (!isContactRow(w.constrained[v])) continue;
    const Vec3d n = w.contactNormal[v];
    const Vec3d r = rowResidual(w.A, w.dv, w.rhs, v);  // a sliding row: its friction is in w.rhs, r is normal
    const double support = n.dot(r);
    Vec3d friction = Vec3d::Zero();
    if (support < 0.0) {  // released, and watched (addDrivenRows)
      w.constrained[v] = kFreeRow;
      w.watchedCollider[v] = w.contactCollider[v];
      w.contactCollider[v] = -1;
      changed = true;
    } else if (w.constrained[v] == kStickRow) {
      const Vec3d t = r - support * n;
      const double limit = std::max(w.contactMu[v].staticCoef, w.contactMu[v].kinetic) * support;
      if (t.norm() > limit) {
        w.constrained[v] = kContactRow;
        friction = (w.contactMu[v].kinetic * support / t.norm()) * t;
        changed = true;
      }
    } else if (w.contactMu[v].kinetic > 0.0f) {
      const Vec3d start = v0[static_cast<size_t>(v)].cast<double>(), v1 = start + w.dv[v];
      const Vec3d along = w.frictionImpulse[v].normalized();
      const double slip = (v1 - w.contactVelocity[v].cast<double>()).dot(along);  // along its friction: reversed
      if (w.frictionImpulse[v].squaredNorm() > 0.0 && slip > kSlipReversed) {
        w.constrained[v] = kStickRow;
        w.dv[v] = stickingVelocity(n, v1.dot(n), w.contactVelocity[v]) - start;
        changed = true;
      } else {
        friction = w.contactMu[v].kinetic * support * along;
      }
    }
    impulseChange[v] = friction - w.frictionImpulse[v];
  }
  return changed;
}

}  // namespace

void contactRows(const Model& model, const GarmentPiece& g, const std::vector<ColliderPose>& poses, const Particles& p,
                 float h, std::span<const float> fabricFriction, ImplicitScratch& w) {
  const size_t first = static_cast<size_t>(g.firstParticle);
  const size_t numColliders = std::min(model.colliders.size(), poses.size());
  const float margin = contactMargin(model, static_cast<int32_t>(g.piece + 1));
  const float band = kContactBand * margin;
  w.contactNormal.resize(static_cast<size_t>(g.count));
  w.contactVelocity.resize(static_cast<size_t>(g.count));
  w.contactMu.resize(static_cast<size_t>(g.count));
  w.frictionImpulse.assign(static_cast<size_t>(g.count), Vec3d::Zero());
  w.contactCollider.assign(static_cast<size_t>(g.count), -1);
  w.watchedCollider.assign(static_cast<size_t>(g.count), -1);
  w.throughSpeed.resize(static_cast<size_t>(g.count));
  w.contactSpeed.resize(static_cast<size_t>(g.count));
  parallelFor(numColliders ? g.count : 0, [&](int64_t v) {
    if (w.constrained[v] != kFreeRow) return;
    const Vec3& x0 = p.x[first + static_cast<size_t>(v)];
    float nearest = band;
    Vec3 nrm = Vec3::Zero(), vCol = Vec3::Zero();
    for (size_t c = 0; c < numColliders; ++c) {
      Vec3 y = x0, n, vc;
      if (!pushOutOf(model.colliders[c], poses[c], band, y, &n, &vc)) continue;
      const float d = band - (y - x0).dot(n);  // x0's distance to the surface
      if (d >= nearest && w.contactCollider[v] >= 0) continue;
      nearest = d;
      nrm = n;
      vCol = vc;
      w.contactCollider[v] = static_cast<int>(c);
    }
    if (w.contactCollider[v] < 0) return;
    // down to the margin, never faster out than the surface moves: a vertex found inside is put back by
    // position after the solve (pushOutOf), so the row's impulse is the support alone and friction with it
    const double vn = std::min((margin - nearest) / h, std::max(vCol.dot(nrm), 0.0f));
    const Vec3d n = nrm.cast<double>();
    const Vec3d v0 = p.v[first + static_cast<size_t>(v)].cast<double>();
    w.contactNormal[v] = n;
    w.contactVelocity[v] = vCol;
    w.contactSpeed[v] = vn;
    w.throughSpeed[v] = vCol.dot(nrm) - nearest / h;  // a normal speed below this ends the step inside
    const Collider& collider = model.colliders[static_cast<size_t>(w.contactCollider[v])];
    const float fabric = fabricFriction[static_cast<size_t>(v)];
    w.contactMu[v] = {mixFriction(fabric, collider.staticFriction), mixFriction(fabric, collider.friction)};
    const Vec3d estimate = v0 + w.A.block[g.rowStart[v]].ldlt().solve(w.rhs[v]);
    if (estimate.dot(n) >= vn) {  // its own forces keep it off the margin: free, watched (addDrivenRows)
      w.watchedCollider[v] = w.contactCollider[v];
      w.contactCollider[v] = -1;
      return;
    }
    holdOnCollider(static_cast<int>(v), v0, w);
  });
}

// the filtered PCG of Eq. 5 with the contact rows, solved again from the last solution while
// updateContactRows changes a row's kind or addDrivenRows adds one, at most kContactRounds more times.
// The rounds that only decide the rows' kinds stop at kRoundLoosening times the tolerance (at most
// kRoundTolerance); the last solve, on the settled kinds, at the tolerance itself (docs/garment.md
// departure 9); a row the last solve adds sends it round again.
constexpr int kContactRounds = 8;
constexpr double kRoundLoosening = 30.0;
constexpr double kRoundTolerance = 3e-3;

void solveWithContact(const GarmentParams& params, std::span<const Vec3> v0, ImplicitScratch& w, ImplicitStats& stats) {
  CgOptions opt;
  opt.maxIterations = params.cgMaxIterations;
  opt.preconditioner = params.cgPreconditioner;
  w.frictionChange.resize(static_cast<size_t>(w.A.rows));
  const double tolerance = params.cgTolerance;
  const double roundTolerance = std::max(tolerance, std::min(tolerance * kRoundLoosening, kRoundTolerance));
  const bool watching = std::any_of(w.watchedCollider.begin(), w.watchedCollider.end(), [](int c) { return c >= 0; });
  // no row to change and no vertex to watch: one solve
  bool settled = !watching && std::none_of(w.constrained.begin(), w.constrained.end(), isContactRow);
  for (int round = 0;; ++round) {
    const bool last = settled || round == kContactRounds;
    opt.tolerance = last ? tolerance : roundTolerance;
    opt.sameMatrix = round > 0;  // the rounds change the filter and the right-hand side only
    const CgResult cg = filteredPcg(w.A, w.rhs, w.constrained, w.dv, opt, w.cg, w.contactNormal);
    stats.cgIterations += cg.iterations;
    ++stats.solves;
    stats.cgResidual = cg.residual;
    stats.converged = cg.converged;
    stats.breakdown = stats.breakdown || cg.breakdown;
    stats.factorFailed = stats.factorFailed || cg.factorFailed;
    const bool added = round < kContactRounds && addDrivenRows(v0, w);  // the tight solve too may drive one in
    if (last && !added) break;
    settled = !updateContactRows(v0, w, w.frictionChange) && !added;
    for (int v = 0; v < w.A.rows; ++v) {  // the new friction: a row that began to slide, or one whose support changed
      w.rhs[v] += w.frictionChange[v];
      w.frictionImpulse[v] += w.frictionChange[v];
    }
  }
  for (int v = 0; v < w.A.rows; ++v) {
    stats.contactRows += isContactRow(w.constrained[v]) ? 1 : 0;
    stats.stickingRows += w.constrained[v] == kStickRow ? 1 : 0;
  }
}

}  // namespace soak
