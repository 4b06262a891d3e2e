// The candidate search of the water-cloth coupling (Eq. 21): once a substep, the triangles each water
// particle may meet on its path, and the side of the sheet it came from.
#include "pbd/coupling_search.hpp"

#include "core/parallel.hpp"

#include <limits>
#include <omp.h>

namespace soak {

using namespace coupling;

namespace {

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

// q's signed distance to the start plane of triangle tri when q starts over its face, else +infinity
float overFaceDistance(const Model& model, const Particles& p, const CouplingScratch& s, uint32_t tri, const Vec3& xq0) {
  const float dist = startPlaneDistance(model, p, s, tri, xq0);
  return startsOverFace(model, p, s, tri, xq0, dist) ? dist : std::numeric_limits<float>::infinity();
}

// the triangles' normals at the start of the substep (p.x does not change during the passes) and
// each triangle's longest edge at the predicted positions, squared
void startPlanes(const Model& model, const Particles& p, CouplingScratch& s) {
  const size_t nTri = model.triangles.size();
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
}

// how far from a water particle's path each cloth particle j can be and still have a triangle that
// the passes may find within d of the path (s.vertexReach): d and half of it (the lateral allowance of
// a contact) and a margin of d/2; the farthest a point of a triangle can be from its nearest corner
// (L / sqrt 3 for the longest edge L of j's triangles); and the farthest j or a particle of its 1-ring
// moved in this substep (a triangle that swept past a slow particle ends up beside it). Returns the
// largest, at most the old bound (h_q + h_cloth) / 2; s.clothRadius: the largest cloth radius
float clothReach(const Model& model, const Particles& p, CouplingScratch& s) {
  const int64_t nc = model.numCloth;
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
  return std::min(reachMax, reachCap);
}

// each water particle's candidates: the triangles of the cloth particles within reach of its path
// (walkNearPath), and its nearest cloth particle. Chunks of water particles go to whichever thread is
// free (the water near the sheet is not spread evenly over the indices); each chunk fills its own list
// and the lists are joined in water order, so the candidates do not depend on the thread count. The
// triangles some particle has are marked in s.triangleActive
void collectCandidates(const Model& model, const Particles& p, CouplingScratch& s, float reachMax) {
  const int64_t nc = model.numCloth, nw = static_cast<int64_t>(p.size()) - nc;
  const size_t nTri = model.triangles.size();
  const float hCloth = s.clothRadius;
  const ClothBoxGrid& grid = s.clothGrid;
  s.nearestCloth.resize(static_cast<size_t>(nw));
  const int nThreads = omp_get_max_threads();
  s.seen.resize(static_cast<size_t>(nThreads));
  s.seenCloth.resize(static_cast<size_t>(nThreads));
  const int64_t chunks = (nw + kWaterChunk - 1) / kWaterChunk;
  s.triangleActive.assign(nTri, 0);
  uint8_t* const active = s.triangleActive.data();
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
      const float reachQ = pairRadius(p.radius[q], hCloth), reach = std::min(reachMax, reachQ);
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
}

// water particle w's side (s.particleSide) and its candidates' (s.candidateSide): a face q starts over
// within half the thickness knows its side better than the smoothed normal at the nearest particle (q
// within a millimetre of a tightly curved sheet: the tangent plane there passes on the other side of
// q, and the triangles beside q then pushed it through the face under it). Farther off, the face may
// be the other layer of a fold, whose side is not this layer's
void chooseSides(const Model& model, const Particles& p, CouplingScratch& s, int64_t w) {
  const int64_t nc = model.numCloth;
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
}

}  // namespace

namespace coupling {

// barycentric weights of x (a point in the plane) on the plane of triangle (a, b, c); negative outside it
Vec3 planeBarycentric(const Vec3& x, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 e0 = b - a, e1 = c - a, e2 = x - a;
  const float d00 = e0.dot(e0), d01 = e0.dot(e1), d11 = e1.dot(e1), d20 = e2.dot(e0), d21 = e2.dot(e1);
  const float denom = d00 * d11 - d01 * d01;
  if (denom <= 0.0f) return {-1, -1, -1};
  const float v = (d11 * d20 - d01 * d21) / denom, w = (d00 * d21 - d01 * d20) / denom;
  return {1 - v - w, v, w};
}

// Eq. 21's sign for triangle tri: its own start plane where q starts over its face, else the sheet's side
float candidateSideOf(const Model& model, const Particles& p, const CouplingScratch& s, uint32_t tri, const Vec3& xq0,
                      float sheetSide) {
  const float dist = startPlaneDistance(model, p, s, tri, xq0);
  const float own = dist >= 0.0f ? 1.0f : -1.0f;
  if (own == sheetSide) return own;  // most candidates: both rules agree, no need to know where q projects
  return startsOverFace(model, p, s, tri, xq0, dist) ? own : sheetSide;
}

}  // namespace coupling

void findCouplingCandidates(const Model& model, const Particles& p, CouplingScratch& s) {
  const int64_t nc = model.numCloth;
  const int64_t nw = static_cast<int64_t>(p.size()) - nc;
  s.candidates.clear();
  if (nc == 0 || nw <= 0) {  // no cloth: nothing to hold per water particle
    s.candidateStart.clear();
    return;
  }
  s.candidateStart.assign(static_cast<size_t>(nw) + 1, 0);
  startPlanes(model, p, s);
  const float reachMax = clothReach(model, p, s);
  // the cloth alone at its predicted positions (the solvers have moved it since the neighbour search)
  buildClothBoxGrid(p, s.vertexReach, nc, std::max(reachMax, 1e-4f), s.clothGrid);
  collectCandidates(model, p, s, reachMax);
  // the triangles some particle has as a candidate: the passes need the planes of these only (in
  // Fig. 1 the 2.5k water particles near a 28k-triangle sheet have a few thousand)
  s.activeTriangles.clear();
  for (size_t t = 0; t < s.triangleActive.size(); ++t)
    if (s.triangleActive[t]) s.activeTriangles.push_back(static_cast<uint32_t>(t));
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
  parallelForDynamic(nw, kWaterChunk, [&](int64_t w) { chooseSides(model, p, s, w); });
}

}  // namespace soak
