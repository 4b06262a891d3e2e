// the water surface (OpenVDB level set and mesh) against the volume of the particles it wraps
#include "render/surface.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <soak/error.hpp>

#include "io/ply.hpp"
#include "world/mesh_sdf.hpp"

namespace soak {
namespace {

namespace fs = std::filesystem;

// Table 1 water: spacing r0 = 0.02 m, support radius h = 0.04 m, mass 0.0082 kg, rho0 = 1000 kg/m^3
constexpr float kSpacing = 0.02f, kSupport = 0.04f, kMass = 0.0082f, kRestDensity = 1000.0f;

struct Block {
  std::vector<Vec3> x;
  std::vector<float> h;
};

// an n x m x k block of particles resting on a lattice of spacing r0, first site at `corner`
Block lattice(int n, int m, int k, const Vec3& corner) {
  Block b;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j)
      for (int l = 0; l < k; ++l) {
        b.x.push_back(corner + kSpacing * Vec3(float(i), float(j), float(l)));
        b.h.push_back(kSupport);
      }
  return b;
}

// every edge of a closed, consistently oriented mesh is used once in each direction
bool closedAndOriented(const SurfaceMesh& m) {
  std::map<std::pair<int, int>, int> count;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) ++count[{t[k], t[(k + 1) % 3]}];
  for (const auto& [e, c] : count)
    if (c != 1 || count.count({e.second, e.first}) == 0 || count.at({e.second, e.first}) != 1) return false;
  return true;
}

TEST(SurfaceVolume, RestingBlockEnclosesTheParticlesVolume) {
  const Block b = lattice(12, 8, 10, Vec3(0.1f, 0.3f, -0.2f));
  const double particleVolume = static_cast<double>(b.x.size()) * kMass / kRestDensity;
  const WaterLevelSet ls = waterLevelSet(b.x, b.h, SurfaceSettings{});
  EXPECT_FLOAT_EQ(ls.voxelSize(), kSupport / 6.0f);
  // only particles at the block's corners sit close enough to the rounded surface to get a drop ball
  EXPECT_LT(ls.dropParticles(), b.x.size() / 20);
  const SurfaceMesh mesh = levelSetMesh(ls);
  ASSERT_GT(mesh.triangles.size(), 100u);
  const double v = enclosedVolume(mesh);
  EXPECT_NEAR(v / particleVolume, 1.0, 0.10) << "mesh " << v << " m^3, particles " << particleVolume << " m^3";
  EXPECT_TRUE(closedAndOriented(mesh));
  // the surface lies about half a spacing outside the outer particles (a box of 12 x 8 x 10 cells)
  Vec3 lo = mesh.vertices[0], hi = mesh.vertices[0];
  for (const Vec3& p : mesh.vertices) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Vec3 size = hi - lo;
  EXPECT_NEAR(size.x(), 12 * kSpacing, 0.6 * kSpacing);
  EXPECT_NEAR(size.y(), 8 * kSpacing, 0.6 * kSpacing);
  EXPECT_NEAR(size.z(), 10 * kSpacing, 0.6 * kSpacing);
}

TEST(SurfaceVolume, NormalsPointOutOfTheWater) {
  const Block b = lattice(6, 6, 6, Vec3(0, 0, 0));
  const SurfaceMesh mesh = levelSetMesh(waterLevelSet(b.x, b.h, SurfaceSettings{}));
  ASSERT_FALSE(mesh.vertices.empty());
  const Vec3 centre(2.5f * kSpacing, 2.5f * kSpacing, 2.5f * kSpacing);
  int outward = 0;
  for (size_t i = 0; i < mesh.vertices.size(); ++i) outward += mesh.normals[i].dot(mesh.vertices[i] - centre) > 0.0f;
  EXPECT_EQ(outward, static_cast<int>(mesh.vertices.size()));
  EXPECT_GT(enclosedVolume(mesh), 0.0);
}

TEST(SurfaceVolume, TwoBlocksApartGiveTwoSeparateVolumes) {
  Block a = lattice(6, 6, 6, Vec3(0, 0, 0));
  const Block b = lattice(6, 6, 6, Vec3(0.4f, 0, 0));
  const double one = enclosedVolume(levelSetMesh(waterLevelSet(a.x, a.h, SurfaceSettings{})));
  a.x.insert(a.x.end(), b.x.begin(), b.x.end());
  a.h.insert(a.h.end(), b.h.begin(), b.h.end());
  const double two = enclosedVolume(levelSetMesh(waterLevelSet(a.x, a.h, SurfaceSettings{})));
  EXPECT_NEAR(two / one, 2.0, 0.01);
}

