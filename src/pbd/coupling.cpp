// the water-cloth coupling constraint, Eq. 21-22 of Shao et al. 2017, solved over each water
// particle's candidate triangles (pbd/coupling_search.cpp)
#include "pbd/coupling.hpp"

#include "pbd/coupling_search.hpp"

#include "core/friction.hpp"
#include "core/parallel.hpp"

#include <algorithm>
#include <omp.h>

namespace soak {

using namespace coupling;

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
  const float reachQ = pairRadius(p.radius[q], s.clothRadius);  // as in findCouplingCandidates
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

namespace {

// the candidates' planes once per pass, shared by every water particle that tests the triangle
void candidatePlanes(const Model& model, const Particles& p, CouplingScratch& s) {
  s.plane.resize(model.triangles.size());
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
}

// Eq. 21 between water particle q and one triangle after another in a pass: q's correction builds up
// in dq (applied when its candidates are done), the cloth's share goes to `out`
struct ParticlePass {
  const Model& model;
  const Particles& p;
  bool rigidCloth;
  int iterations;  // the coupling's iterations (Eq. 5)
  int64_t q;
  float wq;        // q's inverse mass
  Vec3 xq0;        // q at the start of the substep
  std::vector<CouplingContact>& out;
  Vec3 dq = Vec3::Zero();

  // Eq. 21 for one candidate; true when it moved q
  bool operator()(uint32_t tri, const TrianglePlane& plane, float side, int sweep) {
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
    Vec3 bary;
    if (!throughFace(tri, plane, side, xq, dist, bary) && (sweep > 0 || !nearFace(tri, plane, side, xq, bary)))
      return false;
    return push(tri, plane, side, C, bary);
  }

  // a path through the face: q started on its side of the plane and is now behind it, and the point
  // where its path met the plane lies on the triangle (its weights to bary). Found wherever q ended up,
  // so a particle faster than h per step cannot pass the sheet (a departure from the closest-point test
  // alone, docs/models.md on Eq. 21)
  bool throughFace(uint32_t tri, const TrianglePlane& plane, float side, const Vec3& xq, float dist, Vec3& bary) const {
    if (dist >= 0.0f) return false;
    const float before = side * (xq0 - plane.origin).dot(plane.normal);
    if (before <= 0.0f) return false;
    const auto& f = model.triangles[tri];
    const Vec3 hit = xq0 + (before / (before - dist)) * (xq - xq0);
    bary = planeBarycentric(hit, p.xPred[f[0]], p.xPred[f[1]], p.xPred[f[2]]);
    if (bary.minCoeff() < -kFaceTolerance) return false;
    bary = bary.cwiseMax(0.0f) / bary.cwiseMax(0.0f).sum();
    return true;
  }

  // Eq. 21 near the face: the closest point (its weights to bary) must lie within d/2 of q's projection
  // on the plane, and q within its radius and the distance it moved of the plane
  bool nearFace(uint32_t tri, const TrianglePlane& plane, float side, const Vec3& xq, Vec3& bary) const {
    const Vec3& n1 = plane.normal;
    const float thickness = plane.thickness;
    // every point of the triangle is within reach of its centroid: a cheap test that rejects no contact
    const Vec3 toC = xq - plane.centroid;
    const float lateral = plane.reach + 0.5f * thickness;
    if ((toC - toC.dot(n1) * n1).squaredNorm() > lateral * lateral) return false;
    const auto& f = model.triangles[tri];
    Vec3 nrm;
    couplingConstraint(xq, p.xPred[f[0]], p.xPred[f[1]], p.xPred[f[2]], side, thickness, nrm, bary);
    // only a contact over the triangle's face counts; far below or beside it is another triangle's business
    const Vec3 pt = bary.x() * p.xPred[f[0]] + bary.y() * p.xPred[f[1]] + bary.z() * p.xPred[f[2]];
    const Vec3 off = xq - pt;
    const float along = std::fabs(off.dot(n1));
    if ((off - off.dot(n1) * n1).squaredNorm() > 0.25f * thickness * thickness) return false;
    return !(along > p.radius[q] + (p.xPred[q] - xq0).norm());
  }

