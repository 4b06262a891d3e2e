// sparse symmetric matrices of 3x3 blocks, one block row per cloth vertex (block CSR)
#pragma once
#include <soak/math.hpp>

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

}  // namespace soak
