// helpers for the wetting tests: run single wetting stages on a scene's state with neighbour lists
// built on the current positions, and sum where the water is
#pragma once
#include "support/run_scene.hpp"

#include "grid/grid.hpp"
#include "pbd/integrate.hpp"
#include "wetting/wetting.hpp"

#include <string>
#include <vector>

namespace soak::testing {

// what the step gives the wetting stages: a grid and neighbour lists on the positions, and Eq. 10
struct StageRig {
  NeighborGrid grid;
  NeighborLists nb;
  WettingScratch s;

  void refresh(State& state, const Model& model) {
    Particles& p = state.particles;
    p.xPred = p.x;
    buildGrid(p.x, maxSupportRadius(p), grid);
    buildNeighborLists(p.x, p.radius, grid, nb);
    updatePorosity(model, state, nb, s);
  }
};

// appends a resting water particle of the scene's full mass and radius; returns its index
inline size_t addWater(Scene& scene, const Vec3& x) {
  State& st = scene.state;
  return st.particles.add(kWaterPhase, st.nextId++, scene.model.water.particleMass, scene.model.water.supportRadius,
                          x, Vec3::Zero());
}

inline double sum(const std::vector<double>& v) {
  double t = 0.0;
  for (double x : v) t += x;
  return t;
}

// free + held + buffered + removed at the bounds, kg
inline double accountedWater(const Scene& scene) {
  return totalWaterMass(scene) + sum(scene.state.clothWater) + sum(scene.state.clothBuffer) +
         scene.state.ledger.removedAtBounds;
}

// a rectangle cloth piece as scene JSON
inline std::string rectangleJson(const std::string& name, const Vec3& center, float w, float h, int nx, int ny,
                                 const std::string& axisU, const std::string& axisV, const std::string& pin) {
  return "{\"name\": \"" + name + "\", \"mesh\": {\"type\": \"rectangle\", \"center\": [" + std::to_string(center.x()) +
         ", " + std::to_string(center.y()) + ", " + std::to_string(center.z()) + "], \"size\": [" + std::to_string(w) +
         ", " + std::to_string(h) + "], \"resolution\": [" + std::to_string(nx) + ", " + std::to_string(ny) +
         "], \"axisU\": " + axisU + ", \"axisV\": " + axisV + "}, \"pin\": " + pin + "}";
}

// a 0.4 m sheet of 21 x 21 hanging from its two top corners, wetting on with Table 1's defaults
inline const char* kHanging = R"({
  "cloth": [{"name": "sheet", "mesh": {"type": "rectangle", "center": [0, 1, 0], "size": [0.4, 0.4],
             "resolution": [21, 21], "axisU": [1, 0, 0], "axisV": [0, 1, 0]}, "pin": {"corners": [2, 3]}}],
  "wetting": {}
})";

// pins every vertex of a piece (a box around the whole scene)
inline const char* kPinAll = R"({"region": {"min": [-5, -5, -5], "max": [5, 5, 5]}})";

}  // namespace soak::testing
