// bounds that keep hostile scene files from hanging or exhausting the machine: the JSON text's size
// and depth, the counts of the solver's loops, and the memory the particles of a scene can take
// (docs/scene-format.md, "Limits"). Every check runs before the allocation or loop it guards.
#pragma once
#include <soak/model.hpp>

#include "scene/reader.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

namespace soak {

inline constexpr size_t kMaxSceneBytes = size_t(64) << 20;  // a scene file's text
inline constexpr int kMaxJsonDepth = 64;                    // arrays and objects nested in a scene
inline constexpr int kMaxLoopCount = 1000;                  // substeps and iterations of one step
inline constexpr int kMaxStepsPerFrame = 100000;
inline constexpr int kMaxCgIterations = 100000;            // a garment's conjugate gradient solve
inline constexpr double kMinGarmentEdgeLength = 0.002;     // m, a sewn garment's triangle edges
inline constexpr double kMaxGarmentEdgesPerHeight = 1000.0;  // a garment's edges along its mannequin's height
inline constexpr double kMaxMannequinHeight = 10.0;          // m
inline constexpr double kMaxSupportRatio = 10.0;            // water.supportRadius / water.spacing
inline constexpr double kMaxJetRadiusRatio = 1000.0;        // a jet's radius / water.spacing
inline constexpr double kMaxDropsPerSecond = 1e9;           // a rain emitter's rate x area
inline constexpr size_t kMaxNameLength = 256;               // scene, cloth, collider and emitter names
// the memory one particle takes in a run, all its arrays together (State, neighbour lists, solver
// scratch, cloth constraints): the peak resident memory of bench/water_block_100k.json is about 1 kB a
// water particle, of fig3a_cube_on_cloth.json (half cloth) about 2 kB a particle
inline constexpr double kBytesPerParticle = 2048.0;

// the whole file as text; throws soak::Error naming the file when it cannot be read or holds more
// than maxBytes (a device such as /dev/zero is read up to that bound, never further)
std::string readSceneText(const std::string& path, size_t maxBytes = kMaxSceneBytes);

// throws soak::Error "<file>: at line L, column C: expected ..." when the text is larger than
// kMaxSceneBytes or its arrays and objects nest deeper than kMaxJsonDepth (strings and comments are
// skipped); run before parsing, since a deep document overflows the stack of recursive readers
void checkJsonText(const std::string& text, const std::string& file);

// the machine's available memory in bytes (MemAvailable of /proc/meminfo, else physical memory);
// 0 when unknown
uint64_t availableMemoryBytes();

// the particles a scene may hold in memory: solver.maxMemoryGB (default: the available memory)
// divided by kBytesPerParticle
int64_t affordableParticles(float maxMemoryGB);

// the most particles a scene may have and which bound sets it: solver.maxParticles, or the memory
// budget (solver.maxMemoryGB, default the available memory) over kBytesPerParticle
struct ParticleLimit {
  int count = 0;
  std::string why;  // "solver.maxParticles" or "the memory budget: ..."
};
ParticleLimit particleLimit(int maxParticles, float maxMemoryGB);

// "" when `name` is 1..kMaxNameLength printable ASCII characters, else what is wrong with it
// ("a control character (byte 0x0a) at position 5")
std::string nameProblem(const std::string& name);

// the most particles the emitters can create in `duration` seconds of simulation: blocks by their
// lattice, jets and rain by their rate over [start, min(end, duration)), capped at solver.maxParticles
int64_t emitterParticleBound(const Model& model, double duration);

}  // namespace soak
