// two-level smoothed aggregation multigrid preconditioner (multigrid.hpp)
#include "garment/multigrid.hpp"

#include "core/parallel.hpp"
#include "garment/block_cg.hpp"

#include <algorithm>
#include <cmath>

namespace soak {

namespace {

constexpr int kSmoothingSweeps = 2;  // damped block-Jacobi sweeps before and after the coarse correction
constexpr int kPowerIterations = 10;  // for lambda_max(D^-1 A), which sets the damping

// y = S A S x for a filtered x (S x = x): each row's filter of A x, zero on a held row
void filteredMultiply(const BlockMatrix& A, const std::vector<uint8_t>& kind, std::span<const Vec3d> normal,
                      const std::vector<Vec3d>& x, std::vector<Vec3d>& y) {
  y.resize(x.size());
  parallelFor(A.rows, [&](int64_t i) { y[i] = filterRow(kind[i], normal, i, A.row(x, i)); });
}

// rows of blocks built in parallel: unless `samePattern` (out's columns are those of the last build),
// columns(i, list) lists row i's distinct columns (in any fixed order: they are sorted) in a first
// pass; then add(i, put) calls put(column, block) for every term of row i, summed into its block
template <class Columns, class Add>
void buildRows(int rows, int maxColumns, bool samePattern, BlockRows& out, ThreadBuffers<int>& scratch,
               Columns&& columns, Add&& add) {
  if (!samePattern) {
    out.start.assign(static_cast<size_t>(rows) + 1, 0);
    scratch.prepare();
    parallelFor(rows, [&](int64_t i) {
      int* list = scratch.get(static_cast<size_t>(maxColumns));
      out.start[i + 1] = columns(static_cast<int>(i), list);
    });
    for (int i = 0; i < rows; ++i) out.start[i + 1] += out.start[i];
    out.col.resize(static_cast<size_t>(out.start[rows]));
    parallelFor(rows, [&](int64_t i) {
      int* cols = out.col.data() + out.start[i];
      std::sort(cols, cols + columns(static_cast<int>(i), cols));
    });
  }
  out.block.assign(out.col.size(), Eigen::Matrix3d::Zero());
  parallelFor(rows, [&](int64_t i) {
    const int* cols = out.col.data() + out.start[i];
    const int count = out.start[i + 1] - out.start[i];
    Eigen::Matrix3d* blocks = out.block.data() + out.start[i];
    add(static_cast<int>(i), [&](int c, const Eigen::Matrix3d& b) { blocks[std::lower_bound(cols, cols + count, c) - cols] += b; });
  });
}

// appends c to list[0, count) unless it is there; returns the new count
int addColumn(int* list, int count, int c) {
  for (int k = 0; k < count; ++k)
    if (list[k] == c) return count;
  list[count] = c;
  return count + 1;
}

// aggregates of the free and contact vertices over A's pattern (greedy, in index order: a vertex
// whose neighbours are all unassigned starts one with them; the rest join a neighbour's, or start
// their own); -1 for held rows. Returns the number of aggregates.
int aggregate(const BlockMatrix& A, const std::vector<uint8_t>& kind, std::vector<int>& agg) {
  const int n = A.rows;
  agg.assign(static_cast<size_t>(n), -1);
  int count = 0;
  const auto neighbours = [&](int v, auto&& f) {
    for (int k = A.rowStart[v]; k < A.rowStart[v + 1]; ++k)
      if (A.col[k] != v && !rowHeld(kind[A.col[k]])) f(A.col[k]);
  };
  for (int v = 0; v < n; ++v) {
    if (rowHeld(kind[v]) || agg[v] >= 0) continue;
    bool free = true;
    neighbours(v, [&](int u) { free = free && agg[u] < 0; });
    if (!free) continue;
    agg[v] = count;
    neighbours(v, [&](int u) { agg[u] = count; });
    ++count;
  }
  const std::vector<int> first = agg;  // join an aggregate of the first pass only: no chains
  for (int v = 0; v < n; ++v) {
    if (rowHeld(kind[v]) || agg[v] >= 0) continue;
    neighbours(v, [&](int u) {
      if (agg[v] < 0 && first[u] >= 0) agg[v] = first[u];
    });
  }
  for (int v = 0; v < n; ++v) {
    if (rowHeld(kind[v]) || agg[v] >= 0) continue;
    agg[v] = count;
    neighbours(v, [&](int u) {
      if (agg[u] < 0) agg[u] = count;
    });
    ++count;
  }
  return count;
}

}  // namespace

bool Multigrid::setup(const BlockMatrix& A, const std::vector<uint8_t>& kind, std::span<const Vec3d> normal) {
  fine_ = &A;
  kind_ = &kind;
  normal_ = normal;
  const int n = A.rows;
  diagInv_.resize(static_cast<size_t>(n));
  parallelFor(n, [&](int64_t i) {
    diagInv_[i] = filteredDiagonal(kind[i], normal, i, A.block[A.rowStart[i]]).inverse();
  });
  omega_ = 4.0 / (3.0 * std::max(largestEigenvalue(), 1e-12));
  // the levels' patterns (P, S A S P, the coarse matrix and its ordering) depend only on A's pattern
  // and the aggregates: when both are the last setup's, only the values are computed again
  std::vector<int> previous = std::move(agg_);
  const int m = aggregate(A, kind, agg_);
  samePattern_ = ldlt_ && previous == agg_ && rowStart_ == A.rowStart && col_ == A.col;
  if (!samePattern_) {
    rowStart_ = A.rowStart;
    col_ = A.col;
    ldlt_.reset();
  }
  if (m == 0) return true;  // every row held: the smoothing alone
  buildProlongation();
  buildCoarse(m);
  // an aggregate of one contact vertex has no normal unknown: a tiny diagonal keeps the factor
  // defined there (its right-hand side is zero, so is its correction)
  const double scale = coarse_.diagonal().cwiseAbs().maxCoeff();
  for (int k = 0; k < coarse_.rows(); ++k) coarse_.coeffRef(k, k) += 1e-12 * scale;
  if (!ldlt_) {
    ldlt_ = std::make_unique<Ldlt>();
    ldlt_->analyzePattern(coarse_);
  }
  ldlt_->factorize(coarse_);
  return ldlt_->info() == Eigen::Success;
}

// lambda_max(D^-1 S A S) on the free part by power iteration from a fixed start (deterministic)
double Multigrid::largestEigenvalue() {
  const int n = fine_->rows;
  std::vector<Vec3d>& u = x_;
  std::vector<Vec3d>& au = res_;
  u.resize(static_cast<size_t>(n));
  au.resize(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    const Vec3d start(1.0 + double(3 * i) / (3 * n), 1.0 + double(3 * i + 1) / (3 * n), 1.0 + double(3 * i + 2) / (3 * n));
    u[i] = filterRow((*kind_)[i], normal_, i, start);
  }
  double lambda = 1.0;
  for (int k = 0; k < kPowerIterations; ++k) {
    filteredMultiply(*fine_, *kind_, normal_, u, tmp_);
    parallelFor(n, [&](int64_t i) { au[i] = diagInv_[i] * tmp_[i]; });
    const double norm = std::sqrt(blockDot(au, au, partial_)), before = std::sqrt(blockDot(u, u, partial_));
    if (!(norm > 0.0) || !(before > 0.0)) break;
    lambda = norm / before;
    parallelFor(n, [&](int64_t i) { u[i] = au[i] / norm; });
  }
  return lambda;
}

// P = (I - omega D^-1 S A S) P0, P0 row i the filter S_i in aggregate agg(i)'s column; P^T by
// counting. S_j P0_j = P0_j, so row i's term from column j is -omega D_i^-1 S_i A_ij S_j.
void Multigrid::buildProlongation() {
  const BlockMatrix& A = *fine_;
  const std::vector<uint8_t>& kind = *kind_;
  int widest = 0;
  for (int i = 0; i < A.rows; ++i) widest = std::max(widest, A.rowStart[i + 1] - A.rowStart[i]);
  const auto columns = [&](int i, int* list) {
    int count = 0;
    if (agg_[i] < 0) return 0;
    for (int k = A.rowStart[i]; k < A.rowStart[i + 1]; ++k)
      if (agg_[A.col[k]] >= 0) count = addColumn(list, count, agg_[A.col[k]]);
    return count;
  };
  buildRows(A.rows, widest, samePattern_, prolong_, columnScratch_, columns, [&](int i, auto&& put) {
    if (agg_[i] < 0) return;
    const Eigen::Matrix3d si = filterMatrix(kind[i], normal_, i);
    put(agg_[i], si);
    const Eigen::Matrix3d left = -omega_ * diagInv_[i] * si;
    for (int k = A.rowStart[i]; k < A.rowStart[i + 1]; ++k) {
      const int j = A.col[k];
      if (agg_[j] < 0) continue;
      const Eigen::Matrix3d la = left * A.block[k];
      put(agg_[j], kind[j] == kFreeRow ? la : Eigen::Matrix3d(la * filterMatrix(kind[j], normal_, j)));
    }
  });
  const int m = 1 + *std::max_element(agg_.begin(), agg_.end());
  restrict_.start.assign(static_cast<size_t>(m) + 1, 0);
  for (int c : prolong_.col) ++restrict_.start[c + 1];
  for (int a = 0; a < m; ++a) restrict_.start[a + 1] += restrict_.start[a];
  restrict_.col.resize(prolong_.col.size());
  restrict_.block.resize(prolong_.col.size());
  std::vector<int> fill(restrict_.start.begin(), restrict_.start.end() - 1);
  for (int i = 0; i < A.rows; ++i)
    for (int k = prolong_.start[i]; k < prolong_.start[i + 1]; ++k) {
      const int slot = fill[prolong_.col[k]]++;
      restrict_.col[slot] = i;
      restrict_.block[slot] = prolong_.block[k].transpose();
    }
}

// coarse_ = P^T (S A S P), by rows: row i of S A S P is S_i sum_j A_ij P_j (P_j filtered); the
// coarse row a sums P_ia^T times those rows over the vertices i of P^T's row a
void Multigrid::buildCoarse(int m) {
  const BlockMatrix& A = *fine_;
  const auto apColumns = [&](int i, int* list) {
    int count = 0;
    if (rowHeld((*kind_)[i])) return 0;
    for (int k = A.rowStart[i]; k < A.rowStart[i + 1]; ++k) {
      const int j = A.col[k];
      for (int q = prolong_.start[j]; q < prolong_.start[j + 1]; ++q) count = addColumn(list, count, prolong_.col[q]);
    }
    return count;
  };
  buildRows(A.rows, m, samePattern_, product_, columnScratch_, apColumns, [&](int i, auto&& put) {
    if (rowHeld((*kind_)[i])) return;
    const Eigen::Matrix3d si = filterMatrix((*kind_)[i], normal_, i);
    for (int k = A.rowStart[i]; k < A.rowStart[i + 1]; ++k) {
      const int j = A.col[k];
      const Eigen::Matrix3d sa = (*kind_)[i] == kFreeRow ? A.block[k] : Eigen::Matrix3d(si * A.block[k]);
      for (int q = prolong_.start[j]; q < prolong_.start[j + 1]; ++q) put(prolong_.col[q], sa * prolong_.block[q]);
    }
  });
  const auto coarseColumns = [&](int a, int* list) {
    int count = 0;
    for (int k = restrict_.start[a]; k < restrict_.start[a + 1]; ++k) {
      const int i = restrict_.col[k];
      for (int q = product_.start[i]; q < product_.start[i + 1]; ++q) count = addColumn(list, count, product_.col[q]);
    }
    return count;
  };
  buildRows(m, m, samePattern_, coarseBlocks_, columnScratch_, coarseColumns, [&](int a, auto&& put) {
    for (int k = restrict_.start[a]; k < restrict_.start[a + 1]; ++k) {
      const int i = restrict_.col[k];
      for (int q = product_.start[i]; q < product_.start[i + 1]; ++q) put(product_.col[q], restrict_.block[k] * product_.block[q]);
    }
  });
  // the lower triangle, column-major: column 3a + c holds C_ab(c, r) at row 3b + r for b >= a
  // (C symmetric, each block row's columns sorted)
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(coarseBlocks_.block.size() * 9);
  for (int a = 0; a < m; ++a)
    for (int k = coarseBlocks_.start[a]; k < coarseBlocks_.start[a + 1]; ++k) {
      const int b = coarseBlocks_.col[k];
      if (b < a) continue;
      for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r)
          if (3 * b + r >= 3 * a + c) entries.emplace_back(3 * b + r, 3 * a + c, coarseBlocks_.block[k](c, r));
    }
  coarse_.resize(3 * m, 3 * m);
  coarse_.setFromTriplets(entries.begin(), entries.end());
}

