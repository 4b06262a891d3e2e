// sparse symmetric matrices of 3x3 blocks, one block row per cloth vertex (block CSR)
#pragma once
#include <soak/math.hpp>

#include <cstdint>
#include <span>
#include <vector>

namespace soak {

// row i holds blocks [rowStart[i], rowStart[i + 1]) in columns col[k]; its diagonal block comes first
struct BlockMatrix {
  int rows = 0;
  std::vector<int> rowStart;
  std::vector<int> col;
  std::vector<Eigen::Matrix3d> block;

  // (A x)_i, its blocks summed in column order
  Vec3d row(const std::vector<Vec3d>& x, int64_t i) const {
    Vec3d sum = Vec3d::Zero();
    for (int k = rowStart[i]; k < rowStart[i + 1]; ++k) sum += block[k] * x[col[k]];
    return sum;
  }
  // y = A x (gather per row; block_cg.cpp)
  void multiply(const std::vector<Vec3d>& x, std::vector<Vec3d>& y) const;
};

// the filter S_i of row i (Baraff & Witkin's constraint filter), from its kind: kFreeRow: I;
// kContactRow: I - n n^T with n the row's unit contact normal; any other value: 0 (the row is held)
constexpr uint8_t kFreeRow = 0;
constexpr uint8_t kContactRow = 4;  // on a collider, sliding: its normal velocity prescribed
constexpr uint8_t kStickRow = 5;    // on a collider, sticking: held (its whole velocity prescribed)
inline bool isContactRow(uint8_t kind) { return kind == kContactRow || kind == kStickRow; }
inline Vec3d filterRow(uint8_t kind, std::span<const Vec3d> normal, size_t i, const Vec3d& a) {
  if (kind == kFreeRow) return a;
  if (kind == kContactRow) return a - normal[i].dot(a) * normal[i];
  return Vec3d::Zero();
}
inline bool rowHeld(uint8_t kind) { return kind != kFreeRow && kind != kContactRow; }
// S_i as a matrix: I, I - n n^T or 0
inline Eigen::Matrix3d filterMatrix(uint8_t kind, std::span<const Vec3d> normal, size_t i) {
  if (kind == kFreeRow) return Eigen::Matrix3d::Identity();
  if (kind == kContactRow) return Eigen::Matrix3d::Identity() - normal[i] * normal[i].transpose();
  return Eigen::Matrix3d::Zero();
}
// the diagonal block a of row i as the preconditioners take it: a held row's is the identity; a
// contact row's S a S + n n^T tr(a) / 3, whose inverse filtered is that of S a S on the tangent plane
inline Eigen::Matrix3d filteredDiagonal(uint8_t kind, std::span<const Vec3d> normal, size_t i, const Eigen::Matrix3d& a) {
  if (kind == kFreeRow) return a;
  if (kind != kContactRow) return Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d s = filterMatrix(kind, normal, i);
  return s * a * s + (a.trace() / 3.0) * normal[i] * normal[i].transpose();
}

// block k (row i) of the filtered system: S_i A_ik S_j off the diagonal, filteredDiagonal on it
inline Eigen::Matrix3d filteredBlock(const BlockMatrix& A, const std::vector<uint8_t>& kind, std::span<const Vec3d> normal,
                                     int i, int k) {
  const int j = A.col[k];
  if (j == i) return filteredDiagonal(kind[i], normal, i, A.block[k]);
  return filterMatrix(kind[i], normal, i) * A.block[k] * filterMatrix(kind[j], normal, j);
}

}  // namespace soak
