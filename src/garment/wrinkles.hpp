// wrinkle disturbances of Chen, Magnenat-Thalmann, Allen 2012 (section 3.5, imperfection
// sensitivity): in each subdomain of the garment, the most compressed stretch spring marks where a
// buckle wants to start; its vertex A is given a temporary position constraint at a point where
// three of its springs are back at rest length (the intersection of three spheres, Eq. 25), chosen
// by collision, distance and convexity (Eq. 26). The implicit solver enforces the constraint as
// Baraff & Witkin 1998 do, by filtering (implicit.hpp).
#pragma once
#include <soak/model.hpp>
#include <soak/state.hpp>

#include <soak/garment_params.hpp>

#include "garment/springs.hpp"
#include "world/colliders.hpp"

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace soak {

// a vertex that must reach `target` at the end of the next step (vertex local to the piece)
struct PositionConstraint {
  int vertex = 0;
  Vec3 target{0, 0, 0};  // m, world
};

// Eq. 25: the points at distance r1, r2, r3 from c1, c2, c3 (trilateration). count is 0, 1 or 2;
// one point is reported when the two would be closer than 2 tolerance (m), or when the spheres miss
// by less than about tolerance in radius. degenerate is set (and count 0) when the centres are
// collinear or coincide.
struct SphereIntersection {
  int count = 0;
  bool degenerate = false;
  std::array<Vec3, 2> point{Vec3::Zero(), Vec3::Zero()};  // point[0] on the side of (c2 - c1) x (c3 - c1)
};
SphereIntersection intersectThreeSpheres(const Vec3& c1, float r1, const Vec3& c2, float r2, const Vec3& c3, float r3,
                                         float tolerance);

// Eq. 26: k = 2 / (|v1| + |v2|) acos(v1.v2 / (|v1| |v2|)) with v1 = B - A', v2 = A' - D: the turning
// angle of the path D -> A' -> B per unit length (1/m)
float disturbanceCurvature(const Vec3& candidate, const Vec3& b, const Vec3& d);

// steps 2-6 of section 3.5.2: which of the intersection points becomes the target, or -1 when none
// is usable. collides[k]: candidate k is inside a collider. tieDistance (m): |AA1| and |AA2| closer
// than this are equal; then the larger curvature (Eq. 26) wins; on a tie of that too, coin (0 or 1)
// decides.
int chooseDisturbance(const Vec3& a, const SphereIntersection& hits, const std::array<bool, 2>& collides,
                      const Vec3& b, const Vec3& d, float tieDistance, int coin);

// the fraction of the way to A' a vertex of this saturation (in [0, 1]) is moved: dryStrength for a
// dry vertex, strength for a saturated one, linear between (the wetter the cloth, the deeper its wrinkles)
float disturbanceStrength(const WrinkleParams& params, float saturation);

// the disturbances of one cloth piece at this step: for each subdomain (sets of piece-local
// vertices) near equilibrium whose most compressed stretch spring is below -compressionThreshold,
// one constraint, moving A by disturbanceStrength of its saturation (piece-local; empty: all
// saturated, so `strength` applies). Returns nothing unless params.enabled and stepIndex % interval == 0.
std::vector<PositionConstraint> computeDisturbances(const Model& model, int piece, const SpringSet& springs,
                                                    const std::vector<std::vector<int>>& subdomains,
                                                    const Particles& p, const std::vector<ColliderPose>& poses,
                                                    const WrinkleParams& params, uint64_t stepIndex,
                                                    std::span<const float> saturation = {});

// splits a mesh without panels into connected patches of about targetSize vertices: breadth-first
// growth from the lowest unassigned vertex, then patches under half the size merged into their
// smallest neighbour. Every vertex is in exactly one patch; each patch is sorted.
std::vector<std::vector<int>> splitIntoPatches(int numVertices, const std::vector<std::array<int, 3>>& triangles,
                                               int targetSize);

}  // namespace soak
