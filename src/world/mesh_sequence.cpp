// animated mesh colliders (mesh_sequence.hpp): loading an OBJ sequence, checking its topology, and
// the exact signed distance to its interpolated surface through a CGAL AABB tree
#include "world/mesh_sequence.hpp"

#include <soak/error.hpp>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace soak {

namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using KernelTriangles = std::vector<Kernel::Triangle_3>;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, KernelTriangles::const_iterator>;
using AabbTree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

Kernel::Point_3 point(const Vec3d& x) { return {x.x(), x.y(), x.z()}; }

// frame f's topology against the sequence's (frame 0's as its file had it); throws naming its file
void checkSameTopology(const MeshSequence& s, const TriangleMesh& frame, const std::string& name, size_t f) {
  const std::string where = fmt::format("mesh sequence, frame {}", f);
  if (frame.vertices.size() != size_t(s.vertexCount))
    throw errorAt(name, where,
                  fmt::format("expected {} vertices as in the first frame, got {} (every frame must have the same "
                              "topology: export the animation without changing the mesh)",
                              s.vertexCount, frame.vertices.size()));
  if (frame.triangles.size() != s.triangles.size())
    throw errorAt(name, where,
                  fmt::format("expected {} triangles as in the first frame, got {}", s.triangles.size(),
                              frame.triangles.size()));
  for (size_t t = 0; t < frame.triangles.size(); ++t) {
    std::array<int, 3> first = s.triangles[t];
    if (s.flipped) std::swap(first[1], first[2]);
    if (frame.triangles[t] != first)
      throw errorAt(name, fmt::format("{}, triangle {}", where, t),
                    fmt::format("expected vertices ({}, {}, {}) as in the first frame, got ({}, {}, {})", first[0] + 1,
                                first[1] + 1, first[2] + 1, frame.triangles[t][0] + 1, frame.triangles[t][1] + 1,
                                frame.triangles[t][2] + 1));
  }
}

// frame f's positions appended, after checking its topology and its numbers
void appendFrame(MeshSequence& s, const TriangleMesh& frame, const std::string& name, size_t f) {
  if (f > 0) checkSameTopology(s, frame, name, f);
  for (size_t v = 0; v < frame.vertices.size(); ++v) {
    if (!frame.vertices[v].allFinite())
      throw errorAt(name, fmt::format("mesh sequence, frame {}, vertex {}", f, v + 1), "position is not finite");
    s.positions.push_back(frame.vertices[v]);
  }
  ++s.frameCount;
}

float medianEdgeLength(const MeshSequence& s) {
  std::vector<float> lengths;
  lengths.reserve(3 * s.triangles.size());
  for (const auto& t : s.triangles)
    for (int k = 0; k < 3; ++k) lengths.push_back((s.positions[t[(k + 1) % 3]] - s.positions[t[k]]).norm());
  auto mid = lengths.begin() + lengths.size() / 2;
  std::nth_element(lengths.begin(), mid, lengths.end());
  return *mid;
}

// the barycentric weights of q (on triangle a, b, c) for interpolating a vertex quantity
Vec3d barycentric(const Vec3d& q, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const Vec3d e0 = b - a, e1 = c - a, r = q - a;
  const double d00 = e0.dot(e0), d01 = e0.dot(e1), d11 = e1.dot(e1), d20 = r.dot(e0), d21 = r.dot(e1);
  const double den = d00 * d11 - d01 * d01;
  if (!(den > 0.0)) return Vec3d(1.0, 0.0, 0.0);
  const double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
  return Vec3d(1.0 - v - w, v, w);
}

}  // namespace

