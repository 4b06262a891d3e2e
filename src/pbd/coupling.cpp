#include "pbd/coupling.hpp"

#include "core/parallel.hpp"

#include <algorithm>
#include <limits>
#include "core/simd.hpp"

#include <omp.h>

namespace soak {

namespace {

// closest point of triangle (a, b, c) to p as barycentric weights (Ericson, Real-Time Collision
// Detection, 5.1.5)
Vec3 closestBarycentric(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const float d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0f && d2 <= 0.0f) return {1, 0, 0};
  const Vec3 bp = p - b;
  const float d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0f && d4 <= d3) return {0, 1, 0};
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) {
    const float v = d1 / (d1 - d3);
    return {1 - v, v, 0};
  }
  const Vec3 cp = p - c;
  const float d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0f && d5 <= d6) return {0, 0, 1};
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) {
    const float w = d2 / (d2 - d6);
    return {1 - w, 0, w};
  }
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0.0f && (d4 - d3) >= 0.0f && (d5 - d6) >= 0.0f) {
    const float w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0, 1 - w, w};
  }
  const float denom = 1.0f / (va + vb + vc);
  const float v = vb * denom, w = vc * denom;
  return {1 - v - w, v, w};
}

// whether a point p is within r of the segment a -> a + b, from p - a = (px, py, pz), b and 1 / |b|^2
// (0 for a point): the closest point is a + u b, u = clamp((p - a) . b / |b|^2, 0, 1). A template on
// the lane type: the vector walk and the scalar one
template <class F>
inline auto nearSegment(F px, F py, F pz, F bx, F by, F bz, F invLen2, F r) {
  const F u = simd::clamp((px * bx + py * by + pz * bz) * invLen2, F(0.0f), F(1.0f));
  const F dx = px - u * bx, dy = py - u * by, dz = pz - u * bz;
  return dx * dx + dy * dy + dz * dz < r * r;
}

// how far outside a triangle (in barycentric units) a point still counts as on its face
constexpr float kFaceTolerance = 1e-3f;
// water particles per chunk of the coupling's dynamically scheduled loops
constexpr int64_t kWaterChunk = 256;
// the most sweeps of the rigid pass over a particle's candidates
constexpr int kRigidSweeps = 4;

// barycentric weights of x (a point in the plane) on the plane of triangle (a, b, c); negative outside it
Vec3 planeBarycentric(const Vec3& x, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 e0 = b - a, e1 = c - a, e2 = x - a;
  const float d00 = e0.dot(e0), d01 = e0.dot(e1), d11 = e1.dot(e1), d20 = e2.dot(e0), d21 = e2.dot(e1);
  const float denom = d00 * d11 - d01 * d01;
  if (denom <= 0.0f) return {-1, -1, -1};
  const float v = (d11 * d20 - d01 * d21) / denom, w = (d00 * d21 - d01 * d20) / denom;
  return {1 - v - w, v, w};
}

// the area-weighted normals of cloth particle v's triangles at the start of the substep, summed
Vec3 startVertexNormal(const Model& model, const Particles& p, int v) {
  Vec3 sum = Vec3::Zero();
  for (int k = model.vertexTriangleStart[v]; k < model.vertexTriangleStart[v + 1]; ++k) {
    const auto& f = model.triangles[static_cast<size_t>(model.vertexTriangles[k])];
    sum += (p.x[f[1]] - p.x[f[0]]).cross(p.x[f[2]] - p.x[f[0]]);
  }
  return sum;
}

// the sheet's normal at cloth particle v at the start of the substep: startVertexNormal summed again
// over its 1-ring (not normalised: only its direction is used). Computed where asked, for the nearest
// cloth particle of each water particle with candidates: a few hundred of the sheet's 14.4k particles
// in Fig. 6's later seconds, where the whole field took a fifth of the candidate search
Vec3 sheetNormalAt(const Model& model, const Particles& p, int v) {
  Vec3 sum = startVertexNormal(model, p, v);
  for (int k = model.vertexNeighborStart[v]; k < model.vertexNeighborStart[v + 1]; ++k)
    sum += startVertexNormal(model, p, model.vertexNeighbors[k]);
  return sum;
}

