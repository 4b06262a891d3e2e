// exact sparse Cholesky preconditioner for the filtered PCG (sparse_cholesky.hpp)
#include "garment/sparse_cholesky.hpp"

#include <algorithm>

namespace soak {

namespace {

// calls f(k, a, b, row, column) for every scalar entry (a, b) of block k of A on or below the diagonal
template <class F>
void forLowerEntries(const BlockMatrix& A, F&& f) {
  for (int i = 0; i < A.rows; ++i)
    for (int k = A.rowStart[i]; k < A.rowStart[i + 1]; ++k)
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          if (3 * i + a >= 3 * A.col[k] + b) f(k, a, b, 3 * i + a, 3 * A.col[k] + b);
}

}  // namespace

void SparseCholesky::buildPattern(const BlockMatrix& A) {
  rowStart_ = A.rowStart;
  col_ = A.col;
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(A.col.size() * 6);
  forLowerEntries(A, [&](int, int, int, int row, int column) { entries.emplace_back(row, column, 0.0); });
  lower_.resize(3 * A.rows, 3 * A.rows);
  lower_.setFromTriplets(entries.begin(), entries.end());
  lower_.makeCompressed();
  valueOf_.assign(A.col.size() * 9, -1);
  const int* rows = lower_.innerIndexPtr();
  const int* outer = lower_.outerIndexPtr();
  forLowerEntries(A, [&](int k, int a, int b, int row, int column) {
    valueOf_[9 * k + 3 * a + b] = static_cast<int>(std::lower_bound(rows + outer[column], rows + outer[column + 1], row) - rows);
  });
  llt_ = std::make_unique<Llt>();
  llt_->analyzePattern(lower_);
}

bool SparseCholesky::factor(const BlockMatrix& A, const std::vector<uint8_t>& kind, std::span<const Vec3d> normal) {
  if (A.rowStart != rowStart_ || A.col != col_) buildPattern(A);
  double* values = lower_.valuePtr();
  std::fill(values, values + lower_.nonZeros(), 0.0);
  for (int i = 0; i < A.rows; ++i)
    for (int k = A.rowStart[i]; k < A.rowStart[i + 1]; ++k) {
      const Eigen::Matrix3d b = filteredBlock(A, kind, normal, i, k);
      for (int e = 0; e < 9; ++e)  // the lower triangle's entries (two springs between a pair add up)
        if (valueOf_[9 * k + e] >= 0) values[valueOf_[9 * k + e]] += b(e / 3, e % 3);
    }
  llt_->factorize(lower_);
  return llt_->info() == Eigen::Success;
}

void SparseCholesky::solve(const std::vector<Vec3d>& r, std::vector<Vec3d>& s) const {
  const Eigen::Index n = static_cast<Eigen::Index>(r.size()) * 3;
  s.resize(r.size());
  if (r.empty()) return;
  Eigen::Map<Eigen::VectorXd>(s[0].data(), n) = llt_->solve(Eigen::Map<const Eigen::VectorXd>(r[0].data(), n));
}

}  // namespace soak
