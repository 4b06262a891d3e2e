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

namespace {

// atan2 by a minimax polynomial of atan on [0, 1] (max error about 1e-5 rad) and the octant
// symmetries, branch free, so the bend loop vectorises; libm's atan2f was a third of the cloth stage
[[gnu::always_inline]] inline float fastAtan2(float y, float x) {
  const float ax = std::fabs(x), ay = std::fabs(y);
  const float hi = std::max(ax, ay), lo = std::min(ax, ay);
  const float a = lo / std::max(hi, 1e-30f);  // 0 / 1e-30 = 0 at the origin
  const float s = a * a;
  float r = a * (0.99997726f + s * (-0.33262347f + s * (0.19354346f + s * (-0.11643287f + s * (0.05265332f + s * -0.01172120f)))));
  r = ay > ax ? 0.5f * kPi - r : r;
  r = x < 0.0f ? kPi - r : r;
  return y < 0.0f ? -r : r;
}

// plain 3-vectors for the vectorised loops (Eigen's copies of Vector3f stop GCC's vectoriser)
struct V3 {
  float x, y, z;
};
[[gnu::always_inline]] inline V3 sub(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
[[gnu::always_inline]] inline V3 cross(V3 a, V3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
[[gnu::always_inline]] inline float dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
[[gnu::always_inline]] inline V3 scale(float s, V3 a) { return {s * a.x, s * a.y, s * a.z}; }

// the bend constraint, branch free (selects only) for the vectorised colour loop
[[gnu::always_inline]] inline float bendValue(V3 a, V3 b, V3 c, V3 d, float restAngle, V3& g0, V3& g1, V3& g2, V3& g3) {
  const V3 e = sub(b, a);
  const float len2 = dot(e, e);
  const V3 n1 = cross(e, sub(c, a));  // 2 * area1 * unit normal of (a, b, c)
  const V3 n2 = cross(sub(d, a), e);  // 2 * area2 * unit normal of (b, a, d)
  const float n1sq = dot(n1, n1), n2sq = dot(n2, n2);
  const bool valid = (len2 >= 1e-20f) & (n1sq >= 1e-30f) & (n2sq >= 1e-30f);  // & not &&: no branch
  const float z = valid ? 1.0f : 0.0f;
  const float len = std::sqrt(std::max(len2, 1e-20f));
  // both arguments carry the same factor |n1||n2|, which atan2 ignores
  const float theta = fastAtan2(dot(cross(n1, n2), e) / len, dot(n1, n2));
  const V3 gc = scale(-z * len / std::max(n1sq, 1e-30f), n1);
  const V3 gd = scale(-z * len / std::max(n2sq, 1e-30f), n2);
  const float sc = dot(sub(c, a), e) / std::max(len2, 1e-20f);  // where c projects on the edge, 0 at a and 1 at b
  const float sd = dot(sub(d, a), e) / std::max(len2, 1e-20f);
  const float ac = -(1.0f - sc), ad = -(1.0f - sd);
  // component by component: a struct copy stops the vectoriser
  g0.x = ac * gc.x + ad * gd.x;
  g0.y = ac * gc.y + ad * gd.y;
  g0.z = ac * gc.z + ad * gd.z;
  g1.x = -sc * gc.x - sd * gd.x;
  g1.y = -sc * gc.y - sd * gd.y;
  g1.z = -sc * gc.z - sd * gd.z;
  g2.x = gc.x;
  g2.y = gc.y;
  g2.z = gc.z;
  g3.x = gd.x;
  g3.y = gd.y;
  g3.z = gd.z;
  // the short way round, so a fold through +-pi does not unwind a whole turn
  float C = theta - restAngle;
  C -= (C > kPi ? 2.0f * kPi : 0.0f);
  C += (C < -kPi ? 2.0f * kPi : 0.0f);
  return z * C;
}

}  // namespace

// C = theta(a, b, c, d) - phi0 (Eq. 9), theta the signed dihedral angle between triangles (a, b, c) and
// (b, a, d): 0 when flat, positive when the wings fold towards -n (n the normal of (a, b, c)).
// departs from Eq. 9's acos: atan2(sin, cos) is signed and well conditioned near 0 and pi, where acos' slope blows up.
// gradients are the closed forms of Bridson et al. 2003: a wing moves the angle by 1/height along the
// normal, and the edge vertices take the share that keeps the sum zero and rotations free.
float bendConstraint(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, float restAngle, Vec3 grad[4]) {
  V3 g[4];
  const float C = bendValue({a.x(), a.y(), a.z()}, {b.x(), b.y(), b.z()}, {c.x(), c.y(), c.z()}, {d.x(), d.y(), d.z()},
                            restAngle, g[0], g[1], g[2], g[3]);
  for (int k = 0; k < 4; ++k) grad[k] = Vec3(g[k].x, g[k].y, g[k].z);
  return C;
}


namespace {

// XPBD updates of constraints [begin, end) of one colour (Macklin et al. 2016, Eq. 17-18):
// dlambda = (-C - alpha~ lambda) / (sum_k w_k |grad_k C|^2 + alpha~), x_k += w_k grad_k dlambda.
// A colour's constraints share no particle: their moves are computed in a vectorised loop (gathers)
// into out (component c of constraint k at out[c * stride + k]), then added by the caller (scatters).
void stretchRange(int begin, int end, const int* __restrict I, const float* __restrict rest,
                  const float* __restrict compliance, float invDt2, const float* __restrict X, const float* __restrict w,
                  float* __restrict lambda, float* __restrict out, size_t stride) {
#pragma omp simd
  for (int k = begin; k < end; ++k) {
    const int a = I[2 * k], b = I[2 * k + 1];
    const float dx = X[3 * a] - X[3 * b], dy = X[3 * a + 1] - X[3 * b + 1], dz = X[3 * a + 2] - X[3 * b + 2];
    const float len = std::sqrt(dx * dx + dy * dy + dz * dz);
    const float z = len >= 1e-12f ? 1.0f : 0.0f;  // coincident particles have no direction to push along
    const float inv = z / std::max(len, 1e-12f);
    const float gx = inv * dx, gy = inv * dy, gz = inv * dz;
    const float C = len - rest[k];  // Eq. 8
    const float alpha = compliance[k] * invDt2;
    const float denom = alpha + (w[a] + w[b]) * (gx * gx + gy * gy + gz * gz);
    const float dl = denom > 0.0f ? (-C - alpha * lambda[k]) / std::max(denom, 1e-30f) : 0.0f;
    lambda[k] += dl;
    const float fa = w[a] * dl, fb = -w[b] * dl;
    out[k] = fa * gx;
    out[stride + k] = fa * gy;
    out[2 * stride + k] = fa * gz;
    out[3 * stride + k] = fb * gx;
    out[4 * stride + k] = fb * gy;
    out[5 * stride + k] = fb * gz;
  }
}

void bendRange(int begin, int end, const int* __restrict I, const float* __restrict rest,
               const float* __restrict compliance, float invDt2, const float* __restrict X, const float* __restrict w,
               float* __restrict lambda, float* __restrict out, size_t strideSize) {
  const int stride = static_cast<int>(strideSize);  // int indices throughout: the gathers take 32-bit offsets
#pragma omp simd
  for (int k = begin; k < end; ++k) {
    const int i0 = I[4 * k], i1 = I[4 * k + 1], i2 = I[4 * k + 2], i3 = I[4 * k + 3];
    const float ax = X[3 * i0], ay = X[3 * i0 + 1], az = X[3 * i0 + 2];
    const float bx = X[3 * i1], by = X[3 * i1 + 1], bz = X[3 * i1 + 2];
    const float cx = X[3 * i2], cy = X[3 * i2 + 1], cz = X[3 * i2 + 2];
    const float dx = X[3 * i3], dy = X[3 * i3 + 1], dz = X[3 * i3 + 2];
    V3 g0, g1, g2, g3;
    const float C = bendValue({ax, ay, az}, {bx, by, bz}, {cx, cy, cz}, {dx, dy, dz}, rest[k], g0, g1, g2, g3);  // Eq. 9
    const float alpha = compliance[k] * invDt2;
    const float denom = alpha + w[i0] * dot(g0, g0) + w[i1] * dot(g1, g1) + w[i2] * dot(g2, g2) + w[i3] * dot(g3, g3);
    const float dl = denom > 0.0f ? (-C - alpha * lambda[k]) / std::max(denom, 1e-30f) : 0.0f;
    lambda[k] += dl;
    const float f0 = w[i0] * dl, f1 = w[i1] * dl, f2 = w[i2] * dl, f3 = w[i3] * dl;
    out[k] = f0 * g0.x;
    out[stride + k] = f0 * g0.y;
    out[2 * stride + k] = f0 * g0.z;
    out[3 * stride + k] = f1 * g1.x;
    out[4 * stride + k] = f1 * g1.y;
    out[5 * stride + k] = f1 * g1.z;
    out[6 * stride + k] = f2 * g2.x;
    out[7 * stride + k] = f2 * g2.y;
    out[8 * stride + k] = f2 * g2.z;
    out[9 * stride + k] = f3 * g3.x;
    out[10 * stride + k] = f3 * g3.y;
    out[11 * stride + k] = f3 * g3.z;
  }
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
  scratch.correction.resize(12 * std::max(st.ids.size(), bd.ids.size()));
  if (model.numCloth == 0 || dt <= 0.0f) return;
  const float invDt2 = 1.0f / (dt * dt);
  Vec3* x = p.xPred.data();
  const float* w = p.invMass.data();
  float* stretchLambda = scratch.stretchLambda.data();
  float* bendLambda = scratch.bendLambda.data();

  // one parallel region for every colour of every iteration: a barrier between colours (the implicit
  // one of each omp for) instead of a fork and join; colours below the grain run on one thread
  const size_t stride = std::max(st.ids.size(), bd.ids.size());
  float* corr = scratch.correction.data();
  const auto stretchColour = [&](int begin, int end) {
    stretchRange(begin, end, st.ids[0].data(), st.restLength.data(), st.compliance.data(), invDt2, x[0].data(), w,
                 stretchLambda, corr, stride);
    for (int k = begin; k < end; ++k)
      for (int v = 0; v < 2; ++v)
        x[st.ids[k][v]] += Vec3(corr[(3 * v) * stride + k], corr[(3 * v + 1) * stride + k], corr[(3 * v + 2) * stride + k]);
  };
  const auto bendColour = [&](int begin, int end) {
    bendRange(begin, end, bd.ids[0].data(), bd.restAngle.data(), bd.compliance.data(), invDt2, x[0].data(), w,
              bendLambda, corr, stride);
    for (int k = begin; k < end; ++k)
      for (int v = 0; v < 4; ++v)
        x[bd.ids[k][v]] += Vec3(corr[(3 * v) * stride + k], corr[(3 * v + 1) * stride + k], corr[(3 * v + 2) * stride + k]);
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
