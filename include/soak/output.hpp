// what a run writes (docs/output-format.md): the frame files, the per-frame statistics as JSON lines,
// and where the water is. Every failure throws soak::Error naming the file.
#pragma once
#include <soak/model.hpp>
#include <soak/scene.hpp>
#include <soak/state.hpp>
#include <soak/stats.hpp>

#include <nlohmann/json.hpp>

#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace soak {

// writes dir/cloth_NNNN.obj, dir/cloth_NNNN.ply and dir/water_NNNN.ply as enabled in `settings`
// (cloth files only when the model has cloth). With Shao's wetting the cloth PLY carries each
// vertex's saturation and the OBJ its colour on settings.colorRamp; for Chen 2012 pieces without it,
// the wetness Q(t) / delta. Returns the paths written.
std::vector<std::string> writeFrame(const std::string& dir, const Model& model, const State& state,
                                    const OutputSettings& settings, int frame);

// the StepStats of the steps between two written frames, summed (times, contacts, counts) or
// reduced (max speed: max; mean density ratio: mean over the steps)
struct FrameStats {
  int steps = 0;
  int substeps = 0;
  StageTimes ms;                     // ms, summed over the steps
  uint64_t couplingContacts = 0;
  uint64_t emittedParticles = 0;
  uint64_t removedParticles = 0;
  uint64_t colliderPutBack = 0;
  double densityRatioSum = 0.0;
  uint64_t fluidIterations = 0;      // summed over the substeps
  int fluidIterationsMax = 0;
  float maxSpeed = 0.0f;             // m/s
  GarmentStats garment;

  void add(const StepStats& s);
};

// where the water is (kg): free particles, held by the cloth, in the cloth's emission buffers
// (Shao 2017 section 4), emitted so far, removed at the domain bounds, taken in by Chen 2012 pieces;
// total is free + heldInCloth + inBuffers + removedAtBounds + takenByCloth and equals emitted while
// water is conserved
struct WaterMass {
  double free = 0.0, heldInCloth = 0.0, inBuffers = 0.0, emitted = 0.0, removedAtBounds = 0.0, takenByCloth = 0.0,
         total = 0.0;
};
WaterMass waterMass(const State& state);

// the stats line of one frame: frame, time, step, steps, substeps, counts, waterMass, wetting (when
// on), removedAtBounds, couplingContacts, meanDensityRatio, maxSpeed, ms (per stage, summed), msPerStep
nlohmann::ordered_json frameStatsJson(const Model& model, const State& state, int frame, const FrameStats& fs);

// appends JSON lines to a file, flushing after each line so a crashed run keeps its stats
class JsonLinesWriter {
 public:
  // opens `path`, truncating it or, with append, adding after its lines (a resumed run); throws
  // soak::Error naming it on failure
  explicit JsonLinesWriter(const std::string& path, bool append = false);
  void write(const nlohmann::ordered_json& line);
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::ofstream out_;
};

// writes `text` to `path` in one go
void writeTextFile(const std::string& path, std::string_view text);

// reads a whole file; throws soak::Error naming the file on failure
std::string readTextFile(const std::string& path);

}  // namespace soak