namespace {

// a sequence of frame 0 alone: its triangles checked (closed, oriented, none degenerate) and turned
// outward, its search data; the later frames are appended
MeshSequence startSequence(const TriangleMesh& frame, const std::string& name, double fps, double start) {
  if (!(fps > 0.0) || !std::isfinite(fps))
    throw errorAt(name, "mesh sequence", fmt::format("expected fps > 0, got {}", fps));
  MeshSequence s;
  s.fps = fps;
  s.start = start;
  s.vertexCount = static_cast<int>(frame.vertices.size());
  s.triangles = frame.triangles;
  if (s.triangles.empty()) throw errorAt(name, "mesh sequence", "the first frame has no triangles");
  for (size_t t = 0; t < s.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k)
      if (s.triangles[t][k] < 0 || s.triangles[t][k] >= s.vertexCount)
        throw errorAt(name, fmt::format("mesh sequence, triangle {}", t),
                      fmt::format("vertex index {} is out of range [1, {}]", s.triangles[t][k] + 1, s.vertexCount));
  appendFrame(s, frame, name, 0);
  s.twin = twinTriangles(s.triangles, name);
  // outward by frame 0; a closed mesh keeps its orientation through a motion that does not turn it inside out
  std::vector<Vec3d> x0(size_t(s.vertexCount));
  for (size_t v = 0; v < x0.size(); ++v) x0[v] = s.positions[v].cast<double>();
  s.flipped = signedVolume(x0, s.triangles) < 0.0;
  if (s.flipped)
    for (auto& t : s.triangles) std::swap(t[1], t[2]);
  FeatureNormals n0;
  featureNormals(x0, s.triangles, s.twin, n0);
  for (size_t t = 0; t < s.triangles.size(); ++t)
    if (!(n0.face[t].squaredNorm() > 0.0))
      throw errorAt(name, fmt::format("mesh sequence, frame 0, triangle {}", t), "degenerate triangle (zero area)");
  s.thickness = medianEdgeLength(s);
  s.vertexTriangle.assign(size_t(s.vertexCount), -1);
  for (size_t t = 0; t < s.triangles.size(); ++t)
    for (int v : s.triangles[t]) s.vertexTriangle[size_t(v)] = static_cast<int>(t);
  return s;
}

}  // namespace

MeshSequence makeMeshSequence(const std::vector<TriangleMesh>& frames, const std::vector<std::string>& names,
                              double fps, double start) {
  const auto nameOf = [&](size_t f) { return f < names.size() ? names[f] : fmt::format("frame {}", f); };
  if (frames.empty()) throw errorAt(nameOf(0), "mesh sequence", "expected at least one frame");
  MeshSequence s = startSequence(frames[0], nameOf(0), fps, start);
  s.positions.reserve(size_t(s.vertexCount) * frames.size());
  for (size_t f = 1; f < frames.size(); ++f) appendFrame(s, frames[f], nameOf(f), f);
  return s;
}

