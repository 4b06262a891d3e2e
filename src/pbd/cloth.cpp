// PBD cloth of Shao 2017 section 3.2: stretch (Eq. 8) and bend (Eq. 9) constraints solved with XPBD
// (Macklin et al. 2016) colour by colour; the self-collision is in cloth_self_collision.cpp.
#include "pbd/cloth.hpp"

#include <algorithm>
#include <array>
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

// the bend constraint (Eq. 9) of constraints [begin, end): C_k to C[k], and gradient component c
// (x, y, z of a, b, c, d) to G[c * stride + k]. Plain float locals only: under omp simd a struct or
// a local whose address is taken becomes a per-lane array in memory, and the loop does not vectorise.
// Gradients: the closed forms of Bridson et al. 2003 (a wing moves the angle by 1/height along the
// normal; the edge vertices take the share that keeps the sum zero and rotations free).
// Solve: also the XPBD update of each constraint (bendRange's arithmetic, in the same loop so the
// gradients stay in registers): G then holds the particles' moves w_v grad_v C dlambda, lambda is updated
struct BendSolve {
  const float* compliance;
  float invDt2;
  const float* w;
  float* lambda;
};

template <bool Solve>
void bendKernel(int begin, int end, const int* __restrict I, const float* __restrict rest, const float* __restrict X,
                const float* __restrict D, float* __restrict Cout, float* __restrict G, int stride, BendSolve solve = {}) {
  const float* __restrict const compliance = solve.compliance;
  const float* __restrict const w = solve.w;
  float* __restrict const lambda = solve.lambda;
  const float invDt2 = solve.invDt2;
#pragma omp simd
  for (int k = begin; k < end; ++k) {
    const int i0 = I[4 * k], i1 = I[4 * k + 1], i2 = I[4 * k + 2], i3 = I[4 * k + 3];
    // positions X + D, differences taken in the base and in the displacement apart (solveClothFrom)
    const float ax = X[3 * i0], ay = X[3 * i0 + 1], az = X[3 * i0 + 2];
    const float pax = D[3 * i0], pay = D[3 * i0 + 1], paz = D[3 * i0 + 2];
    const float ex = (X[3 * i1] - ax) + (D[3 * i1] - pax), ey = (X[3 * i1 + 1] - ay) + (D[3 * i1 + 1] - pay),
                ez = (X[3 * i1 + 2] - az) + (D[3 * i1 + 2] - paz);  // edge b - a
    const float cx = (X[3 * i2] - ax) + (D[3 * i2] - pax), cy = (X[3 * i2 + 1] - ay) + (D[3 * i2 + 1] - pay),
                cz = (X[3 * i2 + 2] - az) + (D[3 * i2 + 2] - paz);  // c - a
    const float dx = (X[3 * i3] - ax) + (D[3 * i3] - pax), dy = (X[3 * i3 + 1] - ay) + (D[3 * i3 + 1] - pay),
                dz = (X[3 * i3 + 2] - az) + (D[3 * i3 + 2] - paz);  // d - a
    const float len2 = ex * ex + ey * ey + ez * ez;
    // n1 = e x (c - a), n2 = (d - a) x e: 2 * area * unit normal of (a, b, c) and (b, a, d)
    const float n1x = ey * cz - ez * cy, n1y = ez * cx - ex * cz, n1z = ex * cy - ey * cx;
    const float n2x = dy * ez - dz * ey, n2y = dz * ex - dx * ez, n2z = dx * ey - dy * ex;
    const float n1sq = n1x * n1x + n1y * n1y + n1z * n1z, n2sq = n2x * n2x + n2y * n2y + n2z * n2z;
    const bool valid = (len2 >= 1e-20f) & (n1sq >= 1e-30f) & (n2sq >= 1e-30f);  // & not &&: no branch
    const float z = valid ? 1.0f : 0.0f;
    const float len = std::sqrt(std::max(len2, 1e-20f));
    // theta = atan2((n1 x n2) . e / |e|, n1 . n2): both carry the factor |n1||n2|, which atan2 ignores
    const float mx = n1y * n2z - n1z * n2y, my = n1z * n2x - n1x * n2z, mz = n1x * n2y - n1y * n2x;
    const float theta = fastAtan2((mx * ex + my * ey + mz * ez) / len, n1x * n2x + n1y * n2y + n1z * n2z);
    const float s1 = -z * len / std::max(n1sq, 1e-30f), s2 = -z * len / std::max(n2sq, 1e-30f);
    const float gcx = s1 * n1x, gcy = s1 * n1y, gcz = s1 * n1z;
    const float gdx = s2 * n2x, gdy = s2 * n2y, gdz = s2 * n2z;
    const float sc = (cx * ex + cy * ey + cz * ez) / std::max(len2, 1e-20f);  // where c projects on the edge, 0 at a, 1 at b
    const float sd = (dx * ex + dy * ey + dz * ez) / std::max(len2, 1e-20f);
    const float ac = -(1.0f - sc), ad = -(1.0f - sd);
    const float g[12] = {ac * gcx + ad * gdx, ac * gcy + ad * gdy, ac * gcz + ad * gdz,
                         -sc * gcx - sd * gdx, -sc * gcy - sd * gdy, -sc * gcz - sd * gdz,
                         gcx, gcy, gcz, gdx, gdy, gdz};
    // the short way round, so a fold through +-pi does not unwind a whole turn
    float C = theta - rest[k];
    C -= (C > kPi ? 2.0f * kPi : 0.0f);
    C += (C < -kPi ? 2.0f * kPi : 0.0f);
    C = z * C;
    if constexpr (!Solve) {
      for (int c = 0; c < 12; ++c) G[c * stride + k] = g[c];
      Cout[k] = C;
    } else {
      // XPBD (Macklin et al. 2016, Eq. 17-18), as stretchRange
      const float w0 = w[i0], w1 = w[i1], w2 = w[i2], w3 = w[i3];
      float q0 = 0.0f, q1 = 0.0f, q2 = 0.0f, q3 = 0.0f;  // |grad_v C|^2
      for (int c = 0; c < 3; ++c) {
        q0 += g[c] * g[c];
        q1 += g[3 + c] * g[3 + c];
        q2 += g[6 + c] * g[6 + c];
        q3 += g[9 + c] * g[9 + c];
      }
      const float alpha = compliance[k] * invDt2;
      const float denom = alpha + w0 * q0 + w1 * q1 + w2 * q2 + w3 * q3;
      const float dl = denom > 0.0f ? (-C - alpha * lambda[k]) / std::max(denom, 1e-30f) : 0.0f;
      lambda[k] += dl;
      const float f[4] = {w0 * dl, w1 * dl, w2 * dl, w3 * dl};
      for (int c = 0; c < 12; ++c) G[c * stride + k] = g[c] * f[c / 3];
    }
  }
}

}  // namespace

