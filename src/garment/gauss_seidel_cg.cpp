// symmetric block Gauss-Seidel PCG with Eisenstat's trick (gauss_seidel_cg.hpp)
#include "garment/gauss_seidel_cg.hpp"

#include "core/parallel.hpp"
#include "garment/block_cg.hpp"

#include <algorithm>
#include <cmath>

#include <omp.h>

namespace soak {

bool ColourOrder::update(const BlockMatrix& A) {
  if (rowStart == A.rowStart && col == A.col) return false;
  rowStart = A.rowStart;
  col = A.col;
  const int n = A.rows;
  // greedy colouring in row order, each row the lowest colour no earlier neighbour has (a
  // smallest-last order takes 10 colours instead of 12 on the Fig. 9 shirt, but the sweeps in it
  // need more iterations: 330 against 240 a step)
  std::vector<int> colour(static_cast<size_t>(n), -1);
  std::vector<int> seen;  // seen[c] == i: colour c is taken by a neighbour of row i
  int colours = 0;
  for (int i = 0; i < n; ++i) {
    for (int k = A.rowStart[i]; k < A.rowStart[i + 1]; ++k)
      if (const int c = colour[A.col[k]]; c >= 0) seen[c] = i;
    int c = 0;
    while (c < colours && seen[c] == i) ++c;
    if (c == colours) {
      ++colours;
      seen.push_back(-1);
    }
    colour[i] = c;
  }
  // the order: group by group (kGroupRows rows of A each), in a group colour by colour, ascending
  numColours = colours;
  numGroups = (n + kGroupRows - 1) / kGroupRows;
  start.assign(static_cast<size_t>(numGroups) * colours + 1, 0);
  for (int i = 0; i < n; ++i) ++start[(i / kGroupRows) * colours + colour[i] + 1];
  for (size_t s = 1; s < start.size(); ++s) start[s] += start[s - 1];
  row.resize(static_cast<size_t>(n));
  position.resize(static_cast<size_t>(n));
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (int i = 0; i < n; ++i) {
    position[i] = fill[(i / kGroupRows) * colours + colour[i]]++;
    row[position[i]] = i;
  }
  // each row's blocks of lower colours, laid out in the forward sweep's order (colour by colour, in a
  // colour group by group, up the places), and those of higher colours in the backward sweep's
  // (colours downwards, groups upwards, places downwards): each sweep reads its blocks in sequence
  lowerFirst.assign(static_cast<size_t>(n), 0);
  lowerCount.assign(static_cast<size_t>(n), 0);
  upperFirst.assign(static_cast<size_t>(n), 0);
  upperCount.assign(static_cast<size_t>(n), 0);
  lower.clear();
  upper.clear();
  const auto take = [&](int q, bool below, std::vector<int>& list, std::vector<int>& first, std::vector<int>& count) {
    const int i = row[q];
    first[q] = static_cast<int>(list.size());
    for (int k = A.rowStart[i]; k < A.rowStart[i + 1]; ++k)
      if (const int j = A.col[k]; below ? colour[j] < colour[i] : colour[j] > colour[i]) list.push_back(k);
    count[q] = static_cast<int>(list.size()) - first[q];
  };
  for (int c = 0; c < colours; ++c)
    for (int g = 0; g < numGroups; ++g)
      for (int q = begin(g, c); q < end(g, c); ++q) take(q, true, lower, lowerFirst, lowerCount);
  for (int c = colours - 1; c >= 0; --c)
    for (int g = 0; g < numGroups; ++g)
      for (int q = end(g, c) - 1; q >= begin(g, c); --q) take(q, false, upper, upperFirst, upperCount);
  return true;
}

namespace {

// sum of block[k] v[col[k]] over k < count
Vec3d blockSum(const Eigen::Matrix3d* __restrict block, const int* __restrict col, int count, const Vec3d* __restrict v) {
  Vec3d sum = Vec3d::Zero();
  for (int k = 0; k < count; ++k) sum += block[k] * v[col[k]];
  return sum;
}

// the solve in the sweep order's numbering (q; row o.row[q] of A): every per-row array below is in
// that order, the blocks' columns renumbered alike. Inside the solve's parallel region each thread
// takes the groups [g0, g1): in every colour of a sweep, and in the passes over the rows
struct Sweeps {
  const ColourOrder& o;
  GaussSeidelScratch& w;
  int g0 = 0, g1 = 0;

