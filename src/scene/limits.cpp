#include "scene/limits.hpp"

#include <soak/error.hpp>

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>

namespace soak {

std::string readSceneText(const std::string& path, size_t maxBytes) {
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw errorAt(path, "", "cannot open the scene file (expected a readable JSON file)");
  std::string text;
  char chunk[1 << 16];
  // read in chunks up to one byte past the bound: a device or pipe has no size to ask first
  while (in && text.size() <= maxBytes) {
    in.read(chunk, sizeof chunk);
    text.append(chunk, size_t(in.gcount()));
  }
  if (in.bad()) throw errorAt(path, "", std::string("read failed: ") + std::strerror(errno));
  if (text.size() > maxBytes)
    throw errorAt(path, "", fmt::format("expected a scene file of at most {} MiB, got more (is it a scene file?)",
                                        maxBytes >> 20));
  return text;
}

void checkJsonText(const std::string& text, const std::string& file) {
  if (text.size() > kMaxSceneBytes)
    throw errorAt(file, "", fmt::format("expected a scene of at most {} MiB of JSON, got {} bytes", kMaxSceneBytes >> 20,
                                        text.size()));
  int depth = 0;
  size_t line = 1, column = 0;
  bool inString = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    ++column;
    if (c == '\n') {
      ++line;
      column = 0;
    }
    if (inString) {
      if (c == '\\') {
        ++i;  // the escaped character cannot end the string
        ++column;
      } else if (c == '"') {
        inString = false;
      }
      continue;
    }
    if (c == '/' && i + 1 < text.size() && (text[i + 1] == '/' || text[i + 1] == '*')) {
      // a comment (the parser allows them): skip to its end, counting lines
      // a block comment ends after its "*/", a line comment before its newline
      const bool block = text[i + 1] == '*';
      const size_t end = block ? text.find("*/", i + 2) : text.find('\n', i + 2);
      const size_t next = end == std::string::npos ? text.size() : end + (block ? 2 : 0);
      for (size_t k = i + 1; k < next; ++k) {
        ++column;
        if (text[k] == '\n') {
          ++line;
          column = 0;
        }
      }
      i = next - 1;
      continue;
    }
    if (c == '"') inString = true;
    else if (c == ']' || c == '}') --depth;
    else if ((c == '[' || c == '{') && ++depth > kMaxJsonDepth)
      throw errorAt(file, fmt::format("line {}, column {}", line, column),
                    fmt::format("expected arrays and objects nested at most {} deep, got deeper", kMaxJsonDepth));
  }
}

uint64_t availableMemoryBytes() {
  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  uint64_t kib = 0;
  std::string unit;
  while (meminfo >> key >> kib >> unit)
    if (key == "MemAvailable:") return kib * 1024;
  const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGESIZE);
  return pages > 0 && pageSize > 0 ? uint64_t(pages) * uint64_t(pageSize) : 0;
}

int64_t affordableParticles(float maxMemoryGB) {
  double bytes = double(maxMemoryGB) * 1e9;
  if (!(maxMemoryGB > 0.0f)) {
    const uint64_t available = availableMemoryBytes();
    bytes = available > 0 ? double(available) : 1e300;  // unknown: no memory bound, only maxParticles
  }
  return int64_t(std::min(bytes / kBytesPerParticle, 9e18));
}

ParticleLimit particleLimit(int maxParticles, float maxMemoryGB) {
  const int64_t affordable = affordableParticles(maxMemoryGB);
  if (affordable >= maxParticles) return {maxParticles, "solver.maxParticles"};
  const double gb = double(affordable) * kBytesPerParticle / 1e9;
  return {int(affordable),
          maxMemoryGB > 0.0f
              ? fmt::format("what solver.maxMemoryGB = {} affords at {} bytes a particle", maxMemoryGB, kBytesPerParticle)
              : fmt::format("what the {:.3g} GB of available memory affords at {} bytes a particle; set "
                            "solver.maxMemoryGB to allow more",
                            gb, kBytesPerParticle)};
}

std::string nameProblem(const std::string& name) {
  if (name.empty()) return "an empty name";
  if (name.size() > kMaxNameLength) return fmt::format("a name of {} characters", name.size());
  for (size_t i = 0; i < name.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(name[i]);
    if (c < 0x20 || c == 0x7f) return fmt::format("a control character (byte 0x{:02x}) at position {}", c, i);
    if (c > 0x7f) return fmt::format("a non-ASCII byte (0x{:02x}) at position {}", c, i);
  }
  return "";
}

namespace {

// lattice sites of spacing s in [lo, hi] (emitters.cpp's latticeCount), clamped so a tiny spacing
// cannot overflow
double latticeSites(float lo, float hi, float s) {
  const double extent = double(hi) - double(lo);
  return extent > 0.0 ? std::floor(extent / double(s) + 1e-4) : 0.0;
}

// the sites of a jet's disc: the square lattice points within radius / spacing of the centre
double discSites(double radiusOverSpacing) {
  const int64_t n = int64_t(std::floor(std::min(radiusOverSpacing, kMaxJetRadiusRatio)));
  const double r2 = radiusOverSpacing * radiusOverSpacing + 1e-6;
  double sites = 0.0;
  for (int64_t j = -n; j <= n; ++j) sites += 2.0 * std::floor(std::sqrt(std::max(r2 - double(j * j), 0.0))) + 1.0;
  return sites;
}

}  // namespace

int64_t emitterParticleBound(const Model& model, double duration) {
  const double s = model.water.spacing;
  const double cap = double(model.solver.maxParticles);
  double total = 0.0;
  for (const Emitter& e : model.emitters) {
    double n = 0.0;
    const double active = std::max(0.0, std::min(double(e.end), duration) - double(e.start));
    if (e.kind == EmitterKind::Block) {
      n = latticeSites(e.boxMin.x(), e.boxMax.x(), float(s)) * latticeSites(e.boxMin.y(), e.boxMax.y(), float(s)) *
          latticeSites(e.boxMin.z(), e.boxMax.z(), float(s));
    } else if (e.kind == EmitterKind::Jet) {
      n = (double(e.speed) * active / s + 1.0) * discSites(double(e.radius) / s);
    } else {
      n = double(e.rate) * 4.0 * double(e.halfExtents.x()) * double(e.halfExtents.z()) * active + 1.0;
    }
    total += std::min(n, cap);
  }
  return int64_t(std::min(total, cap));
}

}  // namespace soak
