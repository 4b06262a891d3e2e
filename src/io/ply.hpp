// PLY output (binary little endian) for cloth and water, and a small reader for tests and tools.
// Property names are the common ones (x y z, nx ny nz) that Houdini reads and Blender 3.4 reads the positions of.
#pragma once
#include <soak/model.hpp>
#include <soak/state.hpp>

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace soak {

// an extra per-vertex float attribute of the cloth (e.g. "saturation"), one value per cloth particle
struct PlyFloatAttribute {
  std::string name;
  std::span<const float> values;
};

// cloth_NNNN.ply: element vertex (cloth particles [0, numCloth)) with float x y z, float nx ny nz,
// float vx vy vz, int piece, uchar pinned, then each extra float attribute; element face with
// `property list uchar int vertex_indices` (0-based). normals: one per cloth particle, or empty to
// compute them (area weighted). Throws soak::Error naming the file.
void writeClothPly(const std::string& path, const Model& model, const State& state,
                   std::span<const Vec3> normals = {}, std::span<const PlyFloatAttribute> extras = {});

// water_NNNN.ply: element vertex (water particles in state order) with float x y z, float vx vy vz,
// float mass, float radius, uint id. Throws soak::Error naming the file.
void writeWaterPly(const std::string& path, const State& state);

// what readPly returns: every element with its scalar properties widened to double (exact for the
// float/int/uint/uchar types soak writes) and its list properties (integer items, e.g. faces) as
// flat start + values arrays
struct PlyElement {
  std::string name;
  size_t count = 0;
  std::vector<std::string> propertyNames;            // in file order
  std::map<std::string, std::string> propertyType;   // name -> PLY type ("float", "list uchar int", ...)
  std::map<std::string, std::vector<double>> scalars;
  std::map<std::string, std::vector<size_t>> listStart;  // size count + 1
  std::map<std::string, std::vector<int64_t>> listValues;

  bool has(const std::string& property) const { return propertyType.count(property) != 0; }
  // the values of a scalar property; throws soak::Error when it is missing
  const std::vector<double>& scalar(const std::string& property) const;
};

struct PlyData {
  std::string path;
  std::string format;                 // "binary_little_endian", "binary_big_endian" or "ascii"
  std::vector<std::string> comments;
  std::vector<PlyElement> elements;

  bool has(const std::string& element) const;
  // the element named `name`; throws soak::Error when it is missing
  const PlyElement& element(const std::string& name) const;
};

// reads a PLY file (ascii or binary, either endianness). Throws soak::Error naming the file and the
// header line or element where it is malformed or truncated.
PlyData readPly(const std::string& path);

}  // namespace soak
