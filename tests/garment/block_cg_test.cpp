// the block matrices and the filtered PCG of Baraff & Witkin 1998 (section 5.3) that the implicit garment
// solve uses: products against dense algebra, constrained rows held, the preconditioner, the reported
// breakdown and iteration cap, and the same answer for any thread count
#include "garment/block_cg.hpp"
#include "support/block_systems.hpp"

#include <soak/threads.hpp>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <omp.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

namespace soak {
namespace {

using testing::blocksOf;
using testing::randomBlock;
using testing::randomSpd;

TEST(GarmentCg, FilteredPcgSolvesFreeRowsAndKeepsConstrainedRows) {
  // a random SPD 3x3-block tridiagonal matrix of 6 rows
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int n = 6;
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (int i = 0; i + 1 < n; ++i) {
    const Eigen::Matrix3d b = randomBlock(rng);
    dense.block<3, 3>(3 * i, 3 * i + 3) = b;
    dense.block<3, 3>(3 * i + 3, 3 * i) = b.transpose();
  }
  dense += 8.0 * Eigen::MatrixXd::Identity(3 * n, 3 * n);
  const BlockMatrix A = blocksOf(dense);
  std::vector<Vec3d> b(n), x(n, Vec3d::Zero());
  for (auto& v : b) v = Vec3d(u(rng), u(rng), u(rng));
  std::vector<uint8_t> constrained{0, 1, 0, 0, 1, 0};
  x[1] = Vec3d(0.3, -0.2, 0.1);
  x[4] = Vec3d(-1.0, 0.5, 2.0);
  const std::vector<Vec3d> z = x;
  CgScratch scratch;
  const CgResult res = filteredPcg(A, b, constrained, x, CgOptions{1e-10, 200}, scratch);
  EXPECT_TRUE(res.converged);
  EXPECT_LE(res.residual, 1e-10);
  EXPECT_EQ(x[1], z[1]);
  EXPECT_EQ(x[4], z[4]);
  // reference: the free rows of A x = b with the constrained x fixed, solved densely
  const std::vector<int> freeRows{0, 2, 3, 5};
  Eigen::MatrixXd Aff(12, 12);
  Eigen::VectorXd rhs(12);
  Eigen::VectorXd xc = Eigen::VectorXd::Zero(3 * n);
  for (int i : {1, 4}) xc.segment<3>(3 * i) = z[i];
  const Eigen::VectorXd Axc = dense * xc;
  for (int a = 0; a < 4; ++a) {
    rhs.segment<3>(3 * a) = b[freeRows[a]] - Axc.segment<3>(3 * freeRows[a]);
    for (int c = 0; c < 4; ++c) Aff.block<3, 3>(3 * a, 3 * c) = dense.block<3, 3>(3 * freeRows[a], 3 * freeRows[c]);
  }
  const Eigen::VectorXd ref = Aff.ldlt().solve(rhs);
  for (int a = 0; a < 4; ++a) EXPECT_LT((x[freeRows[a]] - ref.segment<3>(3 * a)).norm(), 1e-8);
}

// a contact row (kContactRow) keeps its velocity change along its normal and is solved in its tangent
// plane: the result is the dense solve of T^T A T y = T^T (b - A z), x = z + T y, with T spanning the
// free rows and the contact rows' tangent planes; the impulse A x - b of a contact row is along its
// normal. With every preconditioner.
TEST(GarmentCg, AContactRowIsHeldAlongItsNormalOnly) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int n = 6;
  Eigen::MatrixXd dense = 8.0 * Eigen::MatrixXd::Identity(3 * n, 3 * n);
  for (int i = 0; i + 1 < n; ++i) {
    const Eigen::Matrix3d b = randomBlock(rng);
    dense.block<3, 3>(3 * i, 3 * i + 3) = b;
    dense.block<3, 3>(3 * i + 3, 3 * i) = b.transpose();
  }
  const BlockMatrix A = blocksOf(dense);
  std::vector<Vec3d> b(n), normal(n, Vec3d::Zero()), z(n, Vec3d::Zero());
  for (auto& v : b) v = Vec3d(u(rng), u(rng), u(rng));
  const std::vector<uint8_t> kind{0, 1, kContactRow, 0, kContactRow, 0};
  z[1] = Vec3d(0.3, -0.2, 0.1);
  for (int i : {2, 4}) {
    normal[i] = Vec3d(u(rng), u(rng), u(rng)).normalized();
    z[i] = (0.5 * i) * normal[i];
  }
  const std::vector<Vec3d> ref = testing::filteredReference(dense, b, z, kind, normal);
  for (CgPreconditioner pre : {CgPreconditioner::BlockJacobi, CgPreconditioner::Cholesky, CgPreconditioner::Multigrid,
                               CgPreconditioner::GaussSeidel}) {
    std::vector<Vec3d> x = z;
    CgScratch scratch;
    CgOptions opt{1e-12, 200};
    opt.preconditioner = pre;
    const CgResult res = filteredPcg(A, b, kind, x, opt, scratch, normal);
    EXPECT_TRUE(res.converged);
    if (pre == CgPreconditioner::Cholesky) EXPECT_LE(res.iterations, 1);  // it factors the filtered system
    EXPECT_EQ(x[1], z[1]);
    for (int i : {2, 4}) EXPECT_NEAR(x[i].dot(normal[i]), z[i].dot(normal[i]), 1e-12);
    for (int i = 0; i < n; ++i) EXPECT_LT((x[i] - ref[i]).norm(), 1e-9) << "row " << i;
    std::vector<Vec3d> ax;
    A.multiply(x, ax);
    for (int i : {2, 4}) {
      const Vec3d impulse = ax[i] - b[i];
      EXPECT_LT((impulse - impulse.dot(normal[i]) * normal[i]).norm(), 1e-9);
      EXPECT_GT(std::abs(impulse.dot(normal[i])), 1e-3);  // the row does hold something
    }
  }
}

// y = A x row by row equals the dense product, for a non-symmetric pattern with a gap in it
TEST(GarmentCg, MultiplyMatchesTheDenseProduct) {
  std::mt19937 rng(11);
  const int n = 5;
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  const int pattern[][2] = {{0, 0}, {0, 3}, {1, 1}, {1, 0}, {2, 2}, {2, 4}, {3, 3}, {4, 4}, {4, 1}};
  for (const auto& ij : pattern) dense.block<3, 3>(3 * ij[0], 3 * ij[1]) = randomBlock(rng);
  const BlockMatrix A = blocksOf(dense);
  ASSERT_EQ(A.block.size(), 9u);
  std::vector<Vec3d> x(n), y;
  Eigen::VectorXd xd(3 * n);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int i = 0; i < n; ++i) {
    x[i] = Vec3d(u(rng), u(rng), u(rng));
    xd.segment<3>(3 * i) = x[i];
  }
  A.multiply(x, y);
  const Eigen::VectorXd yd = dense * xd;
  ASSERT_EQ(y.size(), size_t(n));
  for (int i = 0; i < n; ++i) EXPECT_LT((y[i] - yd.segment<3>(3 * i)).norm(), 1e-12) << i;
}

