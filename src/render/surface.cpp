// water surface: particles -> narrow-band level set -> smoothed, eroded -> triangle mesh (OpenVDB)
#include "render/surface.hpp"

#include "world/colliders.hpp"

#include <fmt/format.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetFilter.h>
#include <openvdb/tools/ParticlesToLevelSet.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <soak/error.hpp>

#include "io/file.hpp"
#include "world/mesh_sdf.hpp"

namespace soak {

struct WaterLevelSet::Impl {
  openvdb::FloatGrid::Ptr grid;
  float voxelSize = 0.0f;
  size_t drops = 0;
};

WaterLevelSet::WaterLevelSet(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
WaterLevelSet::~WaterLevelSet() = default;
WaterLevelSet::WaterLevelSet(WaterLevelSet&&) noexcept = default;
WaterLevelSet& WaterLevelSet::operator=(WaterLevelSet&&) noexcept = default;
float WaterLevelSet::voxelSize() const { return impl_->voxelSize; }
size_t WaterLevelSet::activeVoxels() const { return impl_->grid->activeVoxelCount(); }
size_t WaterLevelSet::dropParticles() const { return impl_->drops; }

namespace {

void initOpenVdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

// the particle list interface ParticlesToLevelSet reads (positions and ball radii, world units)
struct BallList {
  using PosType = openvdb::Vec3R;
  std::vector<openvdb::Vec3R> position;
  std::vector<openvdb::Real> radius;
  size_t size() const { return position.size(); }
  void getPos(size_t n, openvdb::Vec3R& p) const { p = position[n]; }
  void getPosRad(size_t n, openvdb::Vec3R& p, openvdb::Real& r) const {
    p = position[n];
    r = radius[n];
  }
};

float median(std::span<const float> values) {
  std::vector<float> v(values.begin(), values.end());
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

void checkSettings(const SurfaceSettings& s) {
  if (!(s.voxelSize >= 0.0f)) throw Error(fmt::format("water surface: voxel size must be >= 0 m, got {}", s.voxelSize));
  if (!(s.radiusFraction > 0.0f))
    throw Error(fmt::format("water surface: radius fraction must be > 0, got {}", s.radiusFraction));
  if (!(s.erosionFraction >= 0.0f) || s.erosionFraction >= s.radiusFraction)
    throw Error(fmt::format("water surface: erosion fraction must be in [0, radius fraction {}), got {}",
                            s.radiusFraction, s.erosionFraction));
  if (s.smoothingIterations < 0)
    throw Error(fmt::format("water surface: smoothing iterations must be >= 0, got {}", s.smoothingIterations));
  if (!(s.dropFraction >= 0.0f))
    throw Error(fmt::format("water surface: drop fraction must be >= 0, got {}", s.dropFraction));
  if (!(s.halfWidth >= 2.0f))
    throw Error(fmt::format("water surface: half width must be >= 2 voxels, got {}", s.halfWidth));
}

std::vector<Vec3> vertexNormals(const SurfaceMesh& m) {
  std::vector<Vec3> n(m.vertices.size(), Vec3::Zero());
  for (const auto& t : m.triangles) {
    // the unnormalised cross product weights each face by its area
    const Vec3 f = (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]);
    for (int k = 0; k < 3; ++k) n[t[k]] += f;
  }
  for (Vec3& v : n) {
    const float len = v.norm();
    v = len > 0.0f ? Vec3(v / len) : Vec3::Zero();
  }
  return n;
}

}  // namespace

WaterLevelSet waterLevelSet(std::span<const Vec3> x, std::span<const float> h, const SurfaceSettings& settings) {
  if (x.size() != h.size()) throw Error(fmt::format("water surface: {} positions but {} radii", x.size(), h.size()));
  checkSettings(settings);
  initOpenVdb();
  const float hMedian = h.empty() ? 0.04f : median(h);
  if (!(hMedian > 0.0f)) throw Error(fmt::format("water surface: median particle radius is {} m", hMedian));
  auto impl = std::make_unique<WaterLevelSet::Impl>();
  impl->voxelSize = settings.voxelSize > 0.0f ? settings.voxelSize : hMedian / 6.0f;
  const double dx = impl->voxelSize;
  openvdb::FloatGrid::Ptr grid = openvdb::createLevelSet<openvdb::FloatGrid>(dx, settings.halfWidth);
  grid->setName("surface");
  impl->grid = grid;
  if (x.empty()) return WaterLevelSet(std::move(impl));

  // balls of particles [ids] of radius fraction * h_i, at least 1.5 voxels, unioned into the grid
  const double rMin = 1.5 * dx;
  auto rasterize = [&](const std::vector<size_t>& ids, float fraction) {
    BallList balls;
    balls.position.reserve(ids.size());
    balls.radius.reserve(ids.size());
    for (size_t i : ids) {
      balls.position.emplace_back(x[i].x(), x[i].y(), x[i].z());
      balls.radius.push_back(std::max(rMin, static_cast<double>(fraction) * h[i]));
    }
    openvdb::tools::ParticlesToLevelSet<openvdb::FloatGrid> raster(*grid);
    raster.setRmin(1.0);  // rMin above already keeps every ball at 1.5 voxels or more
    raster.setRmax(1.0e6);
    raster.rasterizeSpheres(balls);
    raster.finalize(true);
  };
  std::vector<size_t> all(x.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  rasterize(all, settings.radiusFraction);

  openvdb::tools::LevelSetFilter<openvdb::FloatGrid> filter(*grid);
  for (int k = 0; k < settings.smoothingIterations; ++k) filter.gaussian(1);
  // a positive offset raises phi, moving the zero level set inwards
  const float erosion = settings.erosionFraction * hMedian;
  if (erosion > 0.0f) filter.offset(erosion);

  // lone particles lost (most of) their ball to the smoothing: their centres now lie outside or just
  // inside; a particle of the bulk (edges included) lies deeper than a quarter of its drop radius
  std::vector<size_t> drops;
  if (settings.dropFraction > 0.0f) {
    const openvdb::FloatGrid::ConstAccessor acc = grid->getConstAccessor();
    const openvdb::math::Transform& xf = grid->transform();
    for (size_t i = 0; i < x.size(); ++i) {
      const openvdb::Coord c = xf.worldToIndexNodeCentered(openvdb::Vec3d(x[i].x(), x[i].y(), x[i].z()));
      const double r = std::max(rMin, static_cast<double>(settings.dropFraction) * h[i]);
      if (acc.getValue(c) > -0.25 * r) drops.push_back(i);
    }
    if (!drops.empty()) rasterize(drops, settings.dropFraction);
  }
  impl->drops = drops.size();
  return WaterLevelSet(std::move(impl));
}

namespace {

SurfaceMesh meshGrid(const openvdb::FloatGrid& grid) {
  SurfaceMesh mesh;
  if (grid.activeVoxelCount() == 0) return mesh;
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> tris;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(grid, points, tris, quads, 0.0, 0.0);
  mesh.vertices.reserve(points.size());
  for (const auto& p : points) mesh.vertices.emplace_back(p.x(), p.y(), p.z());
  mesh.triangles.reserve(tris.size() + 2 * quads.size());
  for (const auto& t : tris) mesh.triangles.push_back({int(t[0]), int(t[1]), int(t[2])});
  for (const auto& q : quads) {
    mesh.triangles.push_back({int(q[0]), int(q[1]), int(q[2])});
    mesh.triangles.push_back({int(q[0]), int(q[2]), int(q[3])});
  }
  // volumeToMesh winds its polygons inwards; the writers promise outward-facing triangles
  if (enclosedVolume(mesh) < 0.0)
    for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
  mesh.normals = vertexNormals(mesh);
  return mesh;
}

}  // namespace

SurfaceMesh levelSetMesh(const WaterLevelSet& levelSet) { return meshGrid(*levelSet.impl().grid); }

SurfaceMesh sdfGridMesh(const SdfGrid& sdf) {
  initOpenVdb();
  const auto [nx, ny, nz] = sdf.dims;
  if (nx < 2 || ny < 2 || nz < 2 || sdf.value.size() != size_t(nx) * size_t(ny) * size_t(nz)) return {};
  // node (i, j, k) of the grid is voxel (i, j, k): a voxel-centred transform placed at the origin node
  const float band = 3.0f * sdf.cellSize;
  openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(band);
  openvdb::math::Transform::Ptr xf = openvdb::math::Transform::createLinearTransform(sdf.cellSize);
  xf->postTranslate(openvdb::Vec3d(sdf.origin.x(), sdf.origin.y(), sdf.origin.z()));
  grid->setTransform(xf);
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  openvdb::FloatGrid::Accessor acc = grid->getAccessor();
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const float v = sdf.value[size_t(i) + size_t(nx) * (size_t(j) + size_t(ny) * size_t(k))];
        if (std::abs(v) < band) acc.setValue(openvdb::Coord(i, j, k), v);
      }
  // the inside, beyond the band, must read as negative for the mesher
  openvdb::tools::signedFloodFill(grid->tree());
  return meshGrid(*grid);
}

SurfaceMesh colliderSurfaceMesh(const Collider& c, const ColliderPose& pose, const Vec3& lo, const Vec3& hi,
                                float cellSize) {
  SdfGrid sdf;
  sdf.cellSize = cellSize;
  sdf.origin = lo - Vec3::Constant(2.0f * cellSize);
  int64_t nodes = 1;
  for (int a = 0; a < 3; ++a) {
    const float cells = std::ceil((hi[a] - lo[a]) / cellSize) + 4.0f;
    if (!(cells >= 1.0f && cells < 4096.0f)) return {};
    sdf.dims[a] = int(cells) + 1;
    nodes *= sdf.dims[a];
  }
  if (nodes > kMaxSdfNodes) return {};
  std::vector<float> points(size_t(3 * nodes));
  for (int64_t n = 0; n < nodes; ++n) {
    const int64_t i = n % sdf.dims[0], j = (n / sdf.dims[0]) % sdf.dims[1];
    const int64_t k = n / (int64_t(sdf.dims[0]) * sdf.dims[1]);
    const Vec3 x = sdf.origin + cellSize * Vec3(float(i), float(j), float(k));
    std::copy(x.data(), x.data() + 3, points.begin() + 3 * n);
  }
  sdf.value.assign(size_t(nodes), std::numeric_limits<float>::max());
  colliderDistanceBounds(c, pose, points.data(), nodes, sdf.value.data());
  for (float& v : sdf.value) v += kDistanceBoundSlack;  // the bound is the distance less this slack
  return sdfGridMesh(sdf);
}

double enclosedVolume(const SurfaceMesh& mesh) {
  // sum of the signed volumes of the tetrahedra (origin, a, b, c)
  double v = 0.0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>(), b = mesh.vertices[t[1]].cast<double>(),
                          c = mesh.vertices[t[2]].cast<double>();
    v += a.dot(b.cross(c));
  }
  return v / 6.0;
}

void writeLevelSetVdb(const std::string& path, const WaterLevelSet& levelSet, int frame, double time) {
  openvdb::FloatGrid::Ptr grid = levelSet.impl().grid->deepCopy();
  grid->insertMeta("frame", openvdb::Int32Metadata(frame));
  grid->insertMeta("time", openvdb::DoubleMetadata(time));
  grid->insertMeta("units", openvdb::StringMetadata("m, y up"));
  initOpenVdb();
  try {
    openvdb::io::File file(path);
    file.write({grid});
    file.close();
  } catch (const openvdb::Exception& e) {
    throw Error(path + ": cannot write the VDB file: " + e.what());
  }
}

VdbSummary readLevelSetVdb(const std::string& path) {
  initOpenVdb();
  VdbSummary s;
  try {
    openvdb::io::File file(path);
    file.open();
    if (!file.hasGrid("surface")) throw Error(path + ": no grid named 'surface' in the VDB file");
    openvdb::GridBase::Ptr grid = file.readGrid("surface");
    file.close();
    s.levelSet = grid->getGridClass() == openvdb::GRID_LEVEL_SET;
    s.activeVoxels = grid->activeVoxelCount();
    s.voxelSize = static_cast<float>(grid->voxelSize()[0]);
    if (grid->getMetadata<openvdb::Int32Metadata>("frame")) s.frame = grid->metaValue<int32_t>("frame");
    if (grid->getMetadata<openvdb::DoubleMetadata>("time")) s.time = grid->metaValue<double>("time");
  } catch (const openvdb::Exception& e) {
    throw Error(path + ": cannot read the VDB file: " + e.what());
  }
  return s;
}

void writeSurfaceObj(const std::string& path, const SurfaceMesh& mesh) {
  std::string text = fmt::format("# soak water surface: {} vertices, {} triangles (m, y up)\n", mesh.vertices.size(),
                                 mesh.triangles.size());
  text.reserve(text.size() + 40 * (2 * mesh.vertices.size() + mesh.triangles.size()));
  for (const Vec3& v : mesh.vertices) text += fmt::format("v {} {} {}\n", v.x(), v.y(), v.z());
  for (const Vec3& n : mesh.normals) text += fmt::format("vn {} {} {}\n", n.x(), n.y(), n.z());
  for (const auto& t : mesh.triangles)
    text += fmt::format("f {0}//{0} {1}//{1} {2}//{2}\n", t[0] + 1, t[1] + 1, t[2] + 1);
  writeTextFile(path, text);
}

void writeSurfacePly(const std::string& path, const SurfaceMesh& mesh) {
  AtomicFile file(path);
  std::ofstream& out = file.out();
  out << "ply\nformat binary_little_endian 1.0\ncomment soak water surface, SI units (m), y up\n"
      << "element vertex " << mesh.vertices.size() << "\n"
      << "property float x\nproperty float y\nproperty float z\n"
      << "property float nx\nproperty float ny\nproperty float nz\n"
      << "element face " << mesh.triangles.size() << "\nproperty list uchar int vertex_indices\nend_header\n";
  std::vector<char> buf;
  buf.reserve(24 * mesh.vertices.size() + 13 * mesh.triangles.size());
  auto put = [&buf](const void* p, size_t n) {
    const char* c = static_cast<const char*>(p);
    buf.insert(buf.end(), c, c + n);
  };
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vec3 n = i < mesh.normals.size() ? mesh.normals[i] : Vec3::Zero();
    const float v[6] = {mesh.vertices[i].x(), mesh.vertices[i].y(), mesh.vertices[i].z(), n.x(), n.y(), n.z()};
    put(v, sizeof v);
  }
  for (const auto& t : mesh.triangles) {
    const uint8_t three = 3;
    const int32_t ids[3] = {t[0], t[1], t[2]};
    put(&three, 1);
    put(ids, sizeof ids);
  }
  out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
  file.commit();
}

}  // namespace soak
