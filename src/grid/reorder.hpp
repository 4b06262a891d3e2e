// spatial sort of the water particles: from time to time the water is put in the Morton order of
// its grid cells, so neighbours sit close in memory (the gathers of the neighbour search and the PBF
// loops hit the cache). Cloth particles stay at [0, numCloth) in their mesh order. The order depends
// only on the positions and the current order (a stable sort), never on the thread count.
#pragma once
#include <soak/state.hpp>

#include <cstdint>
#include <vector>

namespace soak {

struct ReorderScratch {
  std::vector<uint64_t> keys;     // Morton code of the cell << 32 | current water index
  std::vector<char> buffer;       // one permuted array at a time
};

// the 30-bit Morton code (10 bits per axis, x lowest) of a cell given relative to the lowest cell;
// coordinates past 1023 are clamped (far away particles are sorted coarsely, still correctly)
uint32_t mortonCode(uint32_t cx, uint32_t cy, uint32_t cz);

// sorts the particles [first, n) by the Morton code of the cell of side cellSize that holds x,
// stable (equal cells keep their order), permuting every per-particle array of p together (phase,
// id, mass, invMass, radius, x, xPred, v). Returns true when the order changed.
bool sortParticlesByCell(Particles& p, size_t first, float cellSize, ReorderScratch& scratch);

}  // namespace soak