// blockDot: the per-row dot products summed in row order within chunks of 256 rows, the chunks' sums
// (left in `partial`) added in chunk order: bit for bit that serial loop, at any thread count
TEST(GarmentCg, BlockDotSumsFixedChunksInOrder) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3d> a(3000), b(3000);  // more than parallelFor's grain: the chunks run in parallel
  for (size_t i = 0; i < a.size(); ++i) a[i] = Vec3d(u(rng), 1e6 * u(rng), u(rng)), b[i] = Vec3d(u(rng), u(rng), 1e-6 * u(rng));
  std::vector<double> chunk((a.size() + 255) / 256, 0.0);
  for (size_t i = 0; i < a.size(); ++i) chunk[i / 256] += a[i].dot(b[i]);
  double serial = 0.0;
  for (double c : chunk) serial += c;
  const int before = omp_get_max_threads();
  for (int threads : {1, 2, 3}) {
    omp_set_num_threads(threads);
    std::vector<double> partial;
    EXPECT_EQ(blockDot(a, b, partial), serial) << threads;
    EXPECT_EQ(partial, chunk) << threads;
  }
  omp_set_num_threads(before);
  // rounding shows the order: 5 x 0.75 then 1e16 gives 1e16 + 4 (the spacing of doubles there is 2), and
  // -1e16 leaves 4; summed from the end it would be 0 + 3.75
  std::vector<Vec3d> c(5, Vec3d(0.75, 0, 0)), e(7, Vec3d(1, 0, 0));
  c.push_back(Vec3d(1e16, 0, 0));
  c.push_back(Vec3d(-1e16, 0, 0));
  std::vector<double> partial;
  EXPECT_EQ(blockDot(c, e, partial), 4.0);
}

