// two-level smoothed aggregation multigrid preconditioner (multigrid.hpp)
#include "garment/multigrid.hpp"

#include <algorithm>
#include <cmath>

namespace soak {

namespace {

constexpr int kSmoothingSweeps = 2;  // damped block-Jacobi sweeps before and after the coarse correction
constexpr int kPowerIterations = 10;  // for lambda_max(D^-1 A), which sets the damping

// the filtered system as scalar entries (filteredBlock: a held row the identity, a contact row's
// normal decoupled); its diagonal blocks
std::vector<Eigen::Triplet<double>> filteredEntries(const BlockMatrix& A, const std::vector<uint8_t>& kind,
                                                    std::span<const Vec3d> normal,
                                                    std::vector<Eigen::Matrix3d>& diagonal) {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(A.block.size() * 9);
  diagonal.resize(static_cast<size_t>(A.rows));
  for (int i = 0; i < A.rows; ++i) {
    for (int k = A.rowStart[i]; k < A.rowStart[i + 1]; ++k) {
      const int j = A.col[k];
      const Eigen::Matrix3d b = filteredBlock(A, kind, normal, i, k);
      if (j == i) diagonal[i] = b;
      for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) entries.emplace_back(3 * i + a, 3 * j + c, b(a, c));
    }
  }
  return entries;
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
  const int n = A.rows;
  std::vector<Eigen::Matrix3d> diagonal;
  const std::vector<Eigen::Triplet<double>> entries = filteredEntries(A, kind, normal, diagonal);
  fine_.resize(3 * n, 3 * n);
  fine_.setFromTriplets(entries.begin(), entries.end());
  diagInv_.resize(static_cast<size_t>(n));
  std::vector<Eigen::Triplet<double>> dinv;
  dinv.reserve(static_cast<size_t>(n) * 9);
  for (int i = 0; i < n; ++i) {
    diagInv_[i] = diagonal[i].inverse();
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < 3; ++c) dinv.emplace_back(3 * i + a, 3 * i + c, diagInv_[i](a, c));
  }
  RowMajor dinvA(3 * n, 3 * n);
  dinvA.setFromTriplets(dinv.begin(), dinv.end());
  dinvA = RowMajor(dinvA * fine_).pruned();
  // lambda_max(D^-1 A) by power iteration from a fixed start (deterministic)
  Eigen::VectorXd u = Eigen::VectorXd::LinSpaced(3 * n, 1.0, 2.0), au;
  double lambda = 1.0;
  for (int k = 0; k < kPowerIterations; ++k) {
    au = dinvA * u;
    lambda = au.norm() / std::max(u.norm(), 1e-300);
    u = au / std::max(au.norm(), 1e-300);
  }
  omega_ = 4.0 / (3.0 * std::max(lambda, 1e-12));
  std::vector<int> agg;
  const int m = aggregate(A, kind, agg);
  ldlt_.reset();
  if (m == 0) return true;  // every row held: the smoothing alone (exact on identity rows)
  std::vector<Eigen::Triplet<double>> tent;
  tent.reserve(static_cast<size_t>(n) * 9);
  for (int i = 0; i < n; ++i) {
    if (agg[i] < 0) continue;
    const Eigen::Matrix3d s = filterMatrix(kind[i], normal, i);
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < 3; ++c)
        if (s(a, c) != 0.0) tent.emplace_back(3 * i + a, 3 * agg[i] + c, s(a, c));
  }
  RowMajor tentative(3 * n, 3 * m);
  tentative.setFromTriplets(tent.begin(), tent.end());
  const RowMajor smoothed = dinvA * tentative;
  prolong_ = (tentative - omega_ * smoothed).pruned();
  restrict_ = prolong_.transpose();
  const RowMajor ap = fine_ * prolong_;
  coarse_ = Eigen::SparseMatrix<double>(restrict_ * ap);
  // an aggregate of one contact vertex has no normal unknown: a tiny diagonal keeps the factor
  // defined there (its right-hand side is zero, so is its correction)
  const double scale = coarse_.diagonal().cwiseAbs().maxCoeff();
  for (int k = 0; k < coarse_.rows(); ++k) coarse_.coeffRef(k, k) += 1e-12 * scale;
  ldlt_ = std::make_unique<Ldlt>();
  ldlt_->compute(coarse_);
  return ldlt_->info() == Eigen::Success;
}

void Multigrid::jacobiSweep() {
  for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(diagInv_.size()); ++i)
    x_.segment<3>(3 * i) += omega_ * (diagInv_[i] * res_.segment<3>(3 * i));
}

void Multigrid::apply(const std::vector<Vec3d>& r, std::vector<Vec3d>& s) {
  const Eigen::Index n = static_cast<Eigen::Index>(r.size()) * 3;
  s.resize(r.size());
  if (r.empty()) return;
  const Eigen::Map<const Eigen::VectorXd> rv(r[0].data(), n);
  x_.setZero(n);
  res_ = rv;  // the first sweep from x = 0 needs no product
  for (int k = 0; k < kSmoothingSweeps; ++k) {
    if (k > 0) res_ = rv - fine_ * x_;
    jacobiSweep();
  }
  if (ldlt_) {
    res_ = rv - fine_ * x_;
    tmp_ = restrict_ * res_;
    x_ += prolong_ * ldlt_->solve(tmp_);
  }
  for (int k = 0; k < kSmoothingSweeps; ++k) {
    res_ = rv - fine_ * x_;
    jacobiSweep();
  }
  Eigen::Map<Eigen::VectorXd>(s[0].data(), n) = x_;
}

}  // namespace soak