void Multigrid::residual(const std::vector<Vec3d>& r) {
  const BlockMatrix& A = *fine_;
  parallelFor(A.rows, [&](int64_t i) { res_[i] = r[i] - filterRow((*kind_)[i], normal_, i, A.row(x_, i)); });
}

// x_ += omega D^-1 (r - S A S x_), one pass into tmp_ (every row reads the old x_)
void Multigrid::jacobiSweep(const std::vector<Vec3d>& r) {
  const BlockMatrix& A = *fine_;
  parallelFor(A.rows, [&](int64_t i) {
    tmp_[i] = x_[i] + omega_ * (diagInv_[i] * (r[i] - filterRow((*kind_)[i], normal_, i, A.row(x_, i))));
  });
  std::swap(x_, tmp_);
}

// x_ += P (P^T A P)^-1 P^T res_
void Multigrid::coarseCorrection() {
  const int m = static_cast<int>(restrict_.start.size()) - 1;
  coarseRhs_.resize(3 * m);
  parallelFor(m, [&](int64_t a) {
    Vec3d sum = Vec3d::Zero();
    for (int k = restrict_.start[a]; k < restrict_.start[a + 1]; ++k) sum += restrict_.block[k] * res_[restrict_.col[k]];
    coarseRhs_.segment<3>(3 * a) = sum;
  });
  coarseX_ = ldlt_->solve(coarseRhs_);
  parallelFor(static_cast<int64_t>(x_.size()), [&](int64_t i) {
    for (int k = prolong_.start[i]; k < prolong_.start[i + 1]; ++k)
      x_[i] += prolong_.block[k] * coarseX_.segment<3>(3 * prolong_.col[k]);
  });
}

void Multigrid::apply(const std::vector<Vec3d>& r, std::vector<Vec3d>& s) {
  const int64_t n = static_cast<int64_t>(r.size());
  x_.resize(r.size());
  res_.resize(r.size());
  tmp_.resize(r.size());
  parallelFor(n, [&](int64_t i) { x_[i] = omega_ * (diagInv_[i] * r[i]); });  // the first sweep, from x = 0
  for (int k = 1; k < kSmoothingSweeps; ++k) jacobiSweep(r);
  if (ldlt_) {
    residual(r);
    coarseCorrection();
  }
  for (int k = 0; k < kSmoothingSweeps; ++k) jacobiSweep(r);
  s = x_;
}

}  // namespace soak
