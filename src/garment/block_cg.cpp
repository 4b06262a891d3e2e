// modified PCG of Baraff & Witkin 1998 (Fig. "modified-pcg") on 3x3 block matrices
#include "garment/block_cg.hpp"

#include "core/parallel.hpp"

#include <algorithm>
#include <cmath>

namespace soak {

namespace {

// rows per chunk of a dot product: each chunk's partial sum runs in row order and the chunks' sums
// are added in chunk order, so a sum does not depend on the thread count
constexpr int64_t kSumChunk = 256;

int64_t sumChunks(int64_t n) { return (n + kSumChunk - 1) / kSumChunk; }

// the sum of term(i) over the rows i of chunk c, in row order (term may also write row i's results)
template <class Term>
double chunkSum(int64_t n, int64_t c, Term&& term) {
  double sum = 0.0;
  for (int64_t i = c * kSumChunk, end = std::min(n, (c + 1) * kSumChunk); i < end; ++i) sum += term(i);
  return sum;
}

// the partial sums added in chunk order
double addPartials(const std::vector<double>& partial) {
  double s = 0.0;
  for (double t : partial) s += t;
  return s;
}

// the sum of f(c) over the chunks c of n rows, the chunks in parallel where the rows are many
// (parallelFor's grain)
template <class ChunkFn>
double sumOfChunks(int64_t n, std::vector<double>& partial, ChunkFn&& f) {
  const int64_t chunks = sumChunks(n);
  partial.resize(static_cast<size_t>(chunks));
#pragma omp parallel for schedule(static) if (n >= kParallelGrain)
  for (int64_t c = 0; c < chunks; ++c) partial[c] = f(c);
  return addPartials(partial);
}

// sum over rows i of term(i)
template <class Term>
double chunkedSum(int64_t n, std::vector<double>& partial, Term&& term) {
  return sumOfChunks(n, partial, [&](int64_t c) { return chunkSum(n, c, term); });
}

}  // namespace

void BlockMatrix::multiply(const std::vector<Vec3d>& x, std::vector<Vec3d>& y) const {
  y.resize(static_cast<size_t>(rows));
  parallelFor(rows, [&](int64_t i) { y[i] = row(x, i); });
}

double blockDot(const std::vector<Vec3d>& a, const std::vector<Vec3d>& b, std::vector<double>& partial) {
  return chunkedSum(static_cast<int64_t>(a.size()), partial, [&](int64_t i) { return a[i].dot(b[i]); });
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

// s_i = filter(P_i^-1 r_i) for block Jacobi; for the other preconditioners s holds P^-1 r already
// and is filtered here. Returns r_i^T s_i (s's row i written)
inline double preconditionRow(const std::vector<Vec3d>& r, const Filter& filter, CgPreconditioner kind,
                              const CgScratch& w, std::vector<Vec3d>& s, int64_t i) {
  s[i] = filter(i, kind == CgPreconditioner::BlockJacobi ? Vec3d(w.precond[i] * r[i]) : s[i]);
  return r[i].dot(s[i]);
}

// the global part of the Cholesky or multigrid preconditioner: s = P^-1 r (block Jacobi is per row)
void applyGlobal(const std::vector<Vec3d>& r, CgPreconditioner kind, CgScratch& w, std::vector<Vec3d>& s) {
  s.resize(r.size());
  if (kind == CgPreconditioner::Cholesky) w.cholesky.solve(r, s);
  if (kind == CgPreconditioner::Multigrid) w.multigrid.apply(r, s);
}

// s = filter(P^-1 r); returns r^T s
double precondition(const std::vector<Vec3d>& r, const Filter& filter, CgPreconditioner kind, CgScratch& w,
                    std::vector<Vec3d>& s) {
  applyGlobal(r, kind, w, s);
  return chunkedSum(static_cast<int64_t>(r.size()), w.partial,
                    [&](int64_t i) { return preconditionRow(r, filter, kind, w, s, i); });
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

// the iterations of one solve after its start (startPcg): the state the passes share
struct PcgIterations {
  const BlockMatrix& A;
  const Filter& filter;
  CgPreconditioner kind;
  std::vector<Vec3d>& x;
  CgScratch& w;
  CgResult& result;
  double delta0, deltaNew, tol2;
  int maxIterations;
  int64_t n = A.rows;
  double alpha = 0.0, beta = 0.0;

  // q = filter(A c) and c^T q, over chunk c of the rows
  double product(int64_t c) {
    return chunkSum(n, c, [&](int64_t i) {
      if (rowHeld(filter.kind[i])) {
        w.q[i].setZero();
        return 0.0;
      }
      w.q[i] = filter(i, A.row(w.c, i));
      return w.c[i].dot(w.q[i]);
    });
  }
  // x += alpha c, r -= alpha q (filtered rows of c, q, r are zero)
  void step(int64_t i) {
    x[i] += alpha * w.c[i];
    w.r[i] -= alpha * w.q[i];
  }
  // with block Jacobi also s = filter(P^-1 r) and r^T s, in the same pass
  double stepAndPrecondition(int64_t c) {
    return chunkSum(n, c, [&](int64_t i) {
      step(i);
      return preconditionRow(w.r, filter, kind, w, w.s, i);
    });
  }
  void direction(int64_t i) { w.c[i] = w.s[i] + beta * w.c[i]; }
  // after c^T q: alpha, or false at the breakdown of a matrix that is not positive definite
  bool takeStep(double cq) {
    result.breakdown = !(cq > 0.0);
    alpha = deltaNew / cq;
    return !result.breakdown;
  }
  bool goOn() const { return deltaNew > tol2 * delta0 && result.iterations < maxIterations; }
  // after r^T s: beta, and whether to go on
  bool nextDirection(double rs) {
    beta = rs / deltaNew;
    deltaNew = rs;
    ++result.iterations;
    return goOn();
  }

  // block Jacobi: one parallel region for the whole solve, the passes parted by the loops' barriers,
  // the scalars computed by one thread (fork and join four times an iteration cost as much as a pass)
  void runPerRow() {
    const int64_t chunks = sumChunks(n);
    w.partial.resize(static_cast<size_t>(chunks));
    bool more = goOn();
#pragma omp parallel if (n >= kParallelGrain)
    while (more) {
#pragma omp for schedule(static)
      for (int64_t c = 0; c < chunks; ++c) w.partial[c] = product(c);
#pragma omp single
      more = takeStep(addPartials(w.partial));
      if (!more) break;
#pragma omp for schedule(static)
      for (int64_t c = 0; c < chunks; ++c) w.partial[c] = stepAndPrecondition(c);
#pragma omp single
      more = nextDirection(addPartials(w.partial));
#pragma omp for schedule(static)
      for (int64_t i = 0; i < n; ++i) direction(i);
    }
  }
  // Cholesky and multigrid: their global solve between the passes, each pass its own parallel loop
  void runGlobal() {
    for (bool more = goOn(); more;) {
      if (!takeStep(sumOfChunks(n, w.partial, [&](int64_t c) { return product(c); }))) break;
      parallelFor(n, [&](int64_t i) { step(i); });
      more = nextDirection(precondition(w.r, filter, kind, w, w.s));
      parallelFor(n, [&](int64_t i) { direction(i); });
    }
  }
};

}  // namespace

CgResult filteredPcg(const BlockMatrix& A, const std::vector<Vec3d>& b, const std::vector<uint8_t>& constrained,
                     std::vector<Vec3d>& x, const CgOptions& options, CgScratch& w,
                     std::span<const Vec3d> contactNormal) {
  if (options.preconditioner == CgPreconditioner::GaussSeidel)
    return gaussSeidelPcg(A, b, constrained, contactNormal, x, options, w.gaussSeidel);
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
  PcgIterations it{A, filter, kind, x, w, result, delta0, deltaNew, tol2, options.maxIterations};
  if (kind == CgPreconditioner::BlockJacobi)
    it.runPerRow();
  else
    it.runGlobal();
  result.residual = std::sqrt(std::max(it.deltaNew, 0.0) / delta0);
  result.converged = !result.breakdown && it.deltaNew <= tol2 * delta0;
  return result;
}

}  // namespace soak