// with block-Jacobi preconditioning a block-diagonal system is solved in one iteration: P^-1 A = I. A
// preconditioner other than the inverse diagonal blocks needs several
TEST(GarmentCg, BlockDiagonalSystemIsSolvedInOneIteration) {
  std::mt19937 rng(7);
  const int n = 8;
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Matrix3d r = randomBlock(rng);
    // SPD blocks with eigenvalues spread over two orders of magnitude
    dense.block<3, 3>(3 * i, 3 * i) = r * r.transpose() + (0.1 + 10.0 * i) * Eigen::Matrix3d::Identity();
  }
  const BlockMatrix A = blocksOf(dense);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3d> b(n), x(n, Vec3d::Zero());
  for (auto& v : b) v = Vec3d(u(rng), u(rng), u(rng));
  CgScratch scratch;
  const CgResult res = filteredPcg(A, b, std::vector<uint8_t>(n, 0), x, CgOptions{1e-12, 50}, scratch);
  EXPECT_TRUE(res.converged);
  EXPECT_EQ(res.iterations, 1);
  for (int i = 0; i < n; ++i)
    EXPECT_LT((x[i] - dense.block<3, 3>(3 * i, 3 * i).ldlt().solve(b[i])).norm(), 1e-12 * (1.0 + b[i].norm())) << i;
}

// a direction with c^T A c <= 0 stops the solve as a breakdown, not as convergence. [[I, 2I], [2I, I]] has
// positive diagonal blocks (a positive preconditioner) and eigenvalues 3 and -1; b = (u, -u) lies in the
// negative eigenspace, so the first direction (c = b) already has c^T A c = -|b|^2 < 0
TEST(GarmentCg, IndefiniteMatrixIsReportedAsABreakdown) {
  Eigen::MatrixXd dense(6, 6);
  dense << Eigen::Matrix3d::Identity(), 2.0 * Eigen::Matrix3d::Identity(), 2.0 * Eigen::Matrix3d::Identity(),
      Eigen::Matrix3d::Identity();
  const BlockMatrix A = blocksOf(dense);
  // with the Cholesky preconditioner asked for, its factor fails, block Jacobi is used, and it says so;
  // symmetric Gauss-Seidel's M = [[I, 2I], [2I, 5I]] is positive definite, its first direction is not
  for (const CgPreconditioner kind :
       {CgPreconditioner::BlockJacobi, CgPreconditioner::Cholesky, CgPreconditioner::GaussSeidel}) {
    std::vector<Vec3d> b{Vec3d(1, 1, 1), Vec3d(-1, -1, -1)}, x(2, Vec3d::Zero());
    CgScratch scratch;
    CgOptions opt{1e-10, 100};
    opt.preconditioner = kind;
    const CgResult res = filteredPcg(A, b, std::vector<uint8_t>(2, 0), x, opt, scratch);
    EXPECT_TRUE(res.breakdown);
    EXPECT_FALSE(res.converged);
    EXPECT_EQ(res.iterations, 0);
    EXPECT_EQ(res.factorFailed, kind == CgPreconditioner::Cholesky);
    for (const Vec3d& v : x) EXPECT_TRUE(v.allFinite());
  }
}