// the cloth particles 0 .. nc at their predicted positions (and their reach) in a dense grid of the given cell size over
// their bounding box; a sheet spread over a large volume gets coarser cells rather than a large table
void buildClothBoxGrid(const Particles& p, const std::vector<float>& reach, int64_t nc, float cell, ClothBoxGrid& g) {
  Vec3 lo = p.xPred[0], hi = p.xPred[0];
  for (int64_t j = 1; j < nc; ++j) {
    lo = lo.cwiseMin(p.xPred[j]);
    hi = hi.cwiseMax(p.xPred[j]);
  }
  const double maxCells = 4.0 * static_cast<double>(nc) + 4096.0;
  if (!lo.allFinite() || !hi.allFinite()) hi = lo = Vec3::Zero();  // a diverged cloth: one cell (the step reports it)
  for (;;) {
    const Vec3 span = (hi - lo) / cell;
    g.dims = {static_cast<int>(span.x()) + 1, static_cast<int>(span.y()) + 1, static_cast<int>(span.z()) + 1};
    if (static_cast<double>(g.dims.x()) * g.dims.y() * g.dims.z() <= maxCells) break;
    cell *= 2.0f;
  }
  g.cell = cell;
  g.origin = lo;
  const size_t cells = static_cast<size_t>(g.dims.x()) * g.dims.y() * g.dims.z();
  g.cellOf.resize(static_cast<size_t>(nc));
  parallelFor(nc, [&](int64_t j) {
    const Eigen::Vector3i c = g.clampedCell(p.xPred[j]);
    g.cellOf[j] = g.index(c.x(), c.y(), c.z());
  });
  // counting sort, ascending particle order inside a cell
  g.cellStart.assign(cells + 1, 0);
  for (int64_t j = 0; j < nc; ++j) ++g.cellStart[g.cellOf[j] + 1];
  for (size_t c = 0; c < cells; ++c) g.cellStart[c + 1] += g.cellStart[c];
  g.entry.resize(static_cast<size_t>(nc));
  g.px.resize(static_cast<size_t>(nc));
  g.py.resize(static_cast<size_t>(nc));
  g.pz.resize(static_cast<size_t>(nc));
  g.pr.resize(static_cast<size_t>(nc));
  for (int64_t j = 0; j < nc; ++j) {
    const uint32_t e = g.cellStart[g.cellOf[j]]++;
    g.entry[e] = static_cast<uint32_t>(j);
    g.px[e] = p.xPred[j].x();
    g.py[e] = p.xPred[j].y();
    g.pz[e] = p.xPred[j].z();
    g.pr[e] = reach[j];
  }
  for (size_t c = cells; c > 0; --c) g.cellStart[c] = g.cellStart[c - 1];
  g.cellStart[0] = 0;
}

// the side of the sheet a water particle starting at xq0 is on: against the smoothed sheet normal at
// its nearest cloth particle (+1 without one)
float sheetSideOf(const Model& model, const Particles& p, int32_t nearest, const Vec3& xq0) {
  return nearest < 0 || (xq0 - p.x[nearest]).dot(sheetNormalAt(model, p, nearest)) >= 0.0f ? 1.0f : -1.0f;
}

// q's signed distance to the start plane of triangle tri
float startPlaneDistance(const Model& model, const Particles& p, const CouplingScratch& s, uint32_t tri, const Vec3& xq0) {
  return (xq0 - p.x[model.triangles[tri][0]]).dot(s.startNormal[tri]);
}

// whether q, at distance dist from tri's start plane, projects onto the triangle's face
bool startsOverFace(const Model& model, const Particles& p, const CouplingScratch& s, uint32_t tri, const Vec3& xq0,
                    float dist) {
  const auto& f = model.triangles[tri];
  const Vec3 over = planeBarycentric(xq0 - dist * s.startNormal[tri], p.x[f[0]], p.x[f[1]], p.x[f[2]]);
  return over.minCoeff() >= -kFaceTolerance;
}

// Eq. 21's sign for triangle tri: its own start plane where q starts over its face, else the sheet's side
float candidateSideOf(const Model& model, const Particles& p, const CouplingScratch& s, uint32_t tri, const Vec3& xq0,
                      float sheetSide) {
  const float dist = startPlaneDistance(model, p, s, tri, xq0);
  const float own = dist >= 0.0f ? 1.0f : -1.0f;
  if (own == sheetSide) return own;  // most candidates: both rules agree, no need to know where q projects
  return startsOverFace(model, p, s, tri, xq0, dist) ? own : sheetSide;
}

