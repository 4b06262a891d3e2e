// helpers for the tests of Chen 2012 scenes (tests/garment/stage_test.cpp, run_test.cpp, tests/scene/chen_keys_test.cpp):
// a small implicit sheet under rain, loading from a string as "garment.json", the load error, and a run
#pragma once
#include <soak/error.hpp>
#include <soak/scene.hpp>
#include <soak/step.hpp>

#include "world/garment_mesh.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <string>
#include <vector>

namespace soak::testing {

#ifndef EXPECT_HAS
#define EXPECT_HAS(haystack, needle) EXPECT_NE(std::string(haystack).find(needle), std::string::npos) << (haystack)
#endif

// an implicit 0.4 m sheet of 11 x 11 vertices hung by two corners, with rain over it
inline const char* kSheet = R"({
  "solver": {"dt": 0.0166667, "substeps": 2, "domain": {"min": [-1, 0, -1], "max": [1, 2, 1]}},
  "cloth": [{"name": "sheet", "solver": "implicit", "fabric": "coarse_wool",
             "mesh": {"type": "rectangle", "center": [0, 1, 0], "size": [0.4, 0.4], "resolution": [11, 11]},
             "material": {"particleMass": 2e-4, "thickness": 0.008},
             "pin": {"corners": [0, 1, 2, 3]},
             "garment": {"stretch": {"a1": 500, "a2": 3}, "cg": {"tolerance": 1e-5, "maxIterations": 400}}}],
  "emitters": [{"name": "rain", "type": "rain", "origin": [0, 1.3, 0], "halfExtents": [0.25, 0.25],
                "rate": 3000, "dropRadius": 0.002, "dropSpeed": 2.0, "start": 0.1, "end": 0.8}]
})";

inline Scene fromString(const std::string& text, const std::vector<std::string>& overrides = {}) {
  return loadSceneFromString(text, "garment.json", ".", overrides);
}

// the message of the soak::Error thrown by loading `text`, or "" when it loads
inline std::string loadError(const std::string& text, const std::vector<std::string>& overrides = {}) {
  try {
    fromString(text, overrides);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// the smallest distance of a cloth vertex to the scene's body (its colliders) at the scene's time;
// negative: inside
inline float deepestClothVertex(const Scene& s) {
  float deepest = 1e30f;
  for (int i = 0; i < s.model.numCloth; ++i)
    deepest = std::min(deepest, bodyDistance(s.model.colliders, s.state.time, s.state.particles.x[size_t(i)], nullptr));
  return deepest;
}

// writes an OBJ of the axis-aligned box [lo, hi], its faces wound outwards (a mesh or meshSequence
// collider's frame)
inline void writeBoxObj(const std::string& path, const Vec3& lo, const Vec3& hi) {
  std::ofstream obj(path);
  for (int k = 0; k < 8; ++k)
    obj << "v " << (k & 1 ? hi : lo).x() << " " << (k & 2 ? hi : lo).y() << " " << (k & 4 ? hi : lo).z() << "\n";
  obj << "f 1 3 2\nf 2 3 4\nf 5 6 7\nf 6 8 7\nf 1 2 5\nf 2 6 5\nf 3 7 4\nf 4 7 8\nf 1 5 3\nf 3 5 7\n"
         "f 2 4 6\nf 4 8 6\n";
}

// `steps` steps of the scene's dt; the garment statistics summed into *total
inline void run(const Model& model, State& state, int steps, StepStats* total = nullptr) {
  WorkspacePtr ws = makeWorkspace();
  for (int s = 0; s < steps; ++s) {
    StepStats st;
    step(model, state, *ws, model.solver.dt, st);
    if (total) total->garment += st.garment;
  }
}

}  // namespace soak::testing
