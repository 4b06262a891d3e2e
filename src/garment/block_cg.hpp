// sparse symmetric matrices of 3x3 blocks (one row per cloth vertex) and the modified
// preconditioned conjugate gradient of Baraff & Witkin 1998 (section 5.3) that Chen et al. 2012
// use for Eq. 3-5: constrained vertices are filtered out of every search direction, so the solve
// never moves them away from their prescribed value; a contact row is filtered along its normal only
// (S_i = I - n n^T), so it keeps its prescribed normal velocity change and slides freely.
// Preconditioned by symmetric block Gauss-Seidel (gauss_seidel_cg.hpp), block Jacobi, the exact
// sparse Cholesky factor of the filtered matrix (sparse_cholesky.hpp) or a two-level multigrid
// V-cycle (multigrid.hpp). Double precision; every
// sum runs in a fixed order, so the result does not depend on the thread count.
#pragma once
#include <soak/garment_params.hpp>
#include <soak/math.hpp>

#include "garment/block_matrix.hpp"
#include "garment/gauss_seidel_cg.hpp"
#include "garment/multigrid.hpp"
#include "garment/sparse_cholesky.hpp"

#include <cstdint>
#include <vector>

namespace soak {

struct CgOptions {
  double tolerance = 1e-5;  // stop when sqrt(r^T P^-1 r / b^T P^-1 b) <= tolerance (filtered r, b)
  int maxIterations = 500;
  CgPreconditioner preconditioner = CgPreconditioner::BlockJacobi;
  bool sameMatrix = false;  // A's values are those of the last solve with this scratch (only the filter changed)
};

struct CgResult {
  int iterations = 0;
  double residual = 0.0;   // the relative preconditioned residual at exit
  bool converged = false;
  bool breakdown = false;  // a direction with c^T A c <= 0: the matrix is not positive definite
  bool factorFailed = false;  // the Cholesky or coarse multigrid factor failed: block Jacobi was used
};

struct CgScratch {
  std::vector<Vec3d> r, c, q, s;
  std::vector<Eigen::Matrix3d> precond;  // inverse diagonal blocks (block Jacobi)
  SparseCholesky cholesky;               // the factor and its pattern, kept from solve to solve
  Multigrid multigrid;                   // the levels of the last solve
  GaussSeidelScratch gaussSeidel;        // the colour order and the sweeps' vectors
  std::vector<double> partial;           // per-chunk partial sums of the dot products
};

// solves S (A x - b) = 0 with (I - S) x held at its input value (Baraff-Witkin's z; the free part
// of x is the initial guess); S_i from constrained[i] (filterRow), contactNormal[i] the unit normal
// of each kContactRow row (may be empty when there is none). A must be symmetric positive definite
// on the free part.
CgResult filteredPcg(const BlockMatrix& A, const std::vector<Vec3d>& b, const std::vector<uint8_t>& constrained,
                     std::vector<Vec3d>& x, const CgOptions& options, CgScratch& scratch,
                     std::span<const Vec3d> contactNormal = {});

// deterministic dot product of two block vectors (fixed chunks, partial sums added in order)
double blockDot(const std::vector<Vec3d>& a, const std::vector<Vec3d>& b, std::vector<double>& partial);

}  // namespace soak
