// contact rows of the implicit step (implicit.hpp, Eq. 1-5): contact held as a constraint of the solve
// with Coulomb friction (docs/garment.md departures 9 and 10)
#pragma once
#include "garment/implicit.hpp"

#include <span>
#include <vector>

namespace soak {

// contact as a constraint of the solve (Baraff & Witkin 1998 section 5.3; Chen 2012 leaves contact to
// after the solve: docs/garment.md departure 10): a free vertex within kContactBand margins of a
// collider at the start of the step, which its own row's estimate v0 + A_ii^-1 b_i would take nearer
// than the margin, gets a contact row: its velocity along the nearest collider's normal after the
// step is prescribed, so that it comes down to the margin and never leaves the surface faster than
// the surface moves. With friction it starts sticking (kStickRow: its tangential velocity the
// surface's), without it slides (kContactRow); updateContactRows then applies Coulomb's law. A vertex
// whose estimate leaves is not held, no glue, but watched: a solve that drives it through the surface
// makes it a row (addDrivenRows in the rounds). The solve's neighbours of a held vertex see it held,
// where a push after the solve would stretch their springs. fabricFriction: the fabric's coefficient
// per vertex, mixed with the collider's static and kinetic ones.
void contactRows(const Model& model, const GarmentPiece& g, const std::vector<ColliderPose>& poses, const Particles& p,
                 float h, std::span<const float> fabricFriction, ImplicitScratch& w);

// the filtered PCG of Eq. 5 with the contact rows, the rounds of updateContactRows and addDrivenRows
// (contact_rows.cpp); v0: the piece's velocities at the start of the step
void solveWithContact(const GarmentParams& params, std::span<const Vec3> v0, ImplicitScratch& w, ImplicitStats& stats);

}  // namespace soak
