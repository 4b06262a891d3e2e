// the filtered conjugate gradient of block_cg.hpp preconditioned by symmetric block Gauss-Seidel
// (SSOR with omega = 1) in a multicolour order, applied with Eisenstat's trick (Eisenstat 1981):
// with the filtered matrix split as L + D + U (D its 3x3 diagonal blocks, as block Jacobi takes them;
// L and U the blocks whose column comes earlier or later in the colour order), M = (D + L) D^-1 (D + U)
// and the preconditioned product D (D + L)^-1 A (D + U)^-1 p = D (t + (D + L)^-1 (p - D t)),
// t = (D + U)^-1 p: one backward and one forward sweep, together one pass over the blocks (an
// iteration costs about 1.6 times block Jacobi's on the Fig. 9 shirt, 2 threads), in about half as
// many iterations on stiff cloth. The rows of one colour share no block, so each sweep runs colour by
// colour, a colour's rows in parallel; the colours and the sums' order are fixed, so the result does
// not depend on the thread count. The residual is measured as r^T M^-1 r against b^T M^-1 b
// (CgOptions::tolerance).
#pragma once
#include "garment/block_matrix.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace soak {

struct CgOptions;
struct CgResult;

// the order of a block matrix's rows for the sweeps, and each row's blocks before and after it.
// Rows are coloured so that no two of a colour share a block (greedy, in row order); the order takes
// them group by group (kGroupRows consecutive rows of A), within a group colour by colour. A sweep
// goes colour by colour, each thread through its own groups: a thread reads back mostly what it
// wrote, and a group's rows lie together
constexpr int kGroupRows = 256;
struct ColourOrder {
  int numColours = 0, numGroups = 0;
  std::vector<int> start{0};  // rows of colour c in group g: q in [start[g C + c], start[g C + c + 1]), C colours
  std::vector<int> row;       // the row of A at place q
  std::vector<int> position;  // row i's place: row[position[i]] == i
  // the blocks k (into A.block) of the row at place q whose column has a lower colour:
  // lower[lowerFirst[q] .. lowerFirst[q] + lowerCount[q]); those of a higher colour likewise in upper
  std::vector<int> lower, lowerFirst, lowerCount, upper, upperFirst, upperCount;
  std::vector<int> rowStart, col;  // the pattern these were built for
  // builds the order unless A's pattern is the one it was built for; returns whether it did
  bool update(const BlockMatrix& A);
  int begin(int g, int c) const { return start[static_cast<size_t>(g) * numColours + c]; }
  int end(int g, int c) const { return start[static_cast<size_t>(g) * numColours + c + 1]; }
};

struct GaussSeidelScratch {
  ColourOrder order;
  // the blocks of order.lower and order.upper copied in that order (the sweeps read them in sequence)
  // and their columns; copied again when a solve says the matrix changed (CgOptions::sameMatrix)
  std::vector<Eigen::Matrix3d> lowerBlock, upperBlock;
  std::vector<int> lowerCol, upperCol;
  // per row, in the sweep order: its kind, contact normal and inverse filtered diagonal block
  std::vector<uint8_t> kind;
  std::vector<Vec3d> normal;
  std::vector<Eigen::Matrix3d> diagInv;
  std::vector<Vec3d> t, z, p, r, s, ap, dx;  // the iteration's vectors (gauss_seidel_cg.cpp), dx the step of x
};

// solves the filtered system as filteredPcg does (same arguments; kind per row, normal per contact
// row), from x's free part, with the symmetric Gauss-Seidel preconditioner
CgResult gaussSeidelPcg(const BlockMatrix& A, const std::vector<Vec3d>& b, const std::vector<uint8_t>& kind,
                        std::span<const Vec3d> normal, std::vector<Vec3d>& x, const CgOptions& options,
                        GaussSeidelScratch& w);

}  // namespace soak
