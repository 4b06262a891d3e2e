// a two-level smoothed aggregation multigrid preconditioner for the filtered PCG (block_cg.hpp)
// (Vanek, Mandel & Brezina 1996): the vertices are grouped into aggregates (a vertex and its
// neighbours in the system's pattern), each aggregate's three translations are a coarse unknown,
// the prolongation is that piecewise-constant one smoothed by one damped Jacobi step, and the coarse
// system P^T A P is factored exactly. One symmetric V-cycle (damped block-Jacobi smoothing before
// and after the coarse correction) is the preconditioner: the smoothing removes the stiff springs'
// short-wavelength error, the coarse level the long-wavelength sag that block Jacobi alone needs
// hundreds of iterations for. It works on the filtered matrix S A S (filterRow): a held row takes no
// part, a contact row is restricted to its tangent plane. Everything but the coarse factor works on
// 3x3 blocks, row by row in parallel, each sum in a fixed order: the result does not depend on the
// thread count.
#pragma once
#include "core/parallel.hpp"
#include "garment/block_matrix.hpp"

#include <Eigen/SparseCholesky>

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace soak {

// rows of 3x3 blocks in arbitrary columns: row i holds blocks [start[i], start[i + 1]) in columns col[k]
struct BlockRows {
  std::vector<int> start{0};
  std::vector<int> col;
  std::vector<Eigen::Matrix3d> block;
};

class Multigrid {
 public:
  Multigrid() = default;
  // a copy starts empty, as scratch does: its next setup() builds everything again
  Multigrid(const Multigrid&) {}
  Multigrid& operator=(const Multigrid&) { return *this = Multigrid(); }
  Multigrid(Multigrid&&) = default;
  Multigrid& operator=(Multigrid&&) = default;
  // builds the levels for A filtered by each row's kind (filterRow; normal: the contact rows' unit
  // normals); false when the coarse system does not factor (the caller falls back to block Jacobi).
  // A, kind and normal are read again by apply(): they must outlive it unchanged.
  bool setup(const BlockMatrix& A, const std::vector<uint8_t>& kind, std::span<const Vec3d> normal);
  // s = one V-cycle applied to the filtered r (a symmetric positive definite approximation of the
  // filtered A's inverse on the free part; s is filtered too)
  void apply(const std::vector<Vec3d>& r, std::vector<Vec3d>& s);

 private:
  const BlockMatrix* fine_ = nullptr;      // A of the last setup, filtered in every product
  const std::vector<uint8_t>* kind_ = nullptr;
  std::span<const Vec3d> normal_;
  std::vector<Eigen::Matrix3d> diagInv_;  // inverse filtered diagonal blocks (the smoother)
  double omega_ = 0.0;                    // damping of the smoother and of P's smoothing, 4 / (3 lambda_max(D^-1 A))
  std::vector<int> agg_;                  // each vertex's aggregate, -1 for a held row
  BlockRows prolong_;                     // P: a row per vertex, a column per aggregate
  BlockRows restrict_;                    // P^T: a row per aggregate, a column per vertex
  BlockRows product_;                     // S A S P, a row per vertex
  BlockRows coarseBlocks_;                // P^T S A S P, a row per aggregate
  Eigen::SparseMatrix<double> coarse_;    // its lower triangle, scalar
  using Ldlt = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>>;
  std::unique_ptr<Ldlt> ldlt_;            // on the heap: Eigen's solvers cannot be moved
  std::vector<Vec3d> x_, res_, tmp_;      // V-cycle work vectors
  Eigen::VectorXd coarseRhs_, coarseX_;
  std::vector<double> partial_;           // the power iteration's dot products (blockDot)
  ThreadBuffers<int> columnScratch_;       // each thread's column list while rows are built
  std::vector<int> rowStart_, col_;        // A's pattern at the last setup
  bool samePattern_ = false;               // this setup's patterns are the last one's

  void residual(const std::vector<Vec3d>& r);     // res_ = r - S A S x_
  void jacobiSweep(const std::vector<Vec3d>& r);  // x_ += omega D^-1 (r - S A S x_)
  void coarseCorrection();                     // x_ += P (P^T A P)^-1 P^T res_
  double largestEigenvalue();                  // lambda_max(D^-1 S A S), power iteration
  void buildProlongation();                    // prolong_ and restrict_ from agg_
  void buildCoarse(int aggregates);            // coarse_ = P^T S A S P
};

}  // namespace soak
