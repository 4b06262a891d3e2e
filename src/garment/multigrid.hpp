// a two-level smoothed aggregation multigrid preconditioner for the filtered PCG (block_cg.hpp)
// (Vanek, Mandel & Brezina 1996): the vertices are grouped into aggregates (a vertex and its
// neighbours in the system's pattern), each aggregate's three translations are a coarse unknown,
// the prolongation is that piecewise-constant one smoothed by one damped Jacobi step, and the coarse
// system P^T A P is factored exactly. One symmetric V-cycle (damped block-Jacobi smoothing before
// and after the coarse correction) is the preconditioner: the smoothing removes the stiff springs'
// short-wavelength error, the coarse level the long-wavelength sag that block Jacobi alone needs
// hundreds of iterations for. It works on the filtered matrix: a held row is the identity and
// takes no part in the coarse level, a contact row is restricted to its tangent plane.
#pragma once
#include "garment/block_matrix.hpp"

#include <Eigen/SparseCholesky>

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace soak {

class Multigrid {
 public:
  Multigrid() = default;
  // a copy starts empty, as scratch does: its next setup() builds everything again
  Multigrid(const Multigrid&) {}
  Multigrid& operator=(const Multigrid&) { return *this = Multigrid(); }
  Multigrid(Multigrid&&) = default;
  Multigrid& operator=(Multigrid&&) = default;
  // builds the levels for A filtered by each row's kind (filterRow; normal: the contact rows' unit
  // normals); false when the coarse system does not factor (the caller falls back to block Jacobi)
  bool setup(const BlockMatrix& A, const std::vector<uint8_t>& kind, std::span<const Vec3d> normal);
  // s = one V-cycle applied to r (a symmetric positive definite approximation of the filtered A's
  // inverse on the free part; the caller filters s)
  void apply(const std::vector<Vec3d>& r, std::vector<Vec3d>& s);

 private:
  using RowMajor = Eigen::SparseMatrix<double, Eigen::RowMajor>;
  RowMajor fine_;                         // the filtered A, scalar
  std::vector<Eigen::Matrix3d> diagInv_;  // inverse diagonal blocks of fine_ (the smoother)
  double omega_ = 0.0;                    // damping of the smoother and of P's smoothing, 4 / (3 lambda_max(D^-1 A))
  RowMajor prolong_;                      // P, 3n x 3m
  RowMajor restrict_;                     // P^T
  Eigen::SparseMatrix<double> coarse_;    // P^T A P
  using Ldlt = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>>;
  std::unique_ptr<Ldlt> ldlt_;            // on the heap: Eigen's solvers cannot be moved
  Eigen::VectorXd x_, res_, tmp_;         // V-cycle work vectors

  void jacobiSweep();  // x_ += omega D^-1 res_ (res_ = r - A x_)
};

}  // namespace soak
