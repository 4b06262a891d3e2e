// PBD cloth of Shao 2017 section 3.2: stretch (Eq. 8) and bend (Eq. 9) constraints solved with XPBD
// (Macklin et al. 2016) colour by colour, and particle-particle self-collision.
#include "pbd/cloth.hpp"

#include <algorithm>
#include <cmath>

#include "core/parallel.hpp"

#include <omp.h>

namespace soak {

// C(x1, x2) = |x1 - x2| - l0 (Eq. 8); grad1 = (x1 - x2)/|x1 - x2| = -grad2
float stretchConstraint(const Vec3& x1, const Vec3& x2, float restLength, Vec3& grad1, Vec3& grad2) {
  const Vec3 d = x1 - x2;
  const float len = d.norm();
  if (len < 1e-12f) {
    // coincident particles have no direction to push along
    grad1.setZero();
    grad2.setZero();
    return -restLength;
  }
  grad1 = d / len;
  grad2 = -grad1;
  return len - restLength;
}

// C = theta(a, b, c, d) - phi0 (Eq. 9), theta the signed dihedral angle between triangles (a, b, c) and
// (b, a, d): 0 when flat, positive when the wings fold towards -n (n the normal of (a, b, c)).
// departs from Eq. 9's acos: atan2(sin, cos) is signed and well conditioned near 0 and pi, where acos' slope blows up.
// gradients are the closed forms of Bridson et al. 2003: a wing moves the angle by 1/height along the
// normal, and the edge vertices take the share that keeps the sum zero and rotations free.
float bendConstraint(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, float restAngle, Vec3 grad[4]) {
  const Vec3 e = b - a;
  const float len2 = e.squaredNorm();
  const Vec3 n1 = e.cross(c - a);    // 2 * area1 * unit normal of (a, b, c)
  const Vec3 n2 = (d - a).cross(e);  // 2 * area2 * unit normal of (b, a, d)
  const float n1sq = n1.squaredNorm(), n2sq = n2.squaredNorm();
  if (len2 < 1e-20f || n1sq < 1e-30f || n2sq < 1e-30f) {
    for (int k = 0; k < 4; ++k) grad[k].setZero();
    return 0.0f;
  }
  const float len = std::sqrt(len2);
  // both arguments carry the same factor |n1||n2|, which atan2 ignores
  const float theta = std::atan2(n1.cross(n2).dot(e) / len, n1.dot(n2));
  const Vec3 gc = (-len / n1sq) * n1;
  const Vec3 gd = (-len / n2sq) * n2;
  const float sc = (c - a).dot(e) / len2;  // where c projects on the edge, 0 at a and 1 at b
  const float sd = (d - a).dot(e) / len2;
  grad[0] = -(1.0f - sc) * gc - (1.0f - sd) * gd;
  grad[1] = -sc * gc - sd * gd;
  grad[2] = gc;
  grad[3] = gd;
  // the short way round, so a fold through +-pi does not unwind a whole turn
  float C = theta - restAngle;
  if (C > kPi)
    C -= 2.0f * kPi;
  else if (C < -kPi)
    C += 2.0f * kPi;
  return C;
}

namespace {

// one XPBD update of constraint k with particles ids (Macklin et al. 2016, Eq. 18 and Eq. 17):
// dlambda = (-C - alpha~ lambda) / (sum_k w_k |grad_k C|^2 + alpha~), x_k += w_k grad_k dlambda
template <size_t N>
inline void xpbdUpdate(const std::array<int, N>& ids, float C, const Vec3* grad, float alphaTilde, float& lambda,
                       Vec3* x, const float* w) {
  float denom = alphaTilde;
  for (size_t k = 0; k < N; ++k) denom += w[ids[k]] * grad[k].squaredNorm();
  if (denom <= 0.0f) return;  // all pinned (and rigid): nothing can move
  const float dlambda = (-C - alphaTilde * lambda) / denom;
  lambda += dlambda;
  for (size_t k = 0; k < N; ++k) x[ids[k]] += (w[ids[k]] * dlambda) * grad[k];
}

}  // namespace

// XPBD in place of Eq. 5: compliance alpha = 1/k with alpha~ = alpha/dt^2 gives a stiffness that does not
// depend on the iteration count, unlike Eq. 5's per-iteration factor 1 - (1 - kappa)^(1/n_s); compliance 0
// reproduces kappa = 1 (each projection fully satisfies its constraint). Colours are solved in order
// (Gauss-Seidel between colours); the constraints of one colour share no particle, so they run in parallel
// and the result does not depend on the thread count.
void solveCloth(const Model& model, Particles& p, ClothScratch& scratch, float dt, int iterations) {
  const StretchConstraints& st = model.stretch;
  const BendConstraints& bd = model.bend;
  scratch.stretchLambda.assign(st.ids.size(), 0.0f);
  scratch.bendLambda.assign(bd.ids.size(), 0.0f);
  if (model.numCloth == 0 || dt <= 0.0f) return;
  const float invDt2 = 1.0f / (dt * dt);
  Vec3* x = p.xPred.data();
  const float* w = p.invMass.data();
  float* stretchLambda = scratch.stretchLambda.data();
  float* bendLambda = scratch.bendLambda.data();

  // one parallel region for every colour of every iteration: a barrier between colours (the implicit
  // one of each omp for) instead of a fork and join; colours below the grain run on one thread
  const auto stretchColour = [&](int begin, int end) {
    for (int k = begin; k < end; ++k) {
      const auto& ids = st.ids[k];
      Vec3 grad[2];
      const float C = stretchConstraint(x[ids[0]], x[ids[1]], st.restLength[k], grad[0], grad[1]);
      xpbdUpdate(ids, C, grad, st.compliance[k] * invDt2, stretchLambda[k], x, w);
    }
  };
  const auto bendColour = [&](int begin, int end) {
    for (int k = begin; k < end; ++k) {
      const auto& ids = bd.ids[k];
      Vec3 grad[4];
      const float C = bendConstraint(x[ids[0]], x[ids[1]], x[ids[2]], x[ids[3]], bd.restAngle[k], grad);
      xpbdUpdate(ids, C, grad, bd.compliance[k] * invDt2, bendLambda[k], x, w);
    }
  };
  // each colour split in contiguous chunks, one per thread; a chunk's constraints share no particle
  // with another's, so the split does not change the result
  const auto solveColour = [&](const auto& colour, int begin, int end) {
    if (end - begin < kParallelGrain) {
#pragma omp single
      colour(begin, end);
    } else {
      const int t = omp_get_thread_num(), nt = omp_get_num_threads();
      const int64_t len = end - begin;
      colour(begin + static_cast<int>(len * t / nt), begin + static_cast<int>(len * (t + 1) / nt));
#pragma omp barrier
    }
  };
#pragma omp parallel
  for (int it = 0; it < iterations; ++it) {
    for (size_t c = 0; c + 1 < st.colorStart.size(); ++c) solveColour(stretchColour, st.colorStart[c], st.colorStart[c + 1]);
    for (size_t c = 0; c + 1 < bd.colorStart.size(); ++c) solveColour(bendColour, bd.colorStart[c], bd.colorStart[c + 1]);
  }
}

// for a pair (i, j) of one piece, not 1-ring neighbours and apart by more than the thickness d at rest,
// with |x_i - x_j| < d: delta_i += w_i/(w_i + w_j) (d - |x_ij|) x_ij/|x_ij|. Gathered per particle
// (Jacobi), then applied, so the result does not depend on the thread count.
void clothSelfCollision(const Model& model, Particles& p, const NeighborLists& neighbors, ClothScratch& scratch) {
  const int n = model.numCloth;
  scratch.delta.assign(n, Vec3::Zero());
  scratch.deltaCount.assign(n, 0);
  if (n == 0) return;
  const Vec3* x = p.xPred.data();
  const float* w = p.invMass.data();
  const Vec3* rest = model.clothRestPosition.data();
  Vec3* delta = scratch.delta.data();
  int* count = scratch.deltaCount.data();

  parallelFor(n, [&](int64_t ii) {
    const int i = static_cast<int>(ii);
    const int piece = clothPiece(p.phase[i]);
    if (piece < 0 || piece >= static_cast<int>(model.pieces.size())) return;
    const ClothMaterial& mat = model.pieces[piece].material;
    if (!mat.selfCollision || w[i] == 0.0f) return;
    const float thickness = mat.thickness;
    const auto ringBegin = model.vertexNeighbors.begin() + model.vertexNeighborStart[i];
    const auto ringEnd = model.vertexNeighbors.begin() + model.vertexNeighborStart[i + 1];
    Vec3 sum = Vec3::Zero();
    int contacts = 0;
    for (uint32_t s = neighbors.start[i], end = neighbors.clothEnd(i, static_cast<uint32_t>(n)); s < end; ++s) {
      const int j = static_cast<int>(neighbors.index[s]);
      if (j >= n || j == i || p.phase[j] != p.phase[i]) continue;
      const float wSum = w[i] + w[j];
      if (wSum == 0.0f) continue;
      const Vec3 xij = x[i] - x[j];
      const float dist2 = xij.squaredNorm();
      if (dist2 >= thickness * thickness || dist2 < 1e-24f) continue;
      // pairs that are this close at rest belong together (fine meshes, seams): leave them to Eq. 8
      if ((rest[i] - rest[j]).squaredNorm() <= thickness * thickness) continue;
      if (std::binary_search(ringBegin, ringEnd, j)) continue;
      const float dist = std::sqrt(dist2);
      sum += (w[i] / wSum * (thickness - dist) / dist) * xij;
      ++contacts;
    }
    delta[i] = sum;
    count[i] = contacts;
  });
  Vec3* xw = p.xPred.data();
  parallelFor(n, [&](int64_t i) { xw[i] += delta[i]; });
}

}  // namespace soak
