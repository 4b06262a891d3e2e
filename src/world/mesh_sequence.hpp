// an animated closed mesh played as a collider (ColliderShape::MeshSequence): frames of one topology,
// the usual export of a character's animation from Blender, Houdini or Maya as one OBJ per frame.
// Positions are interpolated linearly between frames; the surface moves with the vertices'
// velocities, interpolated over each triangle; distances are exact to the interpolated triangles
// (a CGAL AABB tree built for each pose, its search started from a vertex near the query found in a
// coarse grid), signed by angle-weighted pseudo-normals (mesh_distance.hpp)
#pragma once
#include <soak/model.hpp>

#include "world/mesh.hpp"
#include "world/mesh_distance.hpp"

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace soak {

struct MeshSequence {
  std::vector<std::array<int, 3>> triangles;  // the same in every frame, outward by frame 0's volume
  std::vector<std::array<int, 3>> twin;       // twinTriangles of them
  int vertexCount = 0, frameCount = 0;
  std::vector<Vec3> positions;  // m, local frame: vertex v of frame f at f * vertexCount + v
  double fps = 24.0;            // frames per second of the sequence
  double start = 0.0;           // s, the simulation time at which frame 0 shows
  // m: the median edge length of frame 0, taken as the thinnest the surface is (how finely a fast
  // particle's path is sampled for a crossing, collider_contact.cpp)
  float thickness = 0.0f;
  std::vector<int> vertexTriangle;  // a triangle holding each vertex (-1: none), for search hints
  bool flipped = false;             // the files' triangles were wound inwards: stored turned (a, c, b)
};

// most positions (vertices x frames) a sequence may hold: 2^26, 768 MiB of floats
constexpr int64_t kMaxSequencePositions = int64_t(1) << 26;

// a sequence from meshes of one topology; names[f] names frame f's file in errors. Throws soak::Error
// naming the file when a frame's triangles differ from frame 0's (count or indices) or its vertex
// count does, a position is not finite, frame 0 is not a closed consistently oriented surface or has
// a degenerate triangle, or fps is not > 0
MeshSequence makeMeshSequence(const std::vector<TriangleMesh>& frames, const std::vector<std::string>& names,
                              double fps, double start);

// the files of a sequence. `pattern` holds one run of '#' in its file name, standing for the frame
// number zero-padded to the run's length ("walk/body_####.obj": body_0001.obj, ..., body_12345.obj).
// first < 0: the lowest frame number found in the directory; last < 0: up to the first missing
// frame, else every frame in [first, last] must exist. Throws soak::Error naming the pattern or the
// missing file
std::vector<std::string> meshSequenceFiles(const std::string& pattern, int first, int last, int* firstFound);

// reads the files (positions multiplied by `scale`) into a sequence, one at a time, each checked as it
// is read; refuses a sequence of more than kMaxSequencePositions positions after reading frame 0
MeshSequence loadMeshSequence(const std::vector<std::string>& files, double fps, double start, float scale);

// the sequence at time t: frames f and f + 1 around u = (t - start) fps blended by u - f, the
// vertices moving at (x_{f+1} - x_f) fps; before frame 0 and after the last frame it rests there
class MeshSnapshot {
 public:
  MeshSnapshot(std::shared_ptr<const MeshSequence> sequence, double t);
  ~MeshSnapshot();
  MeshSnapshot(const MeshSnapshot&) = delete;
  MeshSnapshot& operator=(const MeshSnapshot&) = delete;

  // signed distance (m, negative inside) from p (local frame) to the surface; `normal`: unit, the
  // direction from the nearest surface point (its feature's pseudo-normal on the surface);
  // `velocity`: the surface's velocity at the nearest point. Either may be null
  float distance(const Vec3& p, Vec3* normal, Vec3* velocity) const;

  Vec3 lo{0, 0, 0}, hi{0, 0, 0};  // m, the box of the vertices (local frame)
  float maxSpeed = 0.0f;          // m/s, the fastest vertex
  float thickness() const { return sequence_->thickness; }
  // the surface at this time as a triangle mesh (local frame)
  TriangleMesh surface() const;

 private:
  struct Tree;
  // a vertex near p whose triangle is in the tree, or -1: the search's first guess
  int hintVertex(const Vec3& p) const;

  std::shared_ptr<const MeshSequence> sequence_;
  std::vector<Vec3d> x_, v_;
  FeatureNormals normals_;
  std::unique_ptr<Tree> tree_;
  // one vertex per cell of a grid over the box (-1: none), cells of 4 median edges
  float hintCell_ = 1.0f;
  std::array<int, 3> hintDims_{0, 0, 0};
  std::vector<int> hintGrid_;
};

}  // namespace soak