// q's signed distance to the start plane of triangle tri when q starts over its face, else +infinity
float overFaceDistance(const Model& model, const Particles& p, const CouplingScratch& s, uint32_t tri, const Vec3& xq0) {
  const float dist = startPlaneDistance(model, p, s, tri, xq0);
  return startsOverFace(model, p, s, tri, xq0, dist) ? dist : std::numeric_limits<float>::infinity();
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

}  // namespace

float couplingConstraint(const Vec3& xq, const Vec3& xa, const Vec3& xb, const Vec3& xc, float side, float thickness,
                         Vec3& normal, Vec3& bary) {
  const Vec3 nrm = (xb - xa).cross(xc - xa);
  const float len = nrm.norm();
  if (len < 1e-12f) {
    normal = Vec3::Zero();
    bary = Vec3::Zero();
    return 0.0f;
  }
  normal = nrm / len;
  bary = closestBarycentric(xq, xa, xb, xc);
  const Vec3 pt = bary.x() * xa + bary.y() * xb + bary.z() * xc;
  return side * (xq - pt).dot(normal) - thickness;
}

void findCouplingCandidates(const Model& model, const Particles& p, CouplingScratch& s) {
  const int64_t nc = model.numCloth;
  const int64_t n = static_cast<int64_t>(p.size());
  const int64_t nw = n - nc;
  s.candidates.clear();
  if (nc == 0 || nw <= 0) {  // no cloth: nothing to hold per water particle
    s.candidateStart.clear();
    return;
  }
  s.candidateStart.assign(static_cast<size_t>(nw) + 1, 0);
  const size_t nTri = model.triangles.size();
  // the triangles' normals at the start of the substep: p.x does not change during the passes
  // and each triangle's longest edge at the predicted positions (squared), for the reach below
  s.startNormal.resize(nTri);
  s.triangleEdge2.resize(nTri);
  parallelFor(static_cast<int64_t>(nTri), [&](int64_t t) {
    const auto& f = model.triangles[t];
    const Vec3 n0 = (p.x[f[1]] - p.x[f[0]]).cross(p.x[f[2]] - p.x[f[0]]);
    const float l0 = n0.norm();
    s.startNormal[t] = l0 > 1e-12f ? Vec3(n0 / l0) : Vec3::Zero();
    s.triangleEdge2[t] = std::max({(p.xPred[f[0]] - p.xPred[f[1]]).squaredNorm(), (p.xPred[f[1]] - p.xPred[f[2]]).squaredNorm(),
                                   (p.xPred[f[2]] - p.xPred[f[0]]).squaredNorm()});
  });
  // how far from a water particle's path each cloth particle j can be and still have a triangle that
  // the passes may find within d of the path: d and half of it (the lateral allowance of a contact)
  // and a margin of d/2; the farthest a point of a triangle can be from its nearest corner (L / sqrt 3
  // for the longest edge L of j's triangles); and the farthest j or a particle of its 1-ring moved in
  // this substep (a triangle that swept past a slow particle ends up beside it). At most the old
  // bound (h_q + h_cloth) / 2
  float hCloth = 0.0f;
  for (int64_t j = 0; j < nc; ++j) hCloth = std::max(hCloth, p.radius[j]);
  s.clothRadius = hCloth;
  s.vertexReach.resize(static_cast<size_t>(nc));
  parallelFor(nc, [&](int64_t j) {
    float shift2 = (p.xPred[j] - p.x[j]).squaredNorm(), edge2 = 0.0f;
    for (int k = model.vertexNeighborStart[j]; k < model.vertexNeighborStart[j + 1]; ++k) {
      const int v = model.vertexNeighbors[k];
      shift2 = std::max(shift2, (p.xPred[v] - p.x[v]).squaredNorm());
    }
    for (int k = model.vertexTriangleStart[j]; k < model.vertexTriangleStart[j + 1]; ++k)
      edge2 = std::max(edge2, s.triangleEdge2[static_cast<size_t>(model.vertexTriangles[k])]);
    const float thickness = model.pieces[clothPiece(p.phase[j])].material.thickness;
    s.vertexReach[j] = 2.0f * thickness + std::sqrt(edge2 / 3.0f) + std::sqrt(shift2);
  });
  const float reachCap = std::max(hCloth, model.water.supportRadius);
  float reachMax = 0.0f;
  for (int64_t j = 0; j < nc; ++j) reachMax = std::max(reachMax, s.vertexReach[j]);
  reachMax = std::min(reachMax, reachCap);
  // the cloth alone at its predicted positions (the solvers have moved it since the neighbour search)
  buildClothBoxGrid(p, s.vertexReach, nc, std::max(reachMax, 1e-4f), s.clothGrid);
  const ClothBoxGrid& grid = s.clothGrid;
  s.nearestCloth.resize(static_cast<size_t>(nw));
  const int nThreads = omp_get_max_threads();
  s.seen.resize(static_cast<size_t>(nThreads));
  s.seenCloth.resize(static_cast<size_t>(nThreads));
  const int64_t chunks = (nw + kWaterChunk - 1) / kWaterChunk;
  s.triangleActive.assign(nTri, 0);
  uint8_t* const active = s.triangleActive.data();
  // chunks of water particles go to whichever thread is free (the water near the sheet is not spread
  // evenly over the indices); each chunk fills its own list and the lists are joined in water order,
  // so the candidates do not depend on the thread count
  struct Marks {
    std::vector<uint32_t>& seen;       // the water particle that last took each triangle
    std::vector<uint32_t>& seenCloth;  // the water particle that last took each cloth particle
  };
  const auto marks = [&] {
    const size_t t = static_cast<size_t>(omp_get_thread_num());
    s.seen[t].assign(nTri, ~0u);
    s.seenCloth[t].assign(static_cast<size_t>(nc), ~0u);
    return Marks{s.seen[t], s.seenCloth[t]};
  };
  const auto fill = [&](Marks& m, int64_t chunk, std::vector<uint32_t>& out) {
    std::vector<uint32_t>& seen = m.seen;
    std::vector<uint32_t>& seenCloth = m.seenCloth;
    const int64_t begin = chunk * kWaterChunk, end = std::min(nw, begin + kWaterChunk);
    for (int64_t w = begin; w < end; ++w) {
      const int64_t q = nc + w;
      const Vec3 a = p.x[q], ab = p.xPred[q] - a;
      const float reachQ = 0.5f * (p.radius[q] + hCloth), reach = std::min(reachMax, reachQ);
      float nearest2 = std::numeric_limits<float>::max();
      int32_t nearest = -1;
      // cloth particle j lies within reach of the path: its triangles are candidates
      const auto take = [&](uint32_t j) {
        if (seenCloth[j] == static_cast<uint32_t>(q)) return;
        seenCloth[j] = static_cast<uint32_t>(q);
        const float d2 = (a - p.x[j]).squaredNorm();  // the sheet side is judged at the start
        if (d2 < nearest2 || (d2 == nearest2 && static_cast<int32_t>(j) < nearest)) nearest2 = d2, nearest = static_cast<int32_t>(j);
        for (int f = model.vertexTriangleStart[j]; f < model.vertexTriangleStart[j + 1]; ++f) {
          const uint32_t tri = static_cast<uint32_t>(model.vertexTriangles[f]);
          if (seen[tri] == static_cast<uint32_t>(q)) continue;
          seen[tri] = static_cast<uint32_t>(q);
          if (s.startNormal[tri].isZero()) continue;  // a degenerate triangle has no side
          out.push_back(tri);
          __atomic_store_n(active + tri, uint8_t{1}, __ATOMIC_RELAXED);  // both threads may mark it
        }
      };
      walkNearPath(grid, a, ab, reachQ, reach, take);
      s.nearestCloth[static_cast<size_t>(w)] = nearest;
      s.candidateStart[static_cast<size_t>(w) + 1] = static_cast<uint32_t>(out.size());  // local until shifted
    }
  };
  const auto size = [&](const std::vector<size_t>& offset) { s.candidates.resize(offset[static_cast<size_t>(chunks)]); };
  const auto place = [&](int64_t chunk) {
    const std::vector<uint32_t>& out = s.chunkCandidates[static_cast<size_t>(chunk)];
    const size_t at = s.chunkOffset[static_cast<size_t>(chunk)];
    std::copy(out.begin(), out.end(), s.candidates.begin() + static_cast<std::ptrdiff_t>(at));
    for (int64_t w = chunk * kWaterChunk, end = std::min(nw, w + kWaterChunk); w < end; ++w)
      s.candidateStart[static_cast<size_t>(w) + 1] += static_cast<uint32_t>(at);
  };
  orderedChunks(chunks, s.chunkCandidates, s.chunkOffset, 0, true, marks, fill, size, place);
  // the triangles some particle has as a candidate (marked as they were found): the passes need the
  // planes of these only (in Fig. 1 the 2.5k water particles near a 28k-triangle sheet have a few thousand)
  s.activeTriangles.clear();
  for (size_t t = 0; t < nTri; ++t)
    if (active[t]) s.activeTriangles.push_back(static_cast<uint32_t>(t));
  // the side each water particle came from (Eq. 21's sign), the same for every pass. A triangle's own
  // plane decides only where q started over its face: the plane of a triangle beside q, on a ridge or
  // fold of a crumpled sheet, can pass on either side of q. Elsewhere q keeps the side of the sheet it
  // is on: its side at the nearest cloth particle against the sheet's normal there, smoothed over two
  // rings so that a small fold (a triangle turned over) does not flip it. The mesh's normals agree
  // across the sheet, so one side holds for every triangle of a layer (docs/models.md on Eq. 21)
  s.candidateSide.resize(s.candidates.size());
  s.particleSide.resize(static_cast<size_t>(nw));
  s.searchedEnd.resize(static_cast<size_t>(nw));
  // dynamic: only the water near the sheet has candidates, and it may sit in one part of the indices
  parallelForDynamic(nw, kWaterChunk, [&](int64_t w) {
    const Vec3 xq0 = p.x[static_cast<size_t>(nc + w)];
    const uint32_t c0 = s.candidateStart[static_cast<size_t>(w)], c1 = s.candidateStart[static_cast<size_t>(w) + 1];
    const float sheetSide = sheetSideOf(model, p, s.nearestCloth[static_cast<size_t>(w)], xq0);
    s.particleSide[static_cast<size_t>(w)] = sheetSide;
    s.searchedEnd[static_cast<size_t>(w)] = p.xPred[static_cast<size_t>(nc + w)];
    bool conflict = false;  // q starts over a face whose plane puts it on the other side
    for (uint32_t c = c0; c < c1; ++c) {
      s.candidateSide[c] = candidateSideOf(model, p, s, s.candidates[c], xq0, sheetSide);
      conflict |= s.candidateSide[c] != sheetSide;
    }
    if (!conflict) return;
    // a face q starts over within half the thickness knows its side better than the smoothed normal at
    // the nearest particle (q within a millimetre of a tightly curved sheet: the tangent plane there
    // passes on the other side of q, and the triangles beside q then pushed it through the face under
    // it). Farther off, the face may be the other layer of a fold, whose side is not this layer's
    float nearest = std::numeric_limits<float>::max(), side = sheetSide;
    for (uint32_t c = c0; c < c1; ++c) {
      const uint32_t tri = s.candidates[c];
      const float dist = overFaceDistance(model, p, s, tri, xq0);
      const float close = 0.5f * model.pieces[clothPiece(p.phase[model.triangles[tri][0]])].material.thickness;
      if (std::fabs(dist) < std::min(nearest, close)) nearest = std::fabs(dist), side = dist >= 0.0f ? 1.0f : -1.0f;
    }
    if (side == sheetSide) return;
    s.particleSide[static_cast<size_t>(w)] = side;
    for (uint32_t c = c0; c < c1; ++c) s.candidateSide[c] = candidateSideOf(model, p, s, s.candidates[c], xq0, side);
  });
}

