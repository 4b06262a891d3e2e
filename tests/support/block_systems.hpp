// small block systems for the tests of the block CG solvers (tests/garment/*cg_test.cpp)
#pragma once
#include "garment/block_matrix.hpp"

#include <Eigen/Dense>

#include <random>

namespace soak::testing {

// the 3x3 blocks of `dense` (3n x 3n) where it is not zero, diagonal first in each row
inline BlockMatrix blocksOf(const Eigen::MatrixXd& dense) {
  const int n = int(dense.rows() / 3);
  BlockMatrix A;
  A.rows = n;
  A.rowStart.push_back(0);
  for (int i = 0; i < n; ++i) {
    A.col.push_back(i);
    A.block.push_back(dense.block<3, 3>(3 * i, 3 * i));
    for (int j = 0; j < n; ++j)
      if (j != i && dense.block<3, 3>(3 * i, 3 * j).cwiseAbs().maxCoeff() > 0.0) {
        A.col.push_back(j);
        A.block.push_back(dense.block<3, 3>(3 * i, 3 * j));
      }
    A.rowStart.push_back(int(A.col.size()));
  }
  return A;
}

inline Eigen::Matrix3d randomBlock(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Matrix3d b;
  for (int k = 0; k < 9; ++k) b(k / 3, k % 3) = u(rng);
  return b;
}

// a random SPD block tridiagonal matrix of n rows with a coupling of rows 0 and n - 1 (fill for the
// Cholesky factor), diagonal dominance `shift`
inline Eigen::MatrixXd randomSpd(int n, double shift, unsigned seed) {
  std::mt19937 rng(seed);
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (int i = 0; i + 1 < n; ++i) {
    const Eigen::Matrix3d b = randomBlock(rng);
    dense.block<3, 3>(3 * i, 3 * i + 3) = b;
    dense.block<3, 3>(3 * i + 3, 3 * i) = b.transpose();
  }
  const Eigen::Matrix3d c = randomBlock(rng);
  dense.block<3, 3>(0, 3 * n - 3) = c;
  dense.block<3, 3>(3 * n - 3, 0) = c.transpose();
  dense += shift * Eigen::MatrixXd::Identity(3 * n, 3 * n);
  return dense;
}

}  // namespace soak::testing
