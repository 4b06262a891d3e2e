// modified PCG of Baraff & Witkin 1998 (Fig. "modified-pcg") on 3x3 block matrices
#include "garment/block_cg.hpp"

#include "core/parallel.hpp"

#include <algorithm>
#include <cmath>

namespace soak {

namespace {

// sum of per-row terms in row order: the same for any thread count
double orderedSum(const std::vector<double>& terms) {
  double s = 0.0;
  for (double t : terms) s += t;
  return s;
}

}  // namespace

void BlockMatrix::multiply(const std::vector<Vec3d>& x, std::vector<Vec3d>& y) const {
  y.resize(static_cast<size_t>(rows));
  parallelFor(rows, [&](int64_t i) { y[i] = row(x, i); });
}

double blockDot(const std::vector<Vec3d>& a, const std::vector<Vec3d>& b, std::vector<double>& partial) {
  partial.resize(a.size());
  parallelFor(static_cast<int64_t>(a.size()), [&](int64_t i) { partial[i] = a[i].dot(b[i]); });
  return orderedSum(partial);
}

namespace {

// the constraint filter of a solve: each row's kind and the contact rows' normals (filterRow)
struct Filter {
  const std::vector<uint8_t>& kind;
  std::span<const Vec3d> normal;
  Vec3d operator()(size_t i, const Vec3d& a) const { return filterRow(kind[i], normal, i, a); }
};

// the block-Jacobi preconditioner: the inverse of each diagonal block (the first of its row), of a
// contact row on its tangent plane (filteredDiagonal)
void invertDiagonal(const BlockMatrix& A, const Filter& filter, CgScratch& w) {
  w.precond.resize(static_cast<size_t>(A.rows));
  parallelFor(A.rows, [&](int64_t i) {
    bool ok = false;
    Eigen::Matrix3d inv;
    const Eigen::Matrix3d block = filteredDiagonal(filter.kind[i], filter.normal, i, A.block[A.rowStart[i]]);
    double det = 0.0;
    block.computeInverseAndDetWithCheck(inv, det, ok, 1e-300);
    w.precond[i] = ok ? inv : Eigen::Matrix3d::Identity();
  });
}

// s = filter(P^-1 r); returns r^T s, summed in row order
double precondition(const std::vector<Vec3d>& r, const Filter& filter, CgPreconditioner kind, CgScratch& w,
                    std::vector<Vec3d>& s) {
  const int64_t n = static_cast<int64_t>(r.size());
  s.resize(r.size());
  if (kind == CgPreconditioner::Cholesky) w.cholesky.solve(r, s);
  if (kind == CgPreconditioner::Multigrid) w.multigrid.apply(r, s);
  parallelFor(n, [&](int64_t i) {
    s[i] = filter(i, kind == CgPreconditioner::BlockJacobi ? Vec3d(w.precond[i] * r[i]) : s[i]);
    w.partial[i] = r[i].dot(s[i]);
  });
  return orderedSum(w.partial);
}

// the solve's start: the preconditioner (as asked for, or block Jacobi if its factor fails),
// delta0 = filter(b)^T P^-1 filter(b), the scale the residual is measured against,
// r = filter(b - A x), c = filter(P^-1 r) and deltaNew = r^T c; returns the preconditioner used
CgPreconditioner startPcg(const BlockMatrix& A, const std::vector<Vec3d>& b, const Filter& filter,
                          const std::vector<Vec3d>& x, const CgOptions& options, CgScratch& w, CgResult& result,
                          double& delta0, double& deltaNew) {
  const int64_t n = A.rows;
  w.r.resize(static_cast<size_t>(n));
  w.q.resize(static_cast<size_t>(n));
  w.partial.resize(static_cast<size_t>(n));
  CgPreconditioner kind = options.preconditioner;
  const bool factored = kind == CgPreconditioner::Cholesky    ? w.cholesky.factor(A, filter.kind, filter.normal)
                        : kind == CgPreconditioner::Multigrid ? w.multigrid.setup(A, filter.kind, filter.normal)
                                                              : true;
  if (!factored) {
    result.factorFailed = true;
    kind = CgPreconditioner::BlockJacobi;
  }
  if (kind == CgPreconditioner::BlockJacobi) invertDiagonal(A, filter, w);
  parallelFor(n, [&](int64_t i) { w.r[i] = filter(i, b[i]); });
  delta0 = precondition(w.r, filter, kind, w, w.s);
  parallelFor(n, [&](int64_t i) { w.r[i] = filter(i, b[i] - A.row(x, i)); });  // r = filter(b - A x)
  deltaNew = precondition(w.r, filter, kind, w, w.c);
  return kind;
}

}  // namespace

CgResult filteredPcg(const BlockMatrix& A, const std::vector<Vec3d>& b, const std::vector<uint8_t>& constrained,
                     std::vector<Vec3d>& x, const CgOptions& options, CgScratch& w,
                     std::span<const Vec3d> contactNormal) {
  const int64_t n = A.rows;
  CgResult result;
  double delta0 = 0.0, deltaNew = 0.0;
  const Filter filter{constrained, contactNormal};
  const CgPreconditioner kind = startPcg(A, b, filter, x, options, w, result, delta0, deltaNew);
  if (!(delta0 > 0.0)) delta0 = deltaNew;
  if (!(delta0 > 0.0)) {
    // nothing to solve (b and r are zero), or r^T P^-1 r < 0: the matrix is not positive definite
    result.converged = delta0 == 0.0;
    result.breakdown = !result.converged;
    return result;
  }
  const double tol2 = options.tolerance * options.tolerance;
  while (deltaNew > tol2 * delta0 && result.iterations < options.maxIterations) {
    // q = filter(A c)
    parallelFor(n, [&](int64_t i) {
      if (rowHeld(constrained[i])) {
        w.q[i].setZero();
        w.partial[i] = 0.0;
        return;
      }
      w.q[i] = filter(i, A.row(w.c, i));
      w.partial[i] = w.c[i].dot(w.q[i]);
    });
    const double cq = orderedSum(w.partial);
    if (!(cq > 0.0)) {
      result.breakdown = true;
      break;
    }
    const double alpha = deltaNew / cq;
    // x += alpha c, r -= alpha q (filtered rows of c, q, r are zero), s = filter(P^-1 r)
    parallelFor(n, [&](int64_t i) {
      x[i] += alpha * w.c[i];
      w.r[i] -= alpha * w.q[i];
    });
    const double deltaOld = deltaNew;
    deltaNew = precondition(w.r, filter, kind, w, w.s);
    const double beta = deltaNew / deltaOld;
    parallelFor(n, [&](int64_t i) { w.c[i] = w.s[i] + beta * w.c[i]; });
    ++result.iterations;
  }
  result.residual = std::sqrt(std::max(deltaNew, 0.0) / delta0);
  result.converged = !result.breakdown && deltaNew <= tol2 * delta0;
  return result;
}

}  // namespace soak
