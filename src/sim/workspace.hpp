// scratch buffers of the step, reused from step to step (no allocation after warm-up)
#pragma once
#include <soak/step.hpp>

#include "garment/stage.hpp"
#include "grid/grid.hpp"
#include "grid/reorder.hpp"
#include "pbd/cloth.hpp"
#include "pbd/coupling.hpp"
#include "pbd/fluid.hpp"
#include "wetting/wetting.hpp"
#include "world/colliders.hpp"

#include <vector>

namespace soak {

struct Workspace {
  NeighborGrid grid;
  NeighborLists neighbors;
  std::vector<ColliderPose> poses;      // collider poses at the end of the substep
  std::vector<Vec3> contactNormal;      // collider contact normal per particle, zero when none
  std::vector<float> colliderBound;     // projectColliders' scratch: a lower bound of the distance to the colliders
  FluidScratch fluid;
  ClothScratch cloth;
  SmallStepColliders clothColliders;    // the colliders in the PBD cloth's small steps (smallStepColliders)
  CouplingScratch coupling;
  std::vector<uint8_t> keep;            // particles kept after the domain check
  std::vector<IndexRange> pbdParticles; // the particles the PBD stages move this substep (pbdParticles)
  WettingScratch wetting;               // cloth wetting (Shao 2017 section 4)
  GarmentScratch garment;               // implicit garments and saturation mass (Chen 2012)
  ReorderScratch reorder;               // keys and buffer of the water's sort by cell
};

}  // namespace soak
