// strain limiting after the implicit step (Provot 1995; Bridson, Fedkiw, Anderson 2002): no stretch
// or shear spring ends a step stretched past Eq. 11's pole 1/a2, where the KES law's stress is
// infinite (docs/garment.md, departure 2)
#pragma once
#include "garment/springs.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace soak {

// Gauss-Seidel passes over the stretch then the shear springs, in spring order (the same result for
// any thread count), at most kStrainLimitPasses: a spring of a law with a2 > 0 longer than
// l0 (1 + 1/a2) is shortened to that length, its ends moved along it in proportion
// to their inverse masses (invMass 0: the end stays), and the move over the step h added to their
// velocities, so momentum is kept and the next step starts from the motion the positions made.
// x and v are the piece's end-of-step positions and velocities (local vertices); moved[v] is set to
// 1 for every vertex moved. Returns the springs shortened, summed over the passes.
constexpr int kStrainLimitPasses = 16;
int limitStrain(const SpringSet& springs, const SpringLaws& laws, std::span<const float> invMass, float h,
                std::span<Vec3> x, std::span<Vec3> v, std::vector<uint8_t>& moved);

}  // namespace soak