TEST(SurfaceVolume, LoneDropsStayAsBallsOfTheirVolume) {
  // the smoothing would erase a lone particle: it comes back as a ball of the radius of its volume
  const std::vector<Vec3> x = {Vec3(0, 0, 0), Vec3(0.3f, 0, 0)};
  const std::vector<float> h = {kSupport, 0.5f * kSupport};
  const WaterLevelSet ls = waterLevelSet(x, h, SurfaceSettings{});
  EXPECT_EQ(ls.dropParticles(), 2u);
  const SurfaceMesh mesh = levelSetMesh(ls);
  const double r = 0.3125 * kSupport;  // 0.0125 m: (3 m / (4 pi rho0))^(1/3) for m = 0.0082 kg
  const double sphere = 4.0 / 3.0 * M_PI * r * r * r;
  EXPECT_NEAR(sphere, kMass / kRestDensity, 0.01 * sphere);
  double big = 0.0, small = 0.0;
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vec3& p = mesh.vertices[i];
    if (p.x() < 0.15f)
      big = std::max(big, double(p.norm()));
    else
      small = std::max(small, double((p - x[1]).norm()));
  }
  EXPECT_NEAR(big, r, 0.5 * ls.voxelSize());
  // the half-size drip is 0.00625 m, under 1.5 voxels: enlarged to 1.5 voxels so it shows
  EXPECT_NEAR(small, 1.5 * ls.voxelSize(), 0.5 * ls.voxelSize());
  // a ball under 2 voxels meshes to a coarse polyhedron inside the sphere
  EXPECT_GT(enclosedVolume(mesh), 0.6 * sphere);
  EXPECT_LT(enclosedVolume(mesh), sphere + 4.0 / 3.0 * M_PI * std::pow(1.5 * ls.voxelSize(), 3));
}

TEST(SurfaceVolume, MeshColliderGridIsMeshedWhereItsDistanceIsZero) {
  // a sphere of radius 0.2 m centred at c, sampled on a grid whose node 0 sits at `origin`
  SdfGrid g;
  g.origin = Vec3(-0.5f, 0.1f, -0.3f);
  g.cellSize = 0.02f;
  g.dims = {40, 30, 35};
  const Vec3 c(-0.1f, 0.4f, 0.05f);
  const float r = 0.2f;
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i)
        g.value.push_back((g.origin + g.cellSize * Vec3(float(i), float(j), float(k)) - c).norm() - r);
  const SurfaceMesh mesh = sdfGridMesh(g);
  ASSERT_GT(mesh.triangles.size(), 500u);
  for (const Vec3& p : mesh.vertices) EXPECT_NEAR((p - c).norm(), r, 0.1f * g.cellSize);
  EXPECT_NEAR(enclosedVolume(mesh), 4.0 / 3.0 * M_PI * r * r * r, 0.02 * 4.0 / 3.0 * M_PI * r * r * r);
  EXPECT_TRUE(closedAndOriented(mesh));
}

TEST(SurfaceVolume, NoParticlesGiveAnEmptyMesh) {
  const WaterLevelSet ls = waterLevelSet({}, {}, SurfaceSettings{});
  EXPECT_EQ(ls.activeVoxels(), 0u);
  EXPECT_TRUE(levelSetMesh(ls).triangles.empty());
}

TEST(SurfaceVolume, BadSettingsAreRefused) {
  const Block b = lattice(2, 2, 2, Vec3(0, 0, 0));
  SurfaceSettings s;
  s.erosionFraction = 0.6f;  // more than the ball radius: nothing would be left
  EXPECT_THROW(waterLevelSet(b.x, b.h, s), Error);
  EXPECT_THROW(waterLevelSet(b.x, std::vector<float>(3, kSupport), SurfaceSettings{}), Error);
}

TEST(SurfaceFiles, VdbObjAndPlyHoldTheSurface) {
  const fs::path dir = fs::temp_directory_path() / ("soak_surface_files_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const Block b = lattice(5, 5, 5, Vec3(0, 0, 0));
  const WaterLevelSet ls = waterLevelSet(b.x, b.h, SurfaceSettings{});
  const SurfaceMesh mesh = levelSetMesh(ls);
  writeLevelSetVdb((dir / "s.vdb").string(), ls, 7, 0.21);
  writeSurfaceObj((dir / "s.obj").string(), mesh);
  writeSurfacePly((dir / "s.ply").string(), mesh);

  const VdbSummary vdb = readLevelSetVdb((dir / "s.vdb").string());
  EXPECT_TRUE(vdb.levelSet);
  EXPECT_EQ(vdb.activeVoxels, ls.activeVoxels());
  EXPECT_FLOAT_EQ(vdb.voxelSize, ls.voxelSize());
  EXPECT_EQ(vdb.frame, 7);
  EXPECT_DOUBLE_EQ(vdb.time, 0.21);
  EXPECT_THROW(readLevelSetVdb((dir / "s.obj").string()), Error);

  const PlyData ply = readPly((dir / "s.ply").string());
  EXPECT_EQ(ply.element("vertex").count, mesh.vertices.size());
  EXPECT_EQ(ply.element("face").count, mesh.triangles.size());
  EXPECT_EQ(ply.element("vertex").scalar("y")[3], mesh.vertices[3].y());
  EXPECT_GT(fs::file_size(dir / "s.obj"), 100u);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace soak
