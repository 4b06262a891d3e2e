// water surface from particles (docs/rendering.md, "Water surface"): each particle becomes a ball,
// the balls are unioned into a narrow-band level set (OpenVDB ParticlesToLevelSet), smoothed and
// eroded (LevelSetFilter) and meshed (volumeToMesh). OpenVDB stays inside surface.cpp.
#pragma once
#include <array>
#include <memory>
#include <soak/math.hpp>
#include <soak/model.hpp>
#include <soak/render.hpp>
#include <span>
#include <string>
#include <vector>

#include "world/colliders.hpp"

namespace soak {

// a triangle mesh, outward facing: counter-clockwise seen from outside
struct SurfaceMesh {
  std::vector<Vec3> vertices;                 // m
  std::vector<Vec3> normals;                  // unit, area weighted, one per vertex
  std::vector<std::array<int, 3>> triangles;  // 0-based vertex indices
};

// the narrow-band level set of a water surface (an openvdb::FloatGrid behind a pointer)
class WaterLevelSet {
 public:
  struct Impl;
  explicit WaterLevelSet(std::unique_ptr<Impl> impl);
  ~WaterLevelSet();
  WaterLevelSet(WaterLevelSet&&) noexcept;
  WaterLevelSet& operator=(WaterLevelSet&&) noexcept;

  float voxelSize() const;
  size_t activeVoxels() const;
  // particles added back as single balls (dropFraction) after the smoothing
  size_t dropParticles() const;
  const Impl& impl() const { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

// the level set of the particles at x with support radii h (one per particle); balls under 1.5
// voxels are enlarged to that size (OpenVDB's sampling limit) so that no particle is lost. Throws soak::Error
// when the sizes differ or a setting is out of range.
WaterLevelSet waterLevelSet(std::span<const Vec3> x, std::span<const float> h, const SurfaceSettings& settings);

// the zero isosurface as triangles (quads split), outward facing
SurfaceMesh levelSetMesh(const WaterLevelSet& levelSet);

// the zero level of a mesh collider's signed distance grid as triangles, in the collider's local frame
// (for drawing it; the grid is what the solver sees)
SurfaceMesh sdfGridMesh(const SdfGrid& grid);

// the zero level of a collider's distance at a pose, sampled (colliderDistanceBounds) on a grid of
// spacing cellSize over the world box [lo, hi], in the world frame: how a Body's smooth skin is drawn
// each frame. Empty when the box would need more than kMaxSdfNodes nodes
SurfaceMesh colliderSurfaceMesh(const Collider& c, const ColliderPose& pose, const Vec3& lo, const Vec3& hi,
                                float cellSize);

// volume enclosed by a closed, outward-facing mesh (divergence theorem), m^3
double enclosedVolume(const SurfaceMesh& mesh);

// writes the level set as a VDB file with one grid named "surface" (class level set) and the frame
// metadata given; throws soak::Error naming the file
void writeLevelSetVdb(const std::string& path, const WaterLevelSet& levelSet, int frame, double time);

// what a VDB file written by writeLevelSetVdb holds (for checks and tools)
struct VdbSummary {
  bool levelSet = false;  // the grid "surface" is of class level set
  size_t activeVoxels = 0;
  float voxelSize = 0.0f;  // m
  int frame = -1;          // the "frame" metadata
  double time = 0.0;       // s, the "time" metadata
};
// reads the grid "surface" of a VDB file; throws soak::Error naming the file
VdbSummary readLevelSetVdb(const std::string& path);

// water_surface_NNNN.obj: `v`, `vn` and 1-based `f a//a b//b c//c`
void writeSurfaceObj(const std::string& path, const SurfaceMesh& mesh);

// water_surface_NNNN.ply: binary little endian, float x y z nx ny nz and list uchar int vertex_indices
void writeSurfacePly(const std::string& path, const SurfaceMesh& mesh);

}  // namespace soak
