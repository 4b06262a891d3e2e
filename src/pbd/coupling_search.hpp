// The candidate search of the water-cloth coupling (Eq. 21): the walk over the cloth's grid of boxes
// along a water particle's path, and the side a particle came from. Shared by findCouplingCandidates
// (pbd/coupling_search.cpp) and the rigid pass's second search (pbd/coupling.cpp); internal to src/pbd.
#pragma once
#include "pbd/coupling.hpp"

#include "core/kernels.hpp"
#include "core/simd.hpp"

#include <algorithm>
#include <cmath>

namespace soak::coupling {

// how far outside a triangle (in barycentric units) a point still counts as on its face
constexpr float kFaceTolerance = 1e-3f;
// water particles per chunk of the coupling's dynamically scheduled loops
constexpr int64_t kWaterChunk = 256;
// the most sweeps of the rigid pass over a particle's candidates
constexpr int kRigidSweeps = 4;

// barycentric weights of x (a point in the plane) on the plane of triangle (a, b, c); negative outside it
Vec3 planeBarycentric(const Vec3& x, const Vec3& a, const Vec3& b, const Vec3& c);

// Eq. 21's sign for triangle tri: its own start plane where q (starting at xq0) starts over its face,
// else the sheet's side
float candidateSideOf(const Model& model, const Particles& p, const CouplingScratch& s, uint32_t tri, const Vec3& xq0,
                      float sheetSide);

// whether a point p is within r of the segment a -> a + b, from p - a = (px, py, pz), b and 1 / |b|^2
// (0 for a point): the closest point is a + u b, u = clamp((p - a) . b / |b|^2, 0, 1). A template on
// the lane type: the vector walk and the scalar one
template <class F>
inline auto nearSegment(F px, F py, F pz, F bx, F by, F bz, F invLen2, F r) {
  const F u = simd::clamp((px * bx + py * by + pz * bz) * invLen2, F(0.0f), F(1.0f));
  const F dx = px - u * bx, dy = py - u * by, dz = pz - u * bz;
  return dx * dx + dy * dy + dz * dz < r * r;
}

// calls take(j) for every cloth particle j of the grid within min(reachQ, its own reach) of the path
// a -> a + ab (each may come more than once); reach: the largest such distance
template <class Take>
void walkNearPath(const ClothBoxGrid& grid, const Vec3& a, const Vec3& ab, float reachQ, float reach, Take&& take) {
  const Vec3 lo = grid.origin, hi = grid.origin + grid.dims.cast<float>() * grid.cell;
  // locals: take() writes memory, after which the compiler would load the grid's pointers again
  const float* const PX = grid.px.data();
  const float* const PY = grid.py.data();
  const float* const PZ = grid.pz.data();
  const float* const PR = grid.pr.data();
  const uint32_t* const entry = grid.entry.data();
  const uint32_t* const cellStart = grid.cellStart.data();
  const float len2 = ab.squaredNorm();
  const float invLen2 = len2 > 0.0f ? 1.0f / len2 : 0.0f;  // a still particle: its start point
  // the path in pieces no longer than a cell; each piece's box of cells, row by row (one range each)
  const int pieces = std::max(1, static_cast<int>(std::ceil(std::sqrt(len2) / grid.cell)));
  for (int k = 0; k < pieces; ++k) {
    const Vec3 p0 = a + ab * (static_cast<float>(k) / pieces), p1 = a + ab * (static_cast<float>(k + 1) / pieces);
    const Vec3 boxLo = p0.cwiseMin(p1).array() - reach, boxHi = p0.cwiseMax(p1).array() + reach;
    if ((boxHi.array() < lo.array()).any() || (boxLo.array() > hi.array()).any()) continue;  // clear of the sheet
    const Eigen::Vector3i c0 = grid.clampedCell(boxLo), c1 = grid.clampedCell(boxHi);
    for (int cz = c0.z(); cz <= c1.z(); ++cz)
      for (int cy = c0.y(); cy <= c1.y(); ++cy) {
        const uint32_t e0 = cellStart[grid.index(c0.x(), cy, cz)], e1 = cellStart[grid.index(c1.x(), cy, cz) + 1];
        uint32_t e = e0;
#if SOAK_SIMD_WIDE
        // kLanes slots of the row at a time; the few within reach are taken in slot order
        using simd::FloatW;
        const FloatW vax = a.x(), vay = a.y(), vaz = a.z(), vbx = ab.x(), vby = ab.y(), vbz = ab.z();
        const FloatW vinv = invLen2, vreach = reachQ;
        for (; e < e1; e += simd::kLanes) {
          const simd::MaskW lanes = simd::firstLanes(e1 - e);
          const FloatW r = simd::min(vreach, simd::load(PR + e, lanes));
          const simd::MaskW in = lanes & nearSegment(simd::load(PX + e, lanes) - vax, simd::load(PY + e, lanes) - vay,
                                                     simd::load(PZ + e, lanes) - vaz, vbx, vby, vbz, vinv, r);
          for (uint32_t bits = simd::bits(in); bits; bits &= bits - 1) take(entry[e + static_cast<uint32_t>(__builtin_ctz(bits))]);
        }
#endif
        for (; e < e1; ++e)  // one slot at a time
          if (nearSegment(PX[e] - a.x(), PY[e] - a.y(), PZ[e] - a.z(), ab.x(), ab.y(), ab.z(), invLen2, std::min(reachQ, PR[e])))
            take(entry[e]);
      }
  }
}

}  // namespace soak::coupling