  Vec3d filter(int q, const Vec3d& a) const { return filterRow(w.kind[q], w.normal, static_cast<size_t>(q), a); }
  // S_q sum over row q's blocks [first[q], first[q] + count[q]) (v filtered)
  Vec3d offDiagonal(int q, const std::vector<int>& first, const std::vector<int>& count,
                    const std::vector<Eigen::Matrix3d>& block, const std::vector<int>& col, const std::vector<Vec3d>& v) const {
    return filter(q, blockSum(block.data() + first[q], col.data() + first[q], count[q], v.data()));
  }
  // out = (D + L)^-1 rhs colour by colour upwards, after(q, sigma) for each row with sigma = S_q L_q out
  // (so D_q out_q = rhs_q - sigma). No barrier after the last colour: the next pass reads only its
  // own rows before its own barrier (sumOver)
  template <class Rhs, class After>
  void forward(Rhs&& rhs, std::vector<Vec3d>& out, After&& after) const {
    for (int c = 0; c < o.numColours; ++c) {
      for (int g = g0; g < g1; ++g)
        for (int q = o.begin(g, c); q < o.end(g, c); ++q) {
          const Vec3d sigma = offDiagonal(q, o.lowerFirst, o.lowerCount, w.lowerBlock, w.lowerCol, out);
          out[q] = rowHeld(w.kind[q]) ? Vec3d::Zero() : Vec3d(w.diagInv[q] * (rhs(q) - sigma));
          after(q, sigma);
        }
      if (c + 1 < o.numColours) {
#pragma omp barrier
      }
    }
  }
  // out = (D + U)^-1 rhs colour by colour downwards; before(q) and after(q, sigma) around each row,
  // sigma = S_q U_q out. No barrier after colour 0: a forward sweep follows, whose colour 0 reads only
  // its own rows
  template <class Rhs, class Before, class After>
  void backward(Rhs&& rhs, std::vector<Vec3d>& out, Before&& before, After&& after) const {
    for (int c = o.numColours - 1; c >= 0; --c) {
      for (int g = g0; g < g1; ++g)
        for (int q = o.end(g, c) - 1; q >= o.begin(g, c); --q) {
          before(q);
          const Vec3d sigma = offDiagonal(q, o.upperFirst, o.upperCount, w.upperBlock, w.upperCol, out);
          out[q] = rowHeld(w.kind[q]) ? Vec3d::Zero() : Vec3d(w.diagInv[q] * (rhs(q) - sigma));
          after(q, sigma);
        }
      if (c > 0) {
#pragma omp barrier
      }
    }
  }
  // f(q) for each of the thread's rows; returns the sum of f over all rows: per group in place
  // order, the groups' sums in group order (the same for any thread count), on every thread
  template <class F>
  double sumOver(F&& f, std::vector<double>& partial) const {
    for (int g = g0; g < g1; ++g) {
      double s = 0.0;
      for (int q = o.begin(g, 0); q < o.begin(g + 1, 0); ++q) s += f(q);
      partial[g] = s;
    }
#pragma omp barrier
    double s = 0.0;
    for (double t : partial) s += t;
    return s;
  }
};

// the blocks of `list` and their renumbered columns, in the list's order
void copyBlocks(const BlockMatrix& A, const ColourOrder& o, const std::vector<int>& list,
                std::vector<Eigen::Matrix3d>& block, std::vector<int>& col) {
  block.resize(list.size());
  col.resize(list.size());
  parallelFor(static_cast<int64_t>(list.size()), [&](int64_t k) {
    block[k] = A.block[list[k]];
    col[k] = o.position[A.col[list[k]]];
  });
}

// the per-row data in the colour order: kinds, normals, the inverse filtered diagonal blocks (kept
// from the last solve for a free row that was free then too, when the matrix is the same),
// r = filter(b - A x) and filter(b) (into w.t)
void gatherRows(const BlockMatrix& A, const std::vector<Vec3d>& b, const std::vector<uint8_t>& kind,
                std::span<const Vec3d> normal, const std::vector<Vec3d>& x, bool sameMatrix, GaussSeidelScratch& w) {
  const ColourOrder& o = w.order;
  parallelFor(A.rows, [&](int64_t q) {
    const int i = o.row[q];
    const bool keep = sameMatrix && kind[i] == kFreeRow && w.kind[q] == kFreeRow;
    w.kind[q] = kind[i];
    w.normal[q] = kind[i] == kContactRow ? normal[i] : Vec3d::Zero();
    if (!keep) {
      bool ok = false;
      double det = 0.0;
      filteredDiagonal(w.kind[q], w.normal, q, A.block[A.rowStart[i]]).computeInverseAndDetWithCheck(w.diagInv[q], det, ok, 1e-300);
      if (!ok) w.diagInv[q] = Eigen::Matrix3d::Identity();  // as block Jacobi (block_cg.cpp)
    }
    w.r[q] = filterRow(w.kind[q], w.normal, q, b[i] - A.row(x, i));
    w.t[q] = filterRow(w.kind[q], w.normal, q, b[i]);
  });
}

}  // namespace

CgResult gaussSeidelPcg(const BlockMatrix& A, const std::vector<Vec3d>& b, const std::vector<uint8_t>& kind,
                        std::span<const Vec3d> normal, std::vector<Vec3d>& x, const CgOptions& options,
                        GaussSeidelScratch& w) {
  const int n = A.rows;
  const ColourOrder& o = w.order;
  const bool newOrder = w.order.update(A);
  const bool sameMatrix = options.sameMatrix && !newOrder && w.kind.size() == static_cast<size_t>(n);
  if (!sameMatrix) {
    copyBlocks(A, o, o.lower, w.lowerBlock, w.lowerCol);
    copyBlocks(A, o, o.upper, w.upperBlock, w.upperCol);
  }
  for (auto* v : {&w.t, &w.z, &w.r, &w.s, &w.ap, &w.normal}) v->resize(static_cast<size_t>(n));  // written before read
  w.p.assign(static_cast<size_t>(n), Vec3d::Zero());  // the first direction is r^ + 0 p
  w.dx.assign(static_cast<size_t>(n), Vec3d::Zero());
  w.kind.resize(static_cast<size_t>(n));
  w.diagInv.resize(static_cast<size_t>(n));
  gatherRows(A, b, kind, normal, x, sameMatrix, w);
  std::vector<double> partialA(static_cast<size_t>(o.numGroups)), partialB(static_cast<size_t>(o.numGroups));
  const double tol2 = options.tolerance * options.tolerance;
  CgResult result;
  double delta0 = 0.0, gamma = 0.0;
#pragma omp parallel if (n >= kParallelGrain)
  {
    const int threads = omp_get_num_threads(), thread = omp_get_thread_num();
    const Sweeps sw{o, w, o.numGroups * thread / threads, o.numGroups * (thread + 1) / threads};
    // b^T M^-1 b = u^T D u with u = (D + L)^-1 filter(b) (filter(b) in w.t, D u = filter(b) - L u in
    // w.ap): the scale of the residual
    sw.forward([&](int q) { return w.t[q]; }, w.z, [&](int q, const Vec3d& sigma) { w.ap[q] = w.t[q] - sigma; });
    const double d0 = sw.sumOver([&](int q) { return w.z[q].dot(w.ap[q]); }, partialA);
    // the transformed residual r^ = D (D + L)^-1 r = r - L (D + L)^-1 r (in w.r) and s = D^-1 r^ =
    // (D + L)^-1 r (in w.s); r^T D^-1 r^ is r^T M^-1 r
    sw.forward([&](int q) { return w.r[q]; }, w.s, [&](int q, const Vec3d& sigma) { w.r[q] -= sigma; });
    double g = sw.sumOver([&](int q) { return w.s[q].dot(w.r[q]); }, partialB);
    const double scale = d0 > 0.0 ? d0 : g;
    double beta = 0.0;
    int its = 0;
    bool broke = !(g >= 0.0);  // r^T M^-1 r < 0: M (the matrix's diagonal blocks) is not positive definite
    while (!broke && g > tol2 * scale && its < options.maxIterations) {
      // A^ p = D (t + z) with t = (D + U)^-1 p, p = r^ + beta p, and z = (D + L)^-1 (p - D t); the sweeps'
      // sums give the products with D: D t = p - U t, D z = U t - L z, so D (t + z) = p - L z
      sw.backward([&](int q) { return w.p[q]; }, w.t, [&](int q) { w.p[q] = w.r[q] + beta * w.p[q]; },
                  [&](int q, const Vec3d& sigma) { w.z[q] = sigma; });
      sw.forward([&](int q) { return w.z[q]; }, w.z, [&](int q, const Vec3d& sigma) { w.ap[q] = w.p[q] - sigma; });
      const double pu = sw.sumOver([&](int q) { return w.p[q].dot(w.t[q] + w.z[q]); }, partialA);
      if (!(pu > 0.0)) {
        broke = true;
        break;
      }
      const double alpha = g / pu;
      const double next = sw.sumOver([&](int q) {
        w.dx[q] += alpha * w.t[q];  // x = (D + U)^-1 y: its step is alpha t
        w.r[q] -= alpha * w.ap[q];
        w.s[q] -= alpha * (w.t[q] + w.z[q]);  // s = D^-1 r^
        return w.r[q].dot(w.s[q]);
      }, partialB);
      beta = next / g;
      g = next;
      ++its;
    }
    for (int q = o.begin(sw.g0, 0); q < o.begin(sw.g1, 0); ++q) x[o.row[q]] += w.dx[q];
#pragma omp single
    {
      delta0 = scale;
      gamma = g;
      result.iterations = its;
      result.breakdown = broke;
    }
  }
  result.residual = delta0 > 0.0 ? std::sqrt(std::max(gamma, 0.0) / delta0) : 0.0;
  result.converged = !result.breakdown && gamma <= tol2 * delta0;
  return result;
}

}  // namespace soak