// a matrix that is not positive definite (A = -I: b^T P^-1 b < 0) is reported as a breakdown, not as
// a converged solve that left x untouched
TEST(GarmentCg, NegativeDefiniteDiagonalIsNotReportedAsConverged) {
  const Eigen::MatrixXd dense = -Eigen::MatrixXd::Identity(6, 6);
  const BlockMatrix A = blocksOf(dense);
  for (const CgPreconditioner kind : {CgPreconditioner::BlockJacobi, CgPreconditioner::GaussSeidel}) {
    std::vector<Vec3d> b(2, Vec3d(1, 2, 3)), x(2, Vec3d::Zero());
    CgScratch scratch;
    CgOptions opt{1e-10, 100};
    opt.preconditioner = kind;
    const CgResult res = filteredPcg(A, b, std::vector<uint8_t>(2, 0), x, opt, scratch);
    std::vector<Vec3d> ax;
    A.multiply(x, ax);
    const double error = (ax[0] - b[0]).norm() + (ax[1] - b[1]).norm();
    // either it solved the system, or it did not say it did
    EXPECT_TRUE(!res.converged || error < 1e-8) << "converged with |Ax - b| = " << error;
    EXPECT_TRUE(res.breakdown);
  }
}

// stopped by maxIterations: not converged, the iterations and the residual at exit reported; a zero
// right-hand side, or every row constrained, converges at once and leaves x as it was
TEST(GarmentCg, IterationCapAndTrivialSystemsAreReported) {
  std::mt19937 rng(9);
  const int n = 12;
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (int i = 0; i + 1 < n; ++i) {
    const Eigen::Matrix3d b = randomBlock(rng);
    dense.block<3, 3>(3 * i, 3 * i + 3) = b;
    dense.block<3, 3>(3 * i + 3, 3 * i) = b.transpose();
  }
  dense += 4.0 * Eigen::MatrixXd::Identity(3 * n, 3 * n);
  const BlockMatrix A = blocksOf(dense);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3d> b(n), x(n, Vec3d::Zero());
  for (auto& v : b) v = Vec3d(u(rng), u(rng), u(rng));
  CgScratch scratch;
  CgResult res = filteredPcg(A, b, std::vector<uint8_t>(n, 0), x, CgOptions{1e-12, 2}, scratch);
  EXPECT_FALSE(res.converged);
  EXPECT_FALSE(res.breakdown);
  EXPECT_EQ(res.iterations, 2);
  EXPECT_GT(res.residual, 1e-6);
  EXPECT_LT(res.residual, 1.0);  // but two steps did reduce it
  // the same system to the end: the residual reported is below the tolerance
  std::fill(x.begin(), x.end(), Vec3d::Zero());
  res = filteredPcg(A, b, std::vector<uint8_t>(n, 0), x, CgOptions{1e-9, 500}, scratch);
  EXPECT_TRUE(res.converged);
  EXPECT_LE(res.residual, 1e-9);
  EXPECT_GT(res.iterations, 2);

  const std::vector<Vec3d> zero(n, Vec3d::Zero());
  std::vector<Vec3d> still(n, Vec3d::Zero());
  res = filteredPcg(A, zero, std::vector<uint8_t>(n, 0), still, CgOptions{}, scratch);
  EXPECT_TRUE(res.converged);
  EXPECT_EQ(res.iterations, 0);
  EXPECT_EQ(still, zero);
  std::vector<Vec3d> held(n, Vec3d(0.5, -1.0, 2.0));
  const std::vector<Vec3d> before = held;
  for (CgPreconditioner kind : {CgPreconditioner::BlockJacobi, CgPreconditioner::Multigrid,  // no coarse level
                                CgPreconditioner::GaussSeidel}) {
    CgOptions opt;
    opt.preconditioner = kind;
    res = filteredPcg(A, b, std::vector<uint8_t>(n, 1), held, opt, scratch);
    EXPECT_TRUE(res.converged);
    EXPECT_FALSE(res.factorFailed);
    EXPECT_EQ(res.iterations, 0);
    EXPECT_EQ(held, before);
  }
}

