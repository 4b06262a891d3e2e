// the symmetric Gauss-Seidel preconditioned CG (garment/gauss_seidel_cg.hpp): its colour order, the
// solution of a stiff sheet against a dense solve in fewer iterations than block Jacobi, the same
// answer for any thread count, and the blocks and diagonals it keeps from one solve to the next
#include "garment/block_cg.hpp"
#include "support/block_systems.hpp"

#include <soak/threads.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

namespace soak {
namespace {

// a stiff sheet's implicit system: an n x n grid of unit masses joined along the grid's sides and
// diagonals by springs of stiffness k (h^2 folded in) acting along their direction, with a little
// bending-like stiffness in the other directions: A = I + sum_e k (d d^T + 0.01 I) over each edge's
// rows and columns (+ on the diagonal blocks, - off it). SPD, condition number about k
Eigen::MatrixXd stiffSheet(int n, double k) {
  const int rows = n * n;
  Eigen::MatrixXd dense = Eigen::MatrixXd::Identity(3 * rows, 3 * rows);
  const auto spring = [&](int a, int b, const Vec3d& d) {
    const Eigen::Matrix3d s = k * (d.normalized() * d.normalized().transpose() + 0.01 * Eigen::Matrix3d::Identity());
    dense.block<3, 3>(3 * a, 3 * a) += s;
    dense.block<3, 3>(3 * b, 3 * b) += s;
    dense.block<3, 3>(3 * a, 3 * b) -= s;
    dense.block<3, 3>(3 * b, 3 * a) -= s;
  };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int v = i * n + j;
      if (j + 1 < n) spring(v, v + 1, Vec3d(1, 0, 0.1 * i));
      if (i + 1 < n) spring(v, v + n, Vec3d(0, 1, 0.1 * j));
      if (i + 1 < n && j + 1 < n) spring(v, v + n + 1, Vec3d(1, 1, 0));
    }
  return dense;
}

// every row once in the order; no two rows of a colour in one group share a block; each row's
// off-diagonal blocks split into those of lower and of higher colours, each once
TEST(GaussSeidelCg, TheColourOrderSplitsEveryRowsBlocks) {
  const BlockMatrix A = testing::blocksOf(stiffSheet(24, 10.0));  // 576 rows: three groups
  ColourOrder o;
  ASSERT_TRUE(o.update(A));
  EXPECT_FALSE(o.update(A));  // the same pattern: kept
  ASSERT_EQ(o.numGroups, 3);
  EXPECT_GE(o.numColours, 4);  // a grid with its diagonals holds 4-cliques
  std::vector<int> colour(A.rows, -1), seen(A.rows, 0);
  for (int g = 0; g < o.numGroups; ++g)
    for (int c = 0; c < o.numColours; ++c)
      for (int q = o.begin(g, c); q < o.end(g, c); ++q) {
        const int i = o.row[q];
        EXPECT_EQ(o.position[i], q);
        EXPECT_EQ(i / kGroupRows, g);
        colour[i] = c;
        ++seen[i];
      }
  for (int i = 0; i < A.rows; ++i) ASSERT_EQ(seen[i], 1) << i;
  for (int i = 0; i < A.rows; ++i) {
    const int q = o.position[i];
    std::vector<int> blocks;
    for (int k = o.lowerFirst[q]; k < o.lowerFirst[q] + o.lowerCount[q]; ++k) {
      EXPECT_LT(colour[A.col[o.lower[k]]], colour[i]);
      blocks.push_back(o.lower[k]);
    }
    for (int k = o.upperFirst[q]; k < o.upperFirst[q] + o.upperCount[q]; ++k) {
      EXPECT_GT(colour[A.col[o.upper[k]]], colour[i]);
      blocks.push_back(o.upper[k]);
    }
    std::sort(blocks.begin(), blocks.end());
    std::vector<int> offDiagonal;
    for (int k = A.rowStart[i]; k < A.rowStart[i + 1]; ++k)
      if (A.col[k] != i) offDiagonal.push_back(k);
    EXPECT_EQ(blocks, offDiagonal) << "row " << i;  // so no neighbour has the row's own colour
  }
}

// the stiff sheet with two held rows and a contact row, solved to 1e-10: the dense solution of the
// filtered system, held rows untouched, the contact row's normal component kept, in well under the
// iterations block Jacobi needs (at this stiffness about half)
TEST(GaussSeidelCg, SolvesAStiffSheetInFewerIterationsThanBlockJacobi) {
  const int n = 12, rows = n * n;
  const Eigen::MatrixXd dense = stiffSheet(n, 1000.0);
  const BlockMatrix A = testing::blocksOf(dense);
  std::vector<Vec3d> b(rows), start(rows, Vec3d::Zero()), normal(rows, Vec3d::Zero());
  for (int i = 0; i < rows; ++i) b[i] = Vec3d(0.0, -1.0, 0.2 * std::sin(i));
  std::vector<uint8_t> kind(rows, kFreeRow);
  kind[0] = kind[n - 1] = 1;  // two corners held
  start[n - 1] = Vec3d(0.1, 0.0, 0.0);
  const int contact = rows / 2 + 3;
  kind[contact] = kContactRow;
  normal[contact] = Vec3d(0.0, 0.6, 0.8);
  start[contact] = 0.05 * normal[contact];
  int iterations[2] = {0, 0};
  std::vector<Vec3d> solution[2];
  for (int m = 0; m < 2; ++m) {
    std::vector<Vec3d> x = start;
    CgScratch scratch;
    CgOptions opt{1e-10, 5000};
    opt.preconditioner = m ? CgPreconditioner::GaussSeidel : CgPreconditioner::BlockJacobi;
    const CgResult res = filteredPcg(A, b, kind, x, opt, scratch, normal);
    ASSERT_TRUE(res.converged) << m;
    EXPECT_LE(res.residual, 1e-10);
    iterations[m] = res.iterations;
    solution[m] = x;
  }
  EXPECT_LT(iterations[1], 0.6 * iterations[0]) << iterations[1] << " against " << iterations[0];
  const std::vector<Vec3d>& x = solution[1];
  EXPECT_EQ(x[0], start[0]);
  EXPECT_EQ(x[n - 1], start[n - 1]);
  EXPECT_NEAR(x[contact].dot(normal[contact]), 0.05, 1e-14);
  const std::vector<Vec3d> ref = testing::filteredReference(dense, b, start, kind, normal);
  double worst = 0.0, largest = 0.0;
  for (int i = 0; i < rows; ++i) {
    worst = std::max(worst, (x[i] - ref[i]).norm());
    largest = std::max(largest, ref[i].norm());
  }
  EXPECT_LT(worst, 1e-7 * largest);
}

// above kParallelGrain rows the sweeps run colour by colour in parallel: bit for bit the same solution
// on 1, 2 and 3 threads
TEST(GaussSeidelCg, SameSolutionForAnyThreadCount) {
  const int n = 50, rows = n * n;  // 2,500 rows
  BlockMatrix A;
  {
    // the sheet's pattern without a dense matrix: a 50 x 50 grid, sides and one diagonal
    std::vector<std::vector<std::pair<int, Eigen::Matrix3d>>> row(rows);
    const auto spring = [&](int a, int c, const Vec3d& d) {
      const Eigen::Matrix3d s = 300.0 * (d.normalized() * d.normalized().transpose() + 0.01 * Eigen::Matrix3d::Identity());
      row[a].push_back({c, -s});
      row[c].push_back({a, -s});
      return s;
    };
    std::vector<Eigen::Matrix3d> diag(rows, Eigen::Matrix3d::Identity());
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const int v = i * n + j;
        const auto add = [&](int c, const Vec3d& d) {
          const Eigen::Matrix3d s = spring(v, c, d);
          diag[v] += s;
          diag[c] += s;
        };
        if (j + 1 < n) add(v + 1, Vec3d(1, 0, 0.01 * i));
        if (i + 1 < n) add(v + n, Vec3d(0, 1, 0.01 * j));
        if (i + 1 < n && j + 1 < n) add(v + n + 1, Vec3d(1, 1, 0));
      }
    A.rows = rows;
    A.rowStart.push_back(0);
    for (int v = 0; v < rows; ++v) {
      A.col.push_back(v);
      A.block.push_back(diag[v]);
      std::sort(row[v].begin(), row[v].end(), [](const auto& a, const auto& c) { return a.first < c.first; });
      for (const auto& [c, blk] : row[v]) A.col.push_back(c), A.block.push_back(blk);
      A.rowStart.push_back(int(A.col.size()));
    }
  }
  std::vector<Vec3d> b(rows), normal(rows, Vec3d::Zero());
  for (int i = 0; i < rows; ++i) b[i] = Vec3d(std::sin(0.3 * i), -1.0, std::cos(0.7 * i));
  std::vector<uint8_t> kind(rows, kFreeRow);
  for (int i = 0; i < rows; i += 211) kind[i] = 1;
  for (int i = 50; i < rows; i += 173) {
    kind[i] = kContactRow;
    normal[i] = Vec3d(0.3, 1.0, -0.2).normalized();
  }
  const auto solve = [&](int threads) {
    const int old = threadCount();
    setThreadCount(threads);
    std::vector<Vec3d> x(rows, Vec3d::Zero());
    CgScratch scratch;
    CgOptions opt{1e-9, 2000};
    opt.preconditioner = CgPreconditioner::GaussSeidel;
    const CgResult res = filteredPcg(A, b, kind, x, opt, scratch, normal);
    setThreadCount(old);
    EXPECT_TRUE(res.converged) << threads;
    return x;
  };
  const std::vector<Vec3d> one = solve(1);
  for (int threads : {2, 3}) {
    const std::vector<Vec3d> other = solve(threads);
    EXPECT_EQ(std::memcmp(one.data(), other.data(), one.size() * sizeof(Vec3d)), 0) << threads;
  }
}

