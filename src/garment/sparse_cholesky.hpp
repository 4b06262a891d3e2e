// the sparse Cholesky preconditioner of the filtered PCG (block_cg.hpp): the filtered system matrix
// (filteredBlock: a held vertex's row and column replaced by the identity, a contact row restricted
// to its tangent plane) factored exactly, L L^T, with
// Eigen's SimplicialLLT in an AMD order. With it the PCG needs one or two iterations; the fill-reducing
// order and the elimination tree depend only on the block pattern, so they are computed once per
// pattern and reused by every later solve.
#pragma once
#include "garment/block_matrix.hpp"

#include <Eigen/SparseCholesky>

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace soak {

class SparseCholesky {
 public:
  SparseCholesky() = default;
  // a copy starts empty, as scratch does: its first factor() builds the pattern again
  SparseCholesky(const SparseCholesky&) {}
  SparseCholesky& operator=(const SparseCholesky&) { return *this = SparseCholesky(); }
  SparseCholesky(SparseCholesky&&) = default;
  SparseCholesky& operator=(SparseCholesky&&) = default;
  // factors the filtered matrix of A (filteredBlock: a held row and column replaced by the identity,
  // a contact row restricted to its tangent plane, its normal decoupled); false when it is not
  // numerically positive definite (the caller falls back to block Jacobi)
  bool factor(const BlockMatrix& A, const std::vector<uint8_t>& kind, std::span<const Vec3d> normal);
  // s = F^-1 r with F the factored matrix (the caller filters s); r, s: one Vec3d per row
  void solve(const std::vector<Vec3d>& r, std::vector<Vec3d>& s) const;

 private:
  void buildPattern(const BlockMatrix& A);

  Eigen::SparseMatrix<double> lower_;  // lower triangle of the filtered matrix, scalar, column-major
  std::vector<int> valueOf_;           // per block k and entry 3a + b: index into lower_'s values (-1 above the diagonal: not stored)
  std::vector<int> rowStart_, col_;    // the block pattern lower_ was built for
  using Llt = Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>>;
  std::unique_ptr<Llt> llt_;  // on the heap: Eigen's solvers cannot be moved, the scratch that holds this can
};

}  // namespace soak