// above kParallelGrain rows the loops run in parallel: the solution is bit for bit the same on 1 and 2 threads,
// and it solves the system (a 20000-row block tridiagonal matrix, a few ms a solve)
TEST(GarmentCg, SameSolutionOnOneAndTwoThreadsForALargeSystem) {
  const int n = 20000;
  BlockMatrix A;
  A.rows = n;
  A.rowStart.push_back(0);
  const Eigen::Matrix3d off = (Eigen::Matrix3d() << -1.0, 0.2, 0.0, 0.1, -1.0, 0.3, 0.0, -0.2, -1.0).finished();
  for (int i = 0; i < n; ++i) {
    A.col.push_back(i);
    A.block.push_back(Eigen::Matrix3d::Identity() * (4.5 + 0.5 * std::sin(0.01 * i)));
    if (i > 0) A.col.push_back(i - 1), A.block.push_back(off.transpose());
    if (i + 1 < n) A.col.push_back(i + 1), A.block.push_back(off);
    A.rowStart.push_back(int(A.col.size()));
  }
  std::vector<Vec3d> b(n);
  for (int i = 0; i < n; ++i) b[i] = Vec3d(std::sin(0.3 * i), std::cos(0.7 * i), 1.0);
  std::vector<uint8_t> constrained(n, 0);
  for (int i = 0; i < n; i += 97) constrained[i] = 1;
  const auto solve = [&](int threads) {
    const int old = threadCount();
    setThreadCount(threads);
    std::vector<Vec3d> x(n, Vec3d::Zero());
    CgScratch scratch;
    const CgResult res = filteredPcg(A, b, constrained, x, CgOptions{1e-10, 200}, scratch);
    setThreadCount(old);
    EXPECT_TRUE(res.converged) << threads;
    return x;
  };
  const std::vector<Vec3d> one = solve(1), two = solve(2);
  ASSERT_EQ(one.size(), two.size());
  EXPECT_EQ(std::memcmp(one.data(), two.data(), one.size() * sizeof(Vec3d)), 0);
  // the free rows satisfy A x = b
  std::vector<Vec3d> ax;
  A.multiply(one, ax);
  double worst = 0.0;
  for (int i = 0; i < n; ++i)
    if (!constrained[i]) worst = std::max(worst, (ax[i] - b[i]).norm());
  EXPECT_LT(worst, 1e-7);
  EXPECT_EQ(one[97], Vec3d::Zero());  // constrained rows keep their value
}