// a solve that says the matrix is the last one's (CgOptions::sameMatrix, as the contact rounds do)
// keeps its copy of the blocks and the inverse diagonal of rows free then and now; with other held
// and contact rows it still gives bit for bit what a fresh scratch gives. A solve with new values
// in the same pattern copies them again
TEST(GaussSeidelCg, KeepsOnlyWhatTheSameMatrixAllows) {
  const int n = 10, rows = n * n;
  const BlockMatrix first = testing::blocksOf(stiffSheet(n, 200.0)), second = testing::blocksOf(stiffSheet(n, 50.0));
  ASSERT_EQ(first.col, second.col);
  std::vector<Vec3d> b(rows, Vec3d(0.2, -1.0, 0.1)), normal(rows, Vec3d::Zero());
  std::vector<uint8_t> before(rows, kFreeRow), after(rows, kFreeRow);
  before[5] = 1;
  after[17] = 1;  // a row held now that was free
  after[5] = kContactRow;  // and one held then, on a surface now
  normal[5] = Vec3d(0, 0, 1);
  const auto solve = [&](const BlockMatrix& A, const std::vector<uint8_t>& kind, bool same, CgScratch& scratch) {
    std::vector<Vec3d> x(rows, Vec3d::Zero());
    CgOptions opt{1e-10, 1000};
    opt.preconditioner = CgPreconditioner::GaussSeidel;
    opt.sameMatrix = same;
    EXPECT_TRUE(filteredPcg(A, b, kind, x, opt, scratch, normal).converged);
    return x;
  };
  CgScratch reused, fresh, fresh2;
  solve(first, before, false, reused);
  const std::vector<Vec3d> kept = solve(first, after, true, reused), want = solve(first, after, false, fresh);
  EXPECT_EQ(std::memcmp(kept.data(), want.data(), rows * sizeof(Vec3d)), 0);
  const std::vector<Vec3d> renewed = solve(second, after, false, reused), want2 = solve(second, after, false, fresh2);
  EXPECT_EQ(std::memcmp(renewed.data(), want2.data(), rows * sizeof(Vec3d)), 0);
  EXPECT_NE(renewed, kept);
}

}  // namespace
}  // namespace soak