// C = theta(a, b, c, d) - phi0 (Eq. 9), theta the signed dihedral angle between triangles (a, b, c) and
// (b, a, d): 0 when flat, positive when the wings fold towards -n (n the normal of (a, b, c)).
// departs from Eq. 9's acos: atan2(sin, cos) is signed and well conditioned near 0 and pi, where acos' slope blows up.
// One constraint through bendKernel, the solver's own code (for tests and callers outside the solver).
float bendConstraint(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, float restAngle, Vec3 grad[4]) {
  const float X[12] = {a.x(), a.y(), a.z(), b.x(), b.y(), b.z(), c.x(), c.y(), c.z(), d.x(), d.y(), d.z()};
  const float D[12] = {};
  const int I[4] = {0, 1, 2, 3};
  float C, G[12];
  bendKernel<false>(0, 1, I, &restAngle, X, D, &C, G, 1);
  for (int v = 0; v < 4; ++v) grad[v] = Vec3(G[3 * v], G[3 * v + 1], G[3 * v + 2]);
  return C;
}

namespace {

// XPBD updates of constraints [begin, end) of one colour (Macklin et al. 2016, Eq. 17-18):
// dlambda = (-C - alpha~ lambda) / (sum_k w_k |grad_k C|^2 + alpha~), x_k += w_k grad_k dlambda.
// A colour's constraints share no particle: their moves are computed in a vectorised loop (gathers)
// into out (component c of constraint k at out[c * stride + k]), then added by the caller (scatters).
void stretchRange(int begin, int end, const int* __restrict I, const float* __restrict rest,
                  const float* __restrict compliance, float invDt2, const float* __restrict X, const float* __restrict D,
                  const float* __restrict w, float* __restrict lambda, float* __restrict out, size_t stride) {
#pragma omp simd
  for (int k = begin; k < end; ++k) {
    const int a = I[2 * k], b = I[2 * k + 1];
    // x_a - x_b of x = X + D: the base's difference plus the displacement's (solveClothFrom)
    const float dx = (X[3 * a] - X[3 * b]) + (D[3 * a] - D[3 * b]);
    const float dy = (X[3 * a + 1] - X[3 * b + 1]) + (D[3 * a + 1] - D[3 * b + 1]);
    const float dz = (X[3 * a + 2] - X[3 * b + 2]) + (D[3 * a + 2] - D[3 * b + 2]);
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

// adds the moves of constraints [begin, end) of one colour to their V vertices (component c of
// constraint k at corr[c * stride + k], as stretchRange and bendRange write them): scatters
template <size_t V>
void addMoves(int begin, int end, const std::array<int, V>* ids, const float* corr, size_t stride, Vec3* x) {
  for (int k = begin; k < end; ++k)
    for (size_t v = 0; v < V; ++v)
      x[ids[k][v]] += Vec3(corr[(3 * v) * stride + k], corr[(3 * v + 1) * stride + k], corr[(3 * v + 2) * stride + k]);
}

void bendRange(int begin, int end, const int* __restrict I, const float* __restrict rest,
               const float* __restrict compliance, float invDt2, const float* __restrict X, const float* __restrict D,
               const float* __restrict w, float* __restrict lambda, float* __restrict out, size_t strideSize) {
  bendKernel<true>(begin, end, I, rest, X, D, nullptr, out, static_cast<int>(strideSize), {compliance, invDt2, w, lambda});
}

}  // namespace

// XPBD in place of Eq. 5: compliance alpha = 1/k with alpha~ = alpha/dt^2 gives a stiffness that does not
// depend on the iteration count, unlike Eq. 5's per-iteration factor 1 - (1 - kappa)^(1/n_s); compliance 0
// reproduces kappa = 1 (each projection fully satisfies its constraint). Colours are solved in order
// (Gauss-Seidel between colours); the constraints of one colour share no particle, so they run in parallel
// and the result does not depend on the thread count.
void solveClothFrom(const Model& model, const Vec3* base, Vec3* displacement, const float* invMass,
                    ClothScratch& scratch, float dt, int iterations) {
  const StretchConstraints& st = model.stretch;
  const BendConstraints& bd = model.bend;
  scratch.stretchLambda.assign(st.ids.size(), 0.0f);
  scratch.bendLambda.assign(bd.ids.size(), 0.0f);
  scratch.correction.resize(6 * st.ids.size());
  scratch.correctionBend.resize(12 * bd.ids.size());
  if (model.numCloth == 0 || dt <= 0.0f) return;
  const float invDt2 = 1.0f / (dt * dt);
  const float* X = base[0].data();
  const float* D = displacement[0].data();
  Vec3* x = displacement;  // the constraints' moves go to the displacement
  const float* w = invMass;
  float* stretchLambda = scratch.stretchLambda.data();
  float* bendLambda = scratch.bendLambda.data();

  // separate buffers for the two kinds: a thread may project stretch constraints while another
  // projects bend constraints of the same indices
  float* corrStretch = scratch.correction.data();
  float* corrBend = scratch.correctionBend.data();
  const size_t strideStretch = st.ids.size(), strideBend = bd.ids.size();
  const auto stretchBlock = [&](int begin, int end) {
    stretchRange(begin, end, st.ids[0].data(), st.restLength.data(), st.compliance.data(), invDt2, X, D, w,
                 stretchLambda, corrStretch, strideStretch);
    addMoves(begin, end, st.ids.data(), corrStretch, strideStretch, x);
  };
  const auto bendBlock = [&](int begin, int end) {
    bendRange(begin, end, bd.ids[0].data(), bd.restAngle.data(), bd.compliance.data(), invDt2, X, D, w, bendLambda,
              corrBend, strideBend);
    addMoves(begin, end, bd.ids.data(), corrBend, strideBend, x);
  };
  // one group: its stretch constraints colour by colour, then its bend constraints
  const ConstraintSchedule& ss = st.schedule;
  const ConstraintSchedule& bs = bd.schedule;
  const auto solveGroup = [&](int g) {
    if (static_cast<size_t>(g) + 1 < ss.groupBlock.size())
      for (int b = ss.groupBlock[g]; b < ss.groupBlock[g + 1]; ++b) stretchBlock(ss.blockStart[b], ss.blockStart[b + 1]);
    if (static_cast<size_t>(g) + 1 < bs.groupBlock.size())
      for (int b = bs.groupBlock[g]; b < bs.groupBlock[g + 1]; ++b) bendBlock(bs.blockStart[b], bs.blockStart[b + 1]);
  };
  // Gauss-Seidel in a fixed order of phases: every slab (in parallel, a slab's groups whole on one
  // thread), the interfaces between slabs k and k + 1 for even k, then for odd k, then the rest on
  // one thread. Four barriers per iteration instead of one per colour, and the groups of a phase
  // share no particle, so the result does not depend on the thread count (ConstraintSchedule)
  const int slabs = std::max(ss.numSlabs, 1);
  const int interfaces[2] = {slabs / 2, (slabs - 1) / 2};  // k = 0, 2, 4 ... < slabs - 1, then 1, 3 ...
#pragma omp parallel
  {
    const int t = omp_get_thread_num(), nt = omp_get_num_threads();
    for (int it = 0; it < iterations; ++it) {
      for (int g = slabs * t / nt; g < slabs * (t + 1) / nt; ++g) solveGroup(g);
#pragma omp barrier
      for (int parity = 0; parity < 2; ++parity) {
        for (int m = interfaces[parity] * t / nt; m < interfaces[parity] * (t + 1) / nt; ++m) solveGroup(slabs + 2 * m + parity);
#pragma omp barrier
      }
#pragma omp single
      solveGroup(2 * slabs - 1);
    }
  }
}

// the displacement x* - x taken out of x*, solved (the coarse levels first), and put back: the
// particles the constraints move (free PBD cloth) get x + displacement; the rest keep their x* as it is
void solveCloth(const Model& model, Particles& p, ClothScratch& scratch, float dt, int iterations) {
  const int n = model.numCloth;
  scratch.displacement.resize(static_cast<size_t>(n));
  Vec3* d = scratch.displacement.data();
  parallelFor(n, [&](int64_t i) { d[i] = p.xPred[i] - p.x[i]; });
  solveHierarchyFrom(model, p.x.data(), d, p.invMass.data(), scratch);
  solveClothFrom(model, p.x.data(), d, p.invMass.data(), scratch, dt, iterations);
  parallelFor(n, [&](int64_t i) {
    if (pbdClothMoves(model, i)) p.xPred[i] = p.x[i] + d[i];
  });
}

}  // namespace soak