namespace {

// triangle t's plane at the predicted positions (the cloth does not move during a pass)
TrianglePlane trianglePlane(const Model& model, const Particles& p, const CouplingScratch& s, size_t t) {
  const auto& f = model.triangles[t];
  const Vec3 n1 = (p.xPred[f[1]] - p.xPred[f[0]]).cross(p.xPred[f[2]] - p.xPred[f[0]]);
  const float l1 = n1.norm();
  const Vec3 unit = l1 > 1e-12f ? Vec3(n1 / l1) : Vec3::Zero();
  return {unit, model.pieces[clothPiece(p.phase[f[0]])].material.thickness, p.xPred[f[0]], s.triangleStiffness[t],
          Vec3::Zero(), 0.0f};
}

// how far (m) the passes may carry a water particle from the path its candidates were searched along
// before the rigid pass searches again: a triangle beside the searched path lies within about the
// cloth's reach of it, and this is well inside that
constexpr float kResearchDistance = 0.01f;

// the rigid pass's second search (solveCoupling): the triangles around the cloth particles within reach
// of q's path from its start to xq that are not among its candidates, given q's side, swept with
// visit(tri, plane, side, sweep) as the candidates were
// mark: this thread's marks (one per triangle), stamp: a value no earlier call of the thread left in them
template <class Visit>
void researchAndSweep(const Model& model, const Particles& p, const CouplingScratch& s, int64_t q, const Vec3& xq,
                      std::vector<uint32_t>& mark, uint32_t stamp, Visit&& visit) {
  const int64_t nc = model.numCloth;
  const size_t w = static_cast<size_t>(q - nc);
  const uint32_t c0 = s.candidateStart[w], c1 = s.candidateStart[w + 1];
  const Vec3 a = p.x[q];
  const float reachQ = 0.5f * (p.radius[q] + s.clothRadius);  // as in findCouplingCandidates
  // the candidates and the triangles found so far carry the stamp (a folded sheet gives hundreds of
  // candidates: a linear search of them per triangle was most of Fig. 6(b)'s coupling)
  for (uint32_t c = c0; c < c1; ++c) mark[s.candidates[c]] = stamp;
  std::vector<uint32_t> found;
  const auto take = [&](uint32_t j) {
    for (int f = model.vertexTriangleStart[j]; f < model.vertexTriangleStart[j + 1]; ++f) {
      const uint32_t tri = static_cast<uint32_t>(model.vertexTriangles[f]);
      if (s.startNormal[tri].isZero() || mark[tri] == stamp) continue;
      mark[tri] = stamp;
      found.push_back(tri);
    }
  };
  walkNearPath(s.clothGrid, a, xq - a, reachQ, reachQ, take);
  if (found.empty()) return;
  const float side = s.particleSide[w];
  std::vector<float> sides(found.size());
  std::vector<TrianglePlane> planes(found.size());  // not candidates: the pass computed no plane for most
  for (size_t k = 0; k < found.size(); ++k) {
    sides[k] = candidateSideOf(model, p, s, found[k], a, side);
    planes[k] = trianglePlane(model, p, s, found[k]);
  }
  // sweeps numbered from 1: visit then takes paths through a face only, as in the rigid pass's later sweeps
  for (int sweep = 1; sweep <= kRigidSweeps; ++sweep) {
    bool moved = false;
    for (size_t k = 0; k < found.size(); ++k) moved |= visit(found[k], planes[k], sides[k], sweep);
    if (!moved) break;
  }
}

}  // namespace

