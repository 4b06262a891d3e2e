// the passes and the fail-safe of selfCollide (self_collision.hpp), over the step's pairs, and the
// crossing tests they share with the pair search
#pragma once
#include "garment/self_collision.hpp"

#include <array>
#include <vector>

namespace soak {

// whether the vertex (point 0) went through the triangle (points 1-3) during the step: from one side of
// its plane to the other, crossing it inside the triangle, the triangle turning by less than 60 degrees
bool passedThrough(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1);
// whether edges (0, 1) and (2, 3) passed through each other during the step, their lines' closest
// points inside both then (not where they were within about 6 degrees of parallel)
bool edgesPassedThrough(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1);

// kSelfCollisionPasses Gauss-Seidel passes over s.pairs then s.edgePairs, a pair found clear skipped
// until one of its points moves; returns the pushes of each kind
constexpr int kSelfCollisionPasses = 3;
SelfCollisionPushes pushPairs(const SelfCollisionMesh& mesh, const std::vector<float>& invMass, float thickness,
                              const Vec3* x0, Vec3* x1, Vec3* vel, SelfCollisionScratch& s);
// the fail-safe: rigid impact zones in translation for the pairs still through each other; returns the
// points moved into zones
int impactZones(const SelfCollisionMesh& mesh, const std::vector<float>& invMass, const Vec3* x0, Vec3* x1,
                Vec3* vel, SelfCollisionScratch& s);

}  // namespace soak
