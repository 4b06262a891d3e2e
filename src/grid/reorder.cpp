#include "grid/reorder.hpp"

#include "core/parallel.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace soak {

namespace {

// spreads the low 10 bits of v to every third bit
uint32_t spread3(uint32_t v) {
  v &= 0x3ffu;
  v = (v | (v << 16)) & 0x030000ffu;
  v = (v | (v << 8)) & 0x0300f00fu;
  v = (v | (v << 4)) & 0x030c30c3u;
  v = (v | (v << 2)) & 0x09249249u;
  return v;
}

// a[k] = old[perm(k)] for the sorted keys, through the scratch buffer
template <class T>
void permute(std::vector<T>& a, size_t first, const std::vector<uint64_t>& keys, std::vector<char>& buffer) {
  const size_t m = keys.size();
  buffer.resize(m * sizeof(T));
  T* tmp = reinterpret_cast<T*>(buffer.data());
  const T* src = a.data() + first;
  parallelFor(static_cast<int64_t>(m), [&](int64_t k) { tmp[k] = src[static_cast<uint32_t>(keys[k])]; });
  std::memcpy(static_cast<void*>(a.data() + first), tmp, m * sizeof(T));
}

}  // namespace

uint32_t mortonCode(uint32_t cx, uint32_t cy, uint32_t cz) {
  return spread3(std::min(cx, 1023u)) | (spread3(std::min(cy, 1023u)) << 1) | (spread3(std::min(cz, 1023u)) << 2);
}

bool sortParticlesByCell(Particles& p, size_t first, float cellSize, ReorderScratch& scratch) {
  const size_t n = p.size();
  if (n <= first + 1 || !(cellSize > 0.0f)) return false;
  const size_t m = n - first;
  // the lowest cell of the set, so cell coordinates start at 0
  Vec3 lo = p.x[first];
  for (size_t i = first + 1; i < n; ++i) lo = lo.cwiseMin(p.x[i]);
  const float inv = 1.0f / cellSize;
  std::vector<uint64_t>& keys = scratch.keys;
  keys.resize(m);
  parallelFor(static_cast<int64_t>(m), [&](int64_t k) {
    const Vec3 c = ((p.x[first + k] - lo) * inv).array().floor();
    // finite positions are checked once per frame; a non-finite one sorts last
    const auto coord = [](float v) { return v >= 0.0f && v < 1024.0f ? static_cast<uint32_t>(v) : 1023u; };
    keys[k] = (static_cast<uint64_t>(mortonCode(coord(c.x()), coord(c.y()), coord(c.z()))) << 32) |
              static_cast<uint64_t>(k);
  });
  // the index in the low bits makes every key unique, so the sort is stable and deterministic
  if (std::is_sorted(keys.begin(), keys.end())) return false;
  std::sort(keys.begin(), keys.end());
  permute(p.phase, first, keys, scratch.buffer);
  permute(p.id, first, keys, scratch.buffer);
  permute(p.mass, first, keys, scratch.buffer);
  permute(p.invMass, first, keys, scratch.buffer);
  permute(p.radius, first, keys, scratch.buffer);
  permute(p.x, first, keys, scratch.buffer);
  permute(p.xPred, first, keys, scratch.buffer);
  permute(p.v, first, keys, scratch.buffer);
  return true;
}

}  // namespace soak