uint64_t solveCoupling(const Model& model, Particles& p, CouplingScratch& s, bool rigidCloth) {
  const int64_t nc = model.numCloth;
  const int64_t n = static_cast<int64_t>(p.size());
  if (nc == 0 || n == nc) return 0;
  const int nThreads = omp_get_max_threads();
  const size_t nTri = model.triangles.size();
  const int64_t nw = n - nc, chunks = (nw + kWaterChunk - 1) / kWaterChunk;
  s.chunkContacts.resize(static_cast<size_t>(chunks));  // exactly: the sums below read every chunk's list
  s.researchMark.resize(static_cast<size_t>(nThreads));
  s.researchCount.resize(static_cast<size_t>(nThreads), 0u);
  if (s.triangleStiffness.size() != nTri) s.triangleStiffness.assign(nTri, 1.0f);
  // the rigid pass holds water at dry triangles only (Eq. 22: wet ones let it through): over a sheet
  // wet everywhere (Fig. 6's saturated cloth) it would visit every candidate to move nothing
  if (rigidCloth && std::none_of(s.triangleStiffness.begin(), s.triangleStiffness.end(), [](float k) { return k >= 1.0f; }))
    return 0;
  const int iters = std::max(1, model.solver.couplingIterations);
  // the candidates' planes once per pass, shared by every water particle that tests the triangle
  s.plane.resize(nTri);
  const uint32_t* activeTri = s.activeTriangles.data();
  parallelFor(static_cast<int64_t>(s.activeTriangles.size()), [&](int64_t k) {
    const size_t t = activeTri[k];
    const auto& f = model.triangles[t];
    TrianglePlane& plane = s.plane[t];
    plane = trianglePlane(model, p, s, t);
    const Vec3 c = (p.xPred[f[0]] + p.xPred[f[1]] + p.xPred[f[2]]) / 3.0f;
    plane.centroid = c;
    plane.reach = std::sqrt(std::max({(p.xPred[f[0]] - c).squaredNorm(), (p.xPred[f[1]] - c).squaredNorm(),
                                      (p.xPred[f[2]] - c).squaredNorm()}));
  });

  // chunks of water particles go to whichever thread is free; each chunk records its contacts in its
  // own list, and the lists are summed in water order below, for any thread count
  fillChunks(chunks, s.chunkContacts, nThreads, [] { return 0; }, [&](int, int64_t chunk, std::vector<CouplingContact>& out) {
    const int64_t begin = nc + chunk * kWaterChunk, end = std::min(n, begin + kWaterChunk);
    for (int64_t q = begin; q < end; ++q) {
      const uint32_t c0 = s.candidateStart[static_cast<size_t>(q - nc)], c1 = s.candidateStart[static_cast<size_t>(q - nc) + 1];
      if (c0 == c1) continue;
      const float wq = p.invMass[q];
      const Vec3 xq0 = p.x[q];
      Vec3 dq = Vec3::Zero();
      // Eq. 21 for one candidate; true when it moved q
      const auto visit = [&](uint32_t tri, const TrianglePlane& plane, float side, int sweep) {
        const Vec3& n1 = plane.normal;
        if (n1.isZero()) return false;
        if (rigidCloth && plane.stiffness < 1.0f) return false;  // Eq. 22: wet cloth lets water through
        const float thickness = plane.thickness;
        const Vec3 xq = p.xPred[q] + dq;
        // C = s (x_q - p) . n - d, and (x_q - p) . n is the distance to the plane: most
        // triangles end here, before the closest point is needed
        const float dist = side * (xq - plane.origin).dot(n1);
        // a later sweep only needs q back on its side: a fold narrower than 2d cannot hold it d from both
        const float C = dist - (sweep == 0 ? thickness : 0.25f * thickness);
        if (C >= 0.0f) return false;
        const auto& f = model.triangles[tri];
        Vec3 bary;
        bool contact = false;
        // a path through the face: q started on its side of the plane and is now behind it, and the
        // point where its path met the plane lies on the triangle. Found wherever q ended up, so a
        // particle faster than h per step cannot pass the sheet (a departure from the closest-point
        // test alone, docs/models.md on Eq. 21)
        if (dist < 0.0f) {
          const float before = side * (xq0 - plane.origin).dot(n1);
          if (before > 0.0f) {
            const Vec3 hit = xq0 + (before / (before - dist)) * (xq - xq0);
            bary = planeBarycentric(hit, p.xPred[f[0]], p.xPred[f[1]], p.xPred[f[2]]);
            contact = bary.minCoeff() >= -kFaceTolerance;
            if (contact) bary = bary.cwiseMax(0.0f) / bary.cwiseMax(0.0f).sum();
          }
        }
        if (!contact) {
          if (sweep > 0) return false;
          // Eq. 21 near the face: the closest point must lie within d/2 of q's projection on the plane
          // (below), and every point of the triangle is within reach of its centroid: a cheap test
          // that rejects no contact
          const Vec3 toC = xq - plane.centroid;
          const float lateral = plane.reach + 0.5f * thickness;
          if ((toC - toC.dot(n1) * n1).squaredNorm() > lateral * lateral) return false;
          Vec3 nrm;
          couplingConstraint(xq, p.xPred[f[0]], p.xPred[f[1]], p.xPred[f[2]], side, thickness, nrm, bary);
          // only a contact over the triangle's face counts; far below or beside it is another
          // triangle's business
          const Vec3 pt = bary.x() * p.xPred[f[0]] + bary.y() * p.xPred[f[1]] + bary.z() * p.xPred[f[2]];
          const Vec3 off = xq - pt;
          const float along = std::fabs(off.dot(n1));
          if ((off - off.dot(n1) * n1).squaredNorm() > 0.25f * thickness * thickness) return false;
          if (along > p.radius[q] + (p.xPred[q] - xq0).norm()) return false;
        }
        const float wa = rigidCloth ? 0.0f : p.invMass[f[0]], wb = rigidCloth ? 0.0f : p.invMass[f[1]],
                    wc = rigidCloth ? 0.0f : p.invMass[f[2]];
        const float denom = wq + wa * bary.x() * bary.x() + wb * bary.y() * bary.y() + wc * bary.z() * bary.z();
        if (denom <= 0.0f) return false;
        // kappa^couple through Eq. 5 (1 when dry); the rigid final pass always enforces fully
        const float kappa = rigidCloth ? 1.0f : iterationFactor(plane.stiffness, iters);
        const float dl = -C / denom * kappa;
        const Vec3 g = side * n1;
        dq += wq * dl * g;
        if (!rigidCloth)
          out.push_back({static_cast<uint32_t>(f[0]), static_cast<uint32_t>(f[1]), static_cast<uint32_t>(f[2]),
                         -wa * bary.x() * dl * g, -wb * bary.y() * dl * g, -wc * bary.z() * dl * g});
        return true;
      };
      // the rigid pass sweeps the candidates again, for paths through a face only, while it still
      // moves q: in a crumpled sheet the correction of one triangle can push q through another
      for (int sweep = 0, sweeps = rigidCloth ? kRigidSweeps : 1; sweep < sweeps; ++sweep) {
        bool moved = false;
        for (uint32_t c = c0; c < c1; ++c) moved |= visit(s.candidates[c], s.plane[s.candidates[c]], s.candidateSide[c], sweep);
        if (!moved) break;
      }
      if (rigidCloth) {
        // the passes pushed q along the normal of a triangle its path went through: over a curved sheet
        // that can carry it centimetres past the path its candidates were searched along, beside
        // triangles it never met. Then the triangles near its final path are searched and swept too
        const size_t w = static_cast<size_t>(q - nc);
        const Vec3 xq = p.xPred[q] + dq, a = xq0, ab = s.searchedEnd[w] - xq0;
        const float len2 = ab.squaredNorm();
        const float u = len2 > 0.0f ? std::clamp((xq - a).dot(ab) / len2, 0.0f, 1.0f) : 0.0f;
        if ((xq - (a + u * ab)).squaredNorm() > kResearchDistance * kResearchDistance) {
          const size_t t = static_cast<size_t>(omp_get_thread_num());
          std::vector<uint32_t>& mark = s.researchMark[t];
          if (mark.size() != nTri || s.researchCount[t] == ~0u) mark.assign(nTri, 0), s.researchCount[t] = 0;
          researchAndSweep(model, p, s, q, xq, mark, ++s.researchCount[t], visit);
        }
      }
      p.xPred[q] += dq;  // q's own correction: only this thread writes q
    }
  });
  // cloth corrections summed in water order, averaged per vertex (Jacobi)
  uint64_t contacts = 0;
  for (const auto& list : s.chunkContacts) contacts += list.size();
  if (rigidCloth) return contacts;
  s.clothDelta.assign(static_cast<size_t>(nc), Vec3::Zero());
  s.clothCount.assign(static_cast<size_t>(nc), 0u);
  for (const auto& list : s.chunkContacts)
    for (const CouplingContact& c : list) {
      s.clothDelta[c.a] += c.da;
      s.clothDelta[c.b] += c.db;
      s.clothDelta[c.c] += c.dc;
      ++s.clothCount[c.a];
      ++s.clothCount[c.b];
      ++s.clothCount[c.c];
    }
  parallelFor(nc, [&](int64_t i) {
    if (s.clothCount[i]) p.xPred[i] += s.clothDelta[i] / static_cast<float>(s.clothCount[i]);
  });
  return contacts;
}

}  // namespace soak