namespace {

// the run of '#' in the pattern's file name: [begin, end) in the whole pattern
std::pair<size_t, size_t> hashRun(const std::string& pattern) {
  const size_t slash = pattern.find_last_of('/');
  const size_t nameStart = slash == std::string::npos ? 0 : slash + 1;
  const size_t b = pattern.find('#', nameStart);
  if (b == std::string::npos)
    throw errorAt(pattern, "mesh sequence path",
                  "expected one run of '#' in the file name standing for the frame number (body_####.obj)");
  size_t e = b;
  while (e < pattern.size() && pattern[e] == '#') ++e;
  if (pattern.find('#', e) != std::string::npos)
    throw errorAt(pattern, "mesh sequence path", "expected one run of '#' in the file name, got several");
  return {b, e};
}

std::string framePath(const std::string& pattern, std::pair<size_t, size_t> run, int frame) {
  return pattern.substr(0, run.first) + fmt::format("{:0{}d}", frame, run.second - run.first) +
         pattern.substr(run.second);
}

// the lowest frame number whose file exists, -1 if none
int lowestFrame(const std::string& pattern, std::pair<size_t, size_t> run) {
  const std::filesystem::path dir = std::filesystem::path(pattern.substr(0, run.first)).parent_path();
  const size_t nameStart = dir.empty() ? 0 : pattern.find_last_of('/') + 1;
  const std::string prefix = pattern.substr(nameStart, run.first - nameStart), suffix = pattern.substr(run.second);
  std::error_code ec;
  int lowest = -1;
  for (const auto& entry : std::filesystem::directory_iterator(dir.empty() ? "." : dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.size() <= prefix.size() + suffix.size() || name.compare(0, prefix.size(), prefix) != 0 ||
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    const std::string digits = name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
    if (digits.size() > 9 || !std::all_of(digits.begin(), digits.end(), [](char ch) { return ch >= '0' && ch <= '9'; }))
      continue;
    const int frame = std::stoi(digits);
    // the name the pattern gives that frame (its padding), so "body_1.obj" is not taken for "body_0001.obj"
    if (framePath(pattern, run, frame).substr(nameStart) != name) continue;
    if (lowest < 0 || frame < lowest) lowest = frame;
  }
  return lowest;
}

}  // namespace

std::vector<std::string> meshSequenceFiles(const std::string& pattern, int first, int last, int* firstFound) {
  const auto run = hashRun(pattern);
  if (first < 0) first = lowestFrame(pattern, run);
  if (first < 0)
    throw errorAt(pattern, "mesh sequence path",
                  fmt::format("expected files named by the pattern, found none (the first would be \"{}\")",
                              framePath(pattern, run, 1)));
  if (last >= 0 && last < first)
    throw errorAt(pattern, "mesh sequence", fmt::format("expected lastFrame >= firstFrame ({}), got {}", first, last));
  std::vector<std::string> files;
  std::error_code ec;
  for (int f = first; last < 0 || f <= last; ++f) {
    const std::string path = framePath(pattern, run, f);
    if (!std::filesystem::is_regular_file(path, ec)) {
      if (last >= 0 || f == first)
        throw errorAt(path, "mesh sequence", fmt::format("expected frame {} of the sequence, the file does not exist", f));
      break;
    }
    files.push_back(path);
  }
  if (firstFound) *firstFound = first;
  return files;
}

MeshSequence loadMeshSequence(const std::vector<std::string>& files, double fps, double start, float scale) {
  if (files.empty()) throw errorAt("", "mesh sequence", "expected at least one frame file");
  if (!(scale > 0.0f) || !std::isfinite(scale))
    throw errorAt(files[0], "mesh sequence", fmt::format("expected a scale > 0, got {}", scale));
  // one frame in memory at a time, checked as it is read
  const auto read = [&](size_t f) {
    TriangleMesh m = loadObjMesh(files[f]);
    for (Vec3& x : m.vertices) x *= scale;
    return m;
  };
  const TriangleMesh first = read(0);
  if (int64_t(first.vertices.size()) * int64_t(files.size()) > kMaxSequencePositions)
    throw errorAt(files[0], "mesh sequence",
                  fmt::format("{} frames of {} vertices are more than {} positions; use fewer frames or a coarser mesh",
                              files.size(), first.vertices.size(), kMaxSequencePositions));
  MeshSequence s = startSequence(first, files[0], fps, start);
  s.positions.reserve(first.vertices.size() * files.size());
  for (size_t f = 1; f < files.size(); ++f) appendFrame(s, read(f), files[f], f);
  return s;
}

struct MeshSnapshot::Tree {
  KernelTriangles triangles;  // the non-degenerate triangles at this time
  std::vector<int> ids;       // their index in the sequence
  std::vector<int> slot;      // per sequence triangle: its index in `triangles`, -1 when degenerate
  AabbTree tree;
};

namespace {

constexpr int64_t kMaxHintCells = int64_t(1) << 21;
// rings of cells searched for a hint: a point farther than about that many cells from every vertex
// (a drop in the air between the arms) takes CGAL's own hint, whose k-d tree is built on first use
constexpr int kHintRings = 4;

}  // namespace

MeshSnapshot::MeshSnapshot(std::shared_ptr<const MeshSequence> sequence, double t)
    : sequence_(std::move(sequence)), tree_(std::make_unique<Tree>()) {
  const MeshSequence& s = *sequence_;
  const int nv = s.vertexCount;
  const double u = (t - s.start) * s.fps;
  const int last = s.frameCount - 1;
  // frame f's segment holds u in [f, f + 1), so frame 0 already moves with its segment (as keyframes do)
  const bool playing = u >= 0.0 && u < last;
  const int f = u <= 0.0 ? 0 : (u >= last ? last : static_cast<int>(std::floor(u)));
  const double w = playing ? u - f : 0.0;
  const int g = std::min(f + 1, last);
  x_.resize(nv);
  v_.assign(nv, Vec3d::Zero());
  for (int v = 0; v < nv; ++v) {
    const Vec3d a = s.positions[size_t(f) * nv + v].cast<double>(), b = s.positions[size_t(g) * nv + v].cast<double>();
    x_[v] = a + w * (b - a);
    if (playing) v_[v] = (b - a) * s.fps;
  }
  featureNormals(x_, s.triangles, s.twin, normals_);
  lo = hi = x_.empty() ? Vec3::Zero() : Vec3(x_[0].cast<float>());
  for (int v = 0; v < nv; ++v) {
    lo = lo.cwiseMin(x_[v].cast<float>());
    hi = hi.cwiseMax(x_[v].cast<float>());
    maxSpeed = std::max(maxSpeed, static_cast<float>(v_[v].norm()));
  }
  tree_->slot.assign(s.triangles.size(), -1);
  for (size_t k = 0; k < s.triangles.size(); ++k) {
    if (!(normals_.face[k].squaredNorm() > 0.0)) continue;  // a collapsed triangle: its neighbours hold its points
    const auto& tri = s.triangles[k];
    tree_->slot[k] = static_cast<int>(tree_->triangles.size());
    tree_->triangles.emplace_back(point(x_[tri[0]]), point(x_[tri[1]]), point(x_[tri[2]]));
    tree_->ids.push_back(static_cast<int>(k));
  }
  tree_->tree.rebuild(tree_->triangles.cbegin(), tree_->triangles.cend());
  // a query with no vertex near it falls back on CGAL's own hint (a k-d tree it builds, thread-safe,
  // on the first such query); the grid's hints are cheaper to make than that tree and as good
  hintCell_ = std::max(4.0f * s.thickness, 1e-4f);
  int64_t cells = 1;
  for (int a = 0; a < 3; ++a) {
    hintDims_[a] = static_cast<int>(std::min((hi[a] - lo[a]) / hintCell_, 4096.0f)) + 1;
    cells *= hintDims_[a];
  }
  if (cells > kMaxHintCells) return;  // no grid: every query takes CGAL's hint
  hintGrid_.assign(size_t(cells), -1);
  for (int v = 0; v < nv; ++v) {
    const int t = s.vertexTriangle[size_t(v)];
    if (t < 0 || tree_->slot[size_t(t)] < 0) continue;
    int64_t c = 0;
    for (int a = 2; a >= 0; --a)
      c = c * hintDims_[a] + std::clamp(static_cast<int>((float(x_[v][a]) - lo[a]) / hintCell_), 0, hintDims_[a] - 1);
    hintGrid_[size_t(c)] = v;
  }
}

int MeshSnapshot::hintVertex(const Vec3& p) const {
  if (hintGrid_.empty()) return -1;
  std::array<int, 3> cell;
  for (int a = 0; a < 3; ++a) {
    cell[a] = static_cast<int>(std::floor((p[a] - lo[a]) / hintCell_));
    if (cell[a] < -kHintRings || cell[a] >= hintDims_[a] + kHintRings) return -1;  // far outside the box
  }
  // the point's cell, then the rings of cells around it (a ring's inside was searched before it)
  for (int ring = 0; ring <= kHintRings; ++ring)
    for (int dz = -ring; dz <= ring; ++dz)
      for (int dy = -ring; dy <= ring; ++dy)
        for (int dx = -ring; dx <= ring; ++dx) {
          if (std::max({std::abs(dx), std::abs(dy), std::abs(dz)}) != ring) continue;
          const int i = cell[0] + dx, j = cell[1] + dy, k = cell[2] + dz;
          if (i < 0 || j < 0 || k < 0 || i >= hintDims_[0] || j >= hintDims_[1] || k >= hintDims_[2]) continue;
          const int v = hintGrid_[size_t(i + int64_t(hintDims_[0]) * (j + int64_t(hintDims_[1]) * k))];
          if (v >= 0) return v;
        }
  return -1;
}

MeshSnapshot::~MeshSnapshot() = default;

float MeshSnapshot::distance(const Vec3& p, Vec3* normal, Vec3* velocity) const {
  if (tree_->triangles.empty()) {
    if (normal) *normal = Vec3(0, 1, 0);
    if (velocity) *velocity = Vec3::Zero();
    return 1.0e30f;
  }
  const Vec3d pd = p.cast<double>();
  const int hv = hintVertex(p);
  const auto hit = hv < 0 ? tree_->tree.closest_point_and_primitive(point(pd))
                          : tree_->tree.closest_point_and_primitive(
                                point(pd), {point(x_[size_t(hv)]),
                                            tree_->triangles.cbegin() +
                                                tree_->slot[size_t(sequence_->vertexTriangle[size_t(hv)])]});
  const int t = tree_->ids[size_t(hit.second - tree_->triangles.cbegin())];
  NearestOnMesh best;
  nearerTriangle(x_, sequence_->triangles, normals_, t, pd, best);
  const double dist = std::sqrt(best.dist2);
  if (normal) {
    const Vec3d n = dist > 1e-9 ? Vec3d(best.sign * (pd - best.point) / dist) : best.pseudoNormal.normalized();
    *normal = n.squaredNorm() > 0.0 ? Vec3(n.cast<float>()) : Vec3(0, 1, 0);
  }
  if (velocity) {
    const auto& tri = sequence_->triangles[t];
    const Vec3d b = barycentric(best.point, x_[tri[0]], x_[tri[1]], x_[tri[2]]);
    *velocity = (b[0] * v_[tri[0]] + b[1] * v_[tri[1]] + b[2] * v_[tri[2]]).cast<float>();
  }
  return static_cast<float>(best.sign * dist);
}

TriangleMesh MeshSnapshot::surface() const {
  TriangleMesh m;
  m.vertices.reserve(x_.size());
  for (const Vec3d& x : x_) m.vertices.push_back(x.cast<float>());
  m.triangles = sequence_->triangles;
  return m;
}

}  // namespace soak
