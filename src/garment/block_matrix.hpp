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

  // y = A x (gather per row; block_cg.cpp)
  void multiply(const std::vector<Vec3d>& x, std::vector<Vec3d>& y) const;
};

// the filter S_i of row i (Baraff & Witkin's constraint filter), from its kind: kFreeRow: I;
// kContactRow: I - n n^T with n the row's unit contact normal; any other value: 0 (the row is held)
constexpr uint8_t kFreeRow = 0;
constexpr uint8_t kContactRow = 4;
inline Vec3d filterRow(uint8_t kind, std::span<const Vec3d> normal, size_t i, const Vec3d& a) {
  if (kind == kFreeRow) return a;
  if (kind == kContactRow) return a - normal[i].dot(a) * normal[i];
  return Vec3d::Zero();
}
inline bool rowHeld(uint8_t kind) { return kind != kFreeRow && kind != kContactRow; }

}  // namespace soak
