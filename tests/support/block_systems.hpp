// small block systems for the tests of the block CG solvers (tests/garment/*cg_test.cpp)
#pragma once
#include "garment/block_matrix.hpp"

#include <Eigen/Dense>

#include <cstdint>
#include <random>
#include <vector>

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

// the dense solution of the filtered system the PCG solves: x = z + T y with T^T A T y = T^T (b - A z),
// T spanning the free rows (kind 0) and the contact rows' tangent planes (kContactRow, unit normal);
// held rows keep z
inline std::vector<Vec3d> filteredReference(const Eigen::MatrixXd& dense, const std::vector<Vec3d>& b,
                                            const std::vector<Vec3d>& z, const std::vector<uint8_t>& kind,
                                            const std::vector<Vec3d>& normal) {
  const int n = int(b.size());
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  int cols = 0;
  for (int i = 0; i < n; ++i) {
    if (kind[i] == kFreeRow) {
      T.block<3, 3>(3 * i, cols) = Eigen::Matrix3d::Identity();
      cols += 3;
    } else if (kind[i] == kContactRow) {
      const Vec3d t1 = normal[i].unitOrthogonal(), t2 = normal[i].cross(t1);
      T.block<3, 1>(3 * i, cols++) = t1;
      T.block<3, 1>(3 * i, cols++) = t2;
    }
  }
  T.conservativeResize(Eigen::NoChange, cols);
  Eigen::VectorXd bz(3 * n), zz(3 * n);
  for (int i = 0; i < n; ++i) {
    bz.segment<3>(3 * i) = b[i];
    zz.segment<3>(3 * i) = z[i];
  }
  const Eigen::VectorXd x = zz + T * (T.transpose() * dense * T).ldlt().solve(T.transpose() * (bz - dense * zz));
  std::vector<Vec3d> out(n);
  for (int i = 0; i < n; ++i) out[i] = x.segment<3>(3 * i);
  return out;
}

}  // namespace soak::testing
