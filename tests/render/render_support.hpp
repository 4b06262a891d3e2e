// shared scenes of the render tests (tests/render/*_test.cpp)
#pragma once

namespace soak::testing {

// a wet 10 x 10 cloth pinned at its corners under a 4 x 4 x 4 block, a floor, a ball and a crate that
// rises and turns; 3 frames of 2 steps
inline constexpr const char* kTinyScene = R"({
  "name": "tiny_render",
  "description": "render test",
  "solver": {"dt": 0.01, "substeps": 1, "domain": {"min": [-1, -1, -1], "max": [1, 2, 1]}},
  "output": {"frames": 3, "stepsPerFrame": 2},
  "wetting": {},
  "cloth": [{
    "name": "sheet",
    "mesh": {"type": "rectangle", "center": [0, 0.5, 0], "size": [0.2, 0.2], "resolution": [10, 10],
             "axisU": [1, 0, 0], "axisV": [0, 0, 1]},
    "pin": {"corners": [0, 1, 2, 3]}
  }],
  "colliders": [
    {"name": "ground", "type": "plane", "position": [0, 0, 0]},
    {"name": "ball", "type": "sphere", "radius": 0.05, "position": [0.2, 0.05, 0]},
    {"name": "crate", "type": "box", "halfExtents": [0.05, 0.05, 0.05],
     "keyframes": [{"time": 0, "position": [-0.2, 0.05, 0]},
                   {"time": 0.06, "position": [-0.2, 0.25, 0], "rotation": {"axis": [0, 1, 0], "degrees": 45}}]}
  ],
  "emitters": [{"name": "cube", "type": "block", "min": [-0.04, 0.54, -0.04], "max": [0.04, 0.62, 0.04]}]
})";

}  // namespace soak::testing
