// a sweep (a wedge): variants of one scene, each a set of scene values given as `soak run --set`
// takes them, from a SWEEP.json file (docs/sweeps.md)
#pragma once
#include <string>
#include <utility>
#include <vector>

namespace soak {

struct SweepVariant {
  // the swept values, (scene key, value as JSON text), in the order of the sweep's keys
  std::vector<std::pair<std::string, std::string>> params;
  std::string folder;  // "v000", "v001", ...: the variant's output folder inside the sweep's

  // "key=value" for each parameter, as `soak run --set` takes them
  std::vector<std::string> overrides() const;
  // "key=value, key=value": the variant's label (the summary, the contact sheet)
  std::string label() const;
};

// the contact sheet: one picture of each variant (soak render), labelled with its values
struct SweepSheet {
  int frame = -1;       // the frame pictured; -1: each variant's last
  int columns = 0;      // pictures to a row; 0: about the square root of the count
  int width = 480, height = 360;  // pixels of each picture
  bool particles = false;         // water drawn as particles (faster) instead of its surface
};

struct SweepSpec {
  std::string file;                 // the SWEEP.json it was read from
  std::string scene;                // the base scene, resolved against the sweep file's folder
  std::vector<std::string> common;  // "set": key=value applied to every variant before its own
  int frames = -1;                  // frames per variant; -1: the scene's output.frames
  std::vector<std::string> keys;    // the swept keys, in the file's order
  std::vector<SweepVariant> variants;
  SweepSheet sheet;                 // "contactSheet"
};

// the most variants one sweep may have
inline constexpr int kMaxSweepVariants = 10000;

// reads SWEEP.json: "scene" (a path, relative to the sweep file's folder), optional "set" (a list of
// "key=value"), "frames" and "contactSheet", and either "axes" (key -> a list of values, or {"from", "to", "count",
// "log"}: every combination, the first key slowest) or "variants" (a list of {key: value} objects,
// all with the same keys). Throws soak::Error naming the file, the JSON path and what was expected.
SweepSpec loadSweep(const std::string& path);

// loads the base scene with each variant's values (as `soak validate` would; only variant `only`
// when it is >= 0) so that a bad key or value is reported, with the variant, before anything runs.
// Throws soak::Error.
void checkSweepVariants(const SweepSpec& spec, int only = -1);

}  // namespace soak