// the Cholesky preconditioner is the exact inverse of the filtered matrix: one iteration reaches a
// tolerance block Jacobi needs many for, the constrained rows keep their value, and both give the
// same free rows as a dense solve of the filtered system. The same scratch then takes a matrix of
// another pattern (its factor's pattern is rebuilt) and a copy of it solves too.
TEST(GarmentCg, CholeskyPreconditionerSolvesInOneIteration) {
  const int n = 40;
  const Eigen::MatrixXd dense = randomSpd(n, 3.5, 21);
  const BlockMatrix A = blocksOf(dense);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3d> b(n), start(n, Vec3d::Zero());
  for (auto& v : b) v = Vec3d(u(rng), u(rng), u(rng));
  std::vector<uint8_t> constrained(n, 0);
  constrained[7] = constrained[30] = 1;
  start[7] = Vec3d(0.2, -0.4, 1.0);
  start[30] = Vec3d(-0.5, 0.1, 0.3);
  const auto solve = [&](CgPreconditioner kind, CgScratch& scratch, CgResult& res) {
    std::vector<Vec3d> x = start;
    CgOptions opt{1e-10, 1000};
    opt.preconditioner = kind;
    res = filteredPcg(A, b, constrained, x, opt, scratch);
    return x;
  };
  CgScratch scratch;
  CgResult jacobi, cholesky;
  const std::vector<Vec3d> xj = solve(CgPreconditioner::BlockJacobi, scratch, jacobi);
  const std::vector<Vec3d> xc = solve(CgPreconditioner::Cholesky, scratch, cholesky);
  ASSERT_TRUE(jacobi.converged);
  ASSERT_TRUE(cholesky.converged);
  EXPECT_FALSE(cholesky.factorFailed);
  EXPECT_LE(cholesky.iterations, 1);
  EXPECT_GT(jacobi.iterations, 10) << "a weak case: block Jacobi alone is exact here";
  EXPECT_EQ(xc[7], start[7]);
  EXPECT_EQ(xc[30], start[30]);
  // the dense reference: A_ff x_f = b_f - A_fc x_c
  Eigen::VectorXd xcFixed = Eigen::VectorXd::Zero(3 * n);
  for (int i : {7, 30}) xcFixed.segment<3>(3 * i) = start[i];
  std::vector<int> freeRows;
  for (int i = 0; i < n; ++i)
    if (!constrained[i]) freeRows.push_back(i);
  const int m = int(freeRows.size());
  Eigen::MatrixXd Aff(3 * m, 3 * m);
  Eigen::VectorXd rhs(3 * m);
  const Eigen::VectorXd Axc = dense * xcFixed;
  for (int a = 0; a < m; ++a) {
    rhs.segment<3>(3 * a) = b[freeRows[a]] - Axc.segment<3>(3 * freeRows[a]);
    for (int c = 0; c < m; ++c) Aff.block<3, 3>(3 * a, 3 * c) = dense.block<3, 3>(3 * freeRows[a], 3 * freeRows[c]);
  }
  const Eigen::VectorXd ref = Aff.ldlt().solve(rhs);
  for (int a = 0; a < m; ++a) {
    EXPECT_LT((xc[freeRows[a]] - ref.segment<3>(3 * a)).norm(), 1e-9);
    EXPECT_LT((xj[freeRows[a]] - ref.segment<3>(3 * a)).norm(), 1e-8);
  }
  // another pattern through the same scratch, then a copy of the scratch
  const int n2 = 9;
  const BlockMatrix A2 = blocksOf(randomSpd(n2, 4.0, 8));
  std::vector<Vec3d> b2(n2, Vec3d(1.0, 2.0, -1.0)), x2(n2, Vec3d::Zero()), x3 = x2;
  CgOptions opt{1e-12, 50};
  opt.preconditioner = CgPreconditioner::Cholesky;
  const CgResult r2 = filteredPcg(A2, b2, std::vector<uint8_t>(n2, 0), x2, opt, scratch);
  CgScratch copy = scratch;
  const CgResult r3 = filteredPcg(A2, b2, std::vector<uint8_t>(n2, 0), x3, opt, copy);
  EXPECT_TRUE(r2.converged && r3.converged);
  EXPECT_LE(r2.iterations, 1);
  std::vector<Vec3d> ax;
  A2.multiply(x3, ax);
  for (int i = 0; i < n2; ++i) EXPECT_LT((ax[i] - b2[i]).norm(), 1e-10);
}

// the multigrid keeps its levels' patterns from one setup to the next when A's pattern and the
// aggregates are the same: a scratch that solved another system first (same pattern, other values;
// then other held rows, whose aggregates differ) gives bit for bit what a fresh scratch gives
TEST(GarmentCg, MultigridReusesItsPatternsOnlyWhereTheyHold) {
  const int n = 60;
  const BlockMatrix first = blocksOf(randomSpd(n, 3.5, 31));
  const BlockMatrix second = blocksOf(randomSpd(n, 4.0, 32));
  ASSERT_EQ(first.col, second.col);
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3d> b(n);
  for (auto& v : b) v = Vec3d(u(rng), u(rng), u(rng));
  CgOptions opt{1e-10, 1000};
  opt.preconditioner = CgPreconditioner::Multigrid;
  const auto solve = [&](const BlockMatrix& A, const std::vector<uint8_t>& kind, CgScratch& scratch) {
    std::vector<Vec3d> x(n, Vec3d::Zero());
    const CgResult res = filteredPcg(A, b, kind, x, opt, scratch);
    EXPECT_TRUE(res.converged);
    EXPECT_FALSE(res.factorFailed);
    return x;
  };
  const std::vector<uint8_t> free(n, 0);
  std::vector<uint8_t> held(n, 0);
  held[5] = held[6] = held[40] = 1;  // other aggregates
  CgScratch reused, fresh1, fresh2;
  solve(first, free, reused);
  const std::vector<Vec3d> a = solve(second, free, reused), wantA = solve(second, free, fresh1);
  EXPECT_EQ(std::memcmp(a.data(), wantA.data(), n * sizeof(Vec3d)), 0);
  const std::vector<Vec3d> c = solve(first, held, reused), wantC = solve(first, held, fresh2);
  EXPECT_EQ(std::memcmp(c.data(), wantC.data(), n * sizeof(Vec3d)), 0);
}

}  // namespace
}  // namespace soak
