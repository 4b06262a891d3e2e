// exact sparse Cholesky preconditioner for the filtered PCG (sparse_cholesky.hpp)
#include "garment/sparse_cholesky.hpp"

#include <algorithm>

namespace soak {

void SparseCholesky::buildPattern(const BlockMatrix& A) {
  rowStart_ = A.rowStart;
  col_ = A.col;
  const int n = A.rows;
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(A.col.size() * 6);
  for (int i = 0; i < n; ++i)
    for (int k = A.rowStart[i]; k < A.rowStart[i + 1]; ++k)
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          if (3 * i + a >= 3 * A.col[k] + b) entries.emplace_back(3 * i + a, 3 * A.col[k] + b, 0.0);
  lower_.resize(3 * n, 3 * n);
  lower_.setFromTriplets(entries.begin(), entries.end());
  lower_.makeCompressed();
  valueOf_.assign(A.col.size() * 9, -1);
  const auto indexOf = [&](int row, int column) {
    const int* rows = lower_.innerIndexPtr();
    const int* begin = rows + lower_.outerIndexPtr()[column];
    const int* end = rows + lower_.outerIndexPtr()[column + 1];
    return static_cast<int>(std::lower_bound(begin, end, row) - rows);
  };
  for (int i = 0; i < n; ++i)
    for (int k = A.rowStart[i]; k < A.rowStart[i + 1]; ++k)
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          if (3 * i + a >= 3 * A.col[k] + b) valueOf_[9 * k + 3 * a + b] = indexOf(3 * i + a, 3 * A.col[k] + b);
  llt_ = std::make_unique<Llt>();
  llt_->analyzePattern(lower_);
}

bool SparseCholesky::factor(const BlockMatrix& A, const std::vector<uint8_t>& constrained) {
  if (A.rowStart != rowStart_ || A.col != col_) buildPattern(A);
  double* values = lower_.valuePtr();
  std::fill(values, values + lower_.nonZeros(), 0.0);
  for (int i = 0; i < A.rows; ++i)
    for (int k = A.rowStart[i]; k < A.rowStart[i + 1]; ++k) {
      const int j = A.col[k];
      const bool filtered = constrained[i] || constrained[j];
      if (filtered && i != j) continue;  // a constrained vertex is coupled to nothing
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
          const int slot = valueOf_[9 * k + 3 * a + b];
          if (slot >= 0) values[slot] += filtered ? (a == b ? 1.0 : 0.0) : A.block[k](a, b);
        }
    }
  llt_->factorize(lower_);
  return llt_->info() == Eigen::Success;
}

void SparseCholesky::solve(const std::vector<Vec3d>& r, const std::vector<uint8_t>& constrained,
                           std::vector<Vec3d>& s) const {
  const Eigen::Index n = static_cast<Eigen::Index>(r.size()) * 3;
  s.resize(r.size());
  if (r.empty()) return;
  Eigen::Map<Eigen::VectorXd>(s[0].data(), n) = llt_->solve(Eigen::Map<const Eigen::VectorXd>(r[0].data(), n));
  for (size_t i = 0; i < r.size(); ++i)
    if (constrained[i]) s[i].setZero();
}

}  // namespace soak
