// long range attachments (Kim, Chentanez, Müller 2012) between free cloth particles and the pinned ones
#pragma once
#include <soak/model.hpp>
#include <soak/state.hpp>

namespace soak {

// rebuilds model.tethers from the pins and the stretch edges: each free particle is tied to up to
// maxAnchors pinned particles of its piece, the nearest by shortest path over the rest shape (edges and
// 2-ring chords), with length (1 + material.tetherSlack) times that path
void buildTethers(Model& model, int maxAnchors = 4);

// projects every free cloth particle back inside the spheres |x - x_anchor| <= length (the anchors
// are pinned, so only the free particle moves; gather style)
void solveTethers(const Model& model, Particles& p);

// the same on x* = base + displacement, moving the displacement (the small steps, solveClothFrom)
void solveTethersFrom(const Model& model, const Vec3* base, Vec3* displacement);

}  // namespace soak