  // the projection of C < 0 (Eq. 1-4, mass weighted; the cloth fixed in the rigid pass), stiffness
  // kappa^couple through Eq. 5; false when nothing can move
  bool push(uint32_t tri, const TrianglePlane& plane, float side, float C, const Vec3& bary) {
    const auto& f = model.triangles[tri];
    const float wa = rigidCloth ? 0.0f : p.invMass[f[0]], wb = rigidCloth ? 0.0f : p.invMass[f[1]],
                wc = rigidCloth ? 0.0f : p.invMass[f[2]];
    const float denom = wq + wa * bary.x() * bary.x() + wb * bary.y() * bary.y() + wc * bary.z() * bary.z();
    if (denom <= 0.0f) return false;
    // kappa^couple through Eq. 5 (1 when dry); the rigid final pass always enforces fully
    const float kappa = rigidCloth ? 1.0f : iterationFactor(plane.stiffness, iterations);
    const float dl = -C / denom * kappa;
    const Vec3 g = side * plane.normal;
    // Coulomb friction of the contact (core/friction.hpp): the pair's tangential slip over the substep,
    // limited by the normal push denom * dl, shared by the inverse masses as the push is
    const float mu = model.water.clothFriction;
    float df = 0.0f;
    Vec3 slipDir = Vec3::Zero();
    if (mu > 0.0f) {
      const Vec3 pointMove = bary.x() * (p.xPred[f[0]] - p.x[f[0]]) + bary.y() * (p.xPred[f[1]] - p.x[f[1]]) +
                             bary.z() * (p.xPred[f[2]] - p.x[f[2]]);
      const Vec3 slip = (p.xPred[q] + dq + wq * dl * g - xq0) - pointMove;
      const Vec3 tangential = slip - coulombFriction(slip, g, mu, denom * dl);
      const float len = tangential.norm();
      if (len > 0.0f) slipDir = tangential / len, df = -len / denom;
    }
    dq += wq * (dl * g + df * slipDir);
    if (!rigidCloth) {
      const Vec3 cloth = dl * g + df * slipDir;
      out.push_back({static_cast<uint32_t>(f[0]), static_cast<uint32_t>(f[1]), static_cast<uint32_t>(f[2]),
                     -wa * bary.x() * cloth, -wb * bary.y() * cloth, -wc * bary.z() * cloth});
    }
    return true;
  }
};

// the passes pushed q along the normal of a triangle its path went through: over a curved sheet that
// can carry it centimetres past the path its candidates were searched along, beside triangles it never
// met. Then the triangles near its final path are searched and swept too (the rigid pass only)
void researchIfCarried(const Model& model, const Particles& p, CouplingScratch& s, ParticlePass& pass) {
  const size_t w = static_cast<size_t>(pass.q - model.numCloth);
  const Vec3 xq = p.xPred[pass.q] + pass.dq, a = pass.xq0, ab = s.searchedEnd[w] - pass.xq0;
  const float len2 = ab.squaredNorm();
  const float u = len2 > 0.0f ? std::clamp((xq - a).dot(ab) / len2, 0.0f, 1.0f) : 0.0f;
  if ((xq - (a + u * ab)).squaredNorm() <= kResearchDistance * kResearchDistance) return;
  const size_t nTri = model.triangles.size(), t = static_cast<size_t>(omp_get_thread_num());
  std::vector<uint32_t>& mark = s.researchMark[t];
  if (mark.size() != nTri || s.researchCount[t] == ~0u) mark.assign(nTri, 0), s.researchCount[t] = 0;
  researchAndSweep(model, p, s, pass.q, xq, mark, ++s.researchCount[t], pass);
}

// Eq. 21 between water particle q and its candidates; q's correction applied, the cloth's to `out`
void coupleParticle(const Model& model, Particles& p, CouplingScratch& s, bool rigidCloth, int iterations, int64_t q,
                    std::vector<CouplingContact>& out) {
  const size_t w = static_cast<size_t>(q - model.numCloth);
  const uint32_t c0 = s.candidateStart[w], c1 = s.candidateStart[w + 1];
  if (c0 == c1) return;
  ParticlePass pass{model, p, rigidCloth, iterations, q, p.invMass[q], p.x[q], out};
  // the rigid pass sweeps the candidates again, for paths through a face only, while it still
  // moves q: in a crumpled sheet the correction of one triangle can push q through another
  for (int sweep = 0, sweeps = rigidCloth ? kRigidSweeps : 1; sweep < sweeps; ++sweep) {
    bool moved = false;
    for (uint32_t c = c0; c < c1; ++c) moved |= pass(s.candidates[c], s.plane[s.candidates[c]], s.candidateSide[c], sweep);
    if (!moved) break;
  }
  if (rigidCloth) researchIfCarried(model, p, s, pass);
  p.xPred[q] += pass.dq;  // q's own correction: only this thread writes q
}

// the cloth's corrections summed in water order, averaged per vertex (Jacobi)
void applyClothCorrections(int64_t nc, Particles& p, CouplingScratch& s) {
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
  const int iterations = std::max(1, model.solver.couplingIterations);
  candidatePlanes(model, p, s);
  // chunks of water particles go to whichever thread is free; each chunk records its contacts in its
  // own list, and the lists are summed in water order below, for any thread count
  fillChunks(chunks, s.chunkContacts, nThreads, [] { return 0; }, [&](int, int64_t chunk, std::vector<CouplingContact>& out) {
    for (int64_t q = nc + chunk * kWaterChunk, end = std::min(n, q + kWaterChunk); q < end; ++q)
      coupleParticle(model, p, s, rigidCloth, iterations, q, out);
  });
  uint64_t contacts = 0;
  for (const auto& list : s.chunkContacts) contacts += list.size();
  if (!rigidCloth) applyClothCorrections(nc, p, s);
  return contacts;
}

}  // namespace soak
