#include "support/run_scene.hpp"

#include "core/kernels.hpp"
#include "grid/grid.hpp"
#include "pbd/boundary.hpp"
#include "pbd/fluid.hpp"
#include "pbd/integrate.hpp"
#include "world/colliders.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

using namespace soak;
using namespace soak::testing;

namespace {
// a 0.2 x 0.3 x 0.2 m column of water (10 x 15 x 10 particles) in an open container; PBF's
// compression grows with g dt^2 / iterations, so the column is stepped at dt / 4 with 6 iterations
const char* kColumn = R"({
  "solver": {"dt": 0.015, "substeps": 4, "fluidIterations": 6, "domain": {"min": [-1, -1, -1], "max": [1, 2, 1]}},
  "colliders": [{"type": "container", "halfExtents": [0.1, 0.3, 0.1], "position": [0, 0.3, 0], "wallThickness": 0.05}],
  "emitters": [{"type": "block", "min": [-0.1, 0.0, -0.1], "max": [0.1, 0.3, 0.1]}]
})";

// SPH density of every particle from its positions, with the collider walls as in the solver
std::vector<float> densities(const Scene& scene) {
  const Particles& p = scene.state.particles;
  NeighborGrid grid;
  NeighborLists nb;
  buildGrid(p.x, 0.04f, grid);
  buildNeighborLists(p.x, p.radius, grid, nb);
  std::vector<ColliderPose> poses;
  for (const Collider& c : scene.model.colliders) poses.push_back(colliderPose(c, scene.state.time));
  std::vector<BoundaryPart> parts;
  boundaryParts(scene.model, poses, parts);
  std::vector<float> rho(p.size());
  for (size_t i = 0; i < p.size(); ++i) {
    float r = p.mass[i] * poly6(0.0f, p.radius[i]);
    for (uint32_t k = nb.start[i]; k < nb.start[i + 1]; ++k) {
      const uint32_t j = nb.index[k];
      r += p.mass[j] * poly6((p.x[i] - p.x[j]).squaredNorm(), pairRadius(p.radius[i], p.radius[j]));
    }
    r += scene.model.water.restDensity * boundaryFraction(parts, p.x[i], WallKernel(p.radius[i]), nullptr);
    rho[i] = r;
  }
  return rho;
}
}  // namespace

TEST(Fluid, HydrostaticColumnKeepsRestDensityAndHeight) {
  Scene scene = sceneFromJson(kColumn);
  runSteps(scene, 150);  // 2.25 s: the column settles
  const Particles& p = scene.state.particles;
  ASSERT_EQ(p.size(), 1500u);
  const float h = scene.model.water.supportRadius;
  // free surface: where the SPH density along the column's axis falls to half the rest density
  // (the usual SPH colour-field surface), found by scanning upwards in 1 mm steps
  auto densityAt = [&](const Vec3& q) {
    double r = 0.0;
    for (size_t j = 0; j < p.size(); ++j) r += p.mass[j] * poly6((q - p.x[j]).squaredNorm(), h);
    return r;
  };
  double top = 0.0;
  for (float y = 0.2f; y < 0.5f; y += 0.001f) {
    double mean = 0.0;  // averaged over a few points around the axis, away from the lattice's pattern
    for (const Vec3& o : {Vec3(0, 0, 0), Vec3(0.03f, 0, 0.01f), Vec3(-0.02f, 0, 0.03f), Vec3(0.01f, 0, -0.03f)})
      mean += densityAt(Vec3(o.x(), y, o.z())) / 4.0;
    if (mean < 0.5 * scene.model.water.restDensity) {
      top = y;
      break;
    }
  }
  // height of 1500 particles of mass m at rest density over the 0.2 x 0.2 m floor
  const double expected = 1500.0 * scene.model.water.particleMass / (scene.model.water.restDensity * 0.04);
  EXPECT_NEAR(top / expected, 1.0, 0.02) << "surface at " << top << " m, expected " << expected;
  // mean density of the particles whose kernel lies entirely below the surface
  const std::vector<float> rho = densities(scene);
  double sum = 0.0;
  int count = 0;
  for (size_t i = 0; i < p.size(); ++i)
    if (p.x[i].y() < top - h) {
      sum += rho[i];
      ++count;
    }
  ASSERT_GT(count, 800);
  EXPECT_NEAR(sum / count / scene.model.water.restDensity, 1.0, 0.01);
  // and it is at rest
  double vmean = 0.0;
  for (const Vec3& v : p.v) vmean += v.norm();
  EXPECT_LT(vmean / p.size(), 0.05);
}

// the column at one 0.015 s substep: Table 1's 4 iterations leave it compressed; past them the solver
// goes on while the mean compression exceeds solver.fluidTolerance, which it then meets
TEST(Fluid, IteratesUntilTheMeanCompressionIsWithinTolerance) {
  const auto settle = [](const std::string& most, double& compression) {
    Scene scene = sceneFromJson(kColumn, {"solver.substeps=1", "solver.fluidIterations=4",
                                          "solver.fluidMaxIterations=" + most, "solver.fluidTolerance=0.01"});
    runSteps(scene, 60);  // 0.9 s: settled
    const StepStats last = runSteps(scene, 10);  // the last solve's count is in the State
    // the mean compression of the interior (a kernel away from the walls, floor and surface)
    const std::vector<float> rho = densities(scene);
    compression = 0.0;
    int n = 0;
    for (size_t i = 0; i < rho.size(); ++i) {
      const Vec3& x = scene.state.particles.x[i];
      if (std::max(std::abs(x.x()), std::abs(x.z())) > 0.06f || x.y() < 0.04f || x.y() > 0.2f) continue;
      compression += std::max(rho[i] / scene.model.water.restDensity - 1.0f, 0.0f);
      ++n;
    }
    compression /= n;
    return last;
  };
  double fixed = 0.0, iterated = 0.0;
  const StepStats four = settle("4", fixed);
  EXPECT_EQ(four.fluidIterations, 40u);
  const StepStats more = settle("32", iterated);
  EXPECT_GT(more.fluidIterationsMax, 4);
  EXPECT_LT(more.fluidIterationsMax, 32) << "the tolerance was not reached";
  // at rest the count holds (stopIterating's hysteresis): a count that changed would jolt the column
  EXPECT_EQ(more.fluidIterations, 10u * static_cast<uint64_t>(more.fluidIterationsMax));
  // the mean over all the water (surface included, as the tolerance) within 1%; the interior, the most
  // compressed, within 1.5% (4 iterations: 10%)
  EXPECT_NEAR(more.meanDensityRatio, 1.0, 0.01);
  EXPECT_LT(iterated, 0.015);
  EXPECT_GT(fixed, 0.05) << "the column at 4 iterations should be compressed: the test no longer tests";
}

// below the last solve's count the solver stops only at half the tolerance; at or above it, at the tolerance
TEST(Fluid, StopIteratingHasHysteresisBelowTheLastCount) {
  EXPECT_TRUE(stopIterating(0.009, 0.01, 12, 12));
  EXPECT_FALSE(stopIterating(0.011, 0.01, 12, 12));
  EXPECT_FALSE(stopIterating(0.009, 0.01, 11, 12));
  EXPECT_TRUE(stopIterating(0.004, 0.01, 11, 12));
  EXPECT_TRUE(stopIterating(0.009, 0.01, 13, 12));
}

TEST(Fluid, FreeFlightConservesMomentum) {
  // a blob of water thrown without gravity: internal pressure and XSPH must not change momentum
  Scene scene = sceneFromJson(R"({
    "solver": {"gravity": [0, 0, 0], "domain": {"min": [-5, -5, -5], "max": [5, 5, 5]}},
    "water": {"viscosity": 0.1},
    "emitters": [{"type": "block", "min": [0, 0, 0], "max": [0.16, 0.12, 0.1], "velocity": [1.0, 0.5, -0.2]}]
  })");
  runSteps(scene, 1);
  // squeeze it so the pressure works, then let it fly
  Particles& p = scene.state.particles;
  for (size_t i = 0; i < p.size(); ++i) p.x[i] = Vec3(0.08f, 0.06f, 0.05f) + 0.8f * (p.x[i] - Vec3(0.08f, 0.06f, 0.05f));
  auto momentum = [&] {
    Eigen::Vector3d m = Eigen::Vector3d::Zero();
    for (size_t i = 0; i < p.size(); ++i) m += double(p.mass[i]) * p.v[i].cast<double>();
    return m;
  };
  const Eigen::Vector3d before = momentum();
  runSteps(scene, 20);
  const Eigen::Vector3d after = momentum();
  EXPECT_LT((after - before).norm(), 1e-4 * before.norm()) << after.transpose() << " vs " << before.transpose();
  // the squeezed blob expanded: the pressure really acted
  float spread = 0.0f;
  for (const Vec3& x : p.x) spread = std::max(spread, std::abs(x.y() - p.x[0].y()));
  EXPECT_GT(spread, 0.0f);
}

namespace {
// one PBF iteration written out pair by pair (Eq. 6-7 as docs/models.md states soak's form: the
// inequality constraint, the relaxation in units of w_i / h_i^2, s_corr between water particles, cloth
// as Akinci boundary with the averaged reaction), the reference for solveFluid's pair sums
std::vector<Vec3> referenceIteration(const Model& model, const Particles& p, const NeighborLists& nb,
                                     const FluidScratch& s) {
  const WaterParams& wp = model.water;
  const size_t n = p.size(), nc = static_cast<size_t>(model.numCloth);
  const double rho0 = wp.restDensity;
  const auto lend = [&](size_t j) { return j < nc ? double(s.psi[j]) : double(p.mass[j]); };
  std::vector<double> lambda(n, 0.0);
  for (size_t i = nc; i < n; ++i) {
    double rho = p.mass[i] * poly6(0.0f, p.radius[i]), others = 0.0;
    Eigen::Vector3d grad = Eigen::Vector3d::Zero();
    for (uint32_t k = nb.start[i]; k < nb.start[i + 1]; ++k) {
      const uint32_t j = nb.index[k];
      const float h = pairRadius(p.radius[i], p.radius[j]);
      rho += lend(j) * poly6((p.xPred[i] - p.xPred[j]).squaredNorm(), h);
      const Eigen::Vector3d g = (lend(j) / rho0) * spikyGrad(p.xPred[i] - p.xPred[j], h).cast<double>();
      grad += g;
      others += p.invMass[j] * g.squaredNorm();
    }
    const double C = std::max(rho / rho0 - 1.0, 0.0);
    const double hi = p.radius[i];
    lambda[i] = -C / (p.mass[i] * (p.invMass[i] * grad.squaredNorm() + others + wp.relaxation * p.invMass[i] / (hi * hi)));
  }
  std::vector<Vec3> delta(n, Vec3::Zero());
  for (size_t i = nc; i < n; ++i) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    for (uint32_t k = nb.start[i]; k < nb.start[i + 1]; ++k) {
      const uint32_t j = nb.index[k];
      const float h = pairRadius(p.radius[i], p.radius[j]);
      const double r2 = (p.xPred[i] - p.xPred[j]).squaredNorm();
      double sCorr = 0.0;
      if (j >= nc) {
        const double q = std::max(double(h) * h - r2, 0.0) / (double(h) * h * (1.0 - double(wp.tensileDq) * wp.tensileDq));
        sCorr = -double(wp.tensileK) * s.sCorrScale * std::pow(q * q * q, wp.tensileN);
      }
      d += lend(j) * (lambda[i] + lambda[j] + sCorr) * spikyGrad(p.xPred[i] - p.xPred[j], h).cast<double>();
    }
    delta[i] = (d / rho0).cast<float>();
  }
  for (size_t b = 0; b < nc; ++b) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    int pushing = 0;
    for (uint32_t k = nb.start[b]; k < nb.start[b + 1]; ++k) {
      const uint32_t i = nb.index[k];
      if (i < nc || lambda[i] == 0.0) continue;
      d -= p.mass[i] * lambda[i] * spikyGrad(p.xPred[i] - p.xPred[b], pairRadius(p.radius[i], p.radius[b])).cast<double>();
      ++pushing;
    }
    if (pushing && p.invMass[b] > 0.0f) delta[b] = (p.invMass[b] * s.psi[b] / (rho0 * pushing) * d).cast<float>();
  }
  return delta;
}

// squeezed water on a cloth patch, without colliders: every pair term of the solver is at work
Scene squeezedWaterOnCloth(const std::string& tensileK) {
  Scene scene = sceneFromJson(R"({
    "solver": {"gravity": [0, 0, 0], "fluidIterations": 1, "domain": {"min": [-1, -1, -1], "max": [1, 1, 1]}},
    "water": {"tensile": {"k": )" + tensileK + R"(}},
    "cloth": [{"mesh": {"type": "rectangle", "center": [0, 0, 0], "size": [0.2, 0.2], "resolution": [20, 20],
               "axisU": [1, 0, 0], "axisV": [0, 0, 1]}}],
    "emitters": [{"type": "block", "min": [-0.08, 0.005, -0.08], "max": [0.08, 0.1, 0.08]}]
  })");
  runSteps(scene, 1);  // emits the block
  Particles& p = scene.state.particles;
  for (size_t i = static_cast<size_t>(scene.model.numCloth); i < p.size(); ++i)
    p.xPred[i] = Vec3(p.x[i].x() * 0.85f, 0.01f + (p.x[i].y() - 0.005f) * 0.8f, p.x[i].z() * 0.85f);  // squeezed
  return scene;
}

void expectSolverMatchesReference(Scene& scene, size_t pairCacheLimit) {
  const Model& model = scene.model;
  Particles& p = scene.state.particles;
  NeighborGrid grid;
  NeighborLists nb;
  buildGrid(p.xPred, maxSupportRadius(p), grid);
  buildNeighborLists(p.xPred, p.radius, grid, nb, static_cast<uint32_t>(model.numCloth));
  FluidScratch s;
  s.pairCacheLimit = pairCacheLimit;
  computeBoundaryPsi(model, p, nb, s);
  const std::vector<Vec3> before = p.xPred;
  solveFluid(model, {}, p, nb, s, 1);
  Particles start = p;  // the reference reads s.sCorrScale, which the solver has set now
  start.xPred = before;
  const std::vector<Vec3> want = referenceIteration(model, start, nb, s);
  float largest = 0.0f, worst = 0.0f;
  size_t moved = 0, movedCloth = 0;
  for (size_t i = 0; i < p.size(); ++i) largest = std::max(largest, want[i].norm());
  for (size_t i = 0; i < p.size(); ++i) {
    const Vec3 got = p.xPred[i] - before[i];
    worst = std::max(worst, (got - want[i]).norm());
    moved += want[i].norm() > 1e-3f * largest;
    movedCloth += i < static_cast<size_t>(model.numCloth) && want[i].norm() > 1e-3f * largest;
  }
  EXPECT_LT(worst, 1e-4f * largest) << "largest correction " << largest;
  EXPECT_GT(moved, p.size() / 4);  // the squeeze really compressed the water
  EXPECT_GT(movedCloth, 20u);      // and the water pushed the cloth
}
}  // namespace

TEST(Fluid, SolverPassMatchesPairByPairReference) {
  // the solver's pair sums (16 neighbours at a time with AVX-512, scalar for short lists) against a
  // plain double-precision loop: equal radii, the artificial pressure, and mixed radii; with the pair
  // cache of the correction pass (the default here) and without it (a large scene's path)
  for (const size_t limit : {FluidScratch().pairCacheLimit, size_t(0)}) {
    SCOPED_TRACE(limit ? "pair cache" : "no pair cache");
    Scene equal = squeezedWaterOnCloth("0");
    expectSolverMatchesReference(equal, limit);
    Scene tensile = squeezedWaterOnCloth("0.1");
    expectSolverMatchesReference(tensile, limit);
    Scene mixed = squeezedWaterOnCloth("0.1");
    Particles& p = mixed.state.particles;
    for (size_t i = static_cast<size_t>(mixed.model.numCloth); i < p.size(); i += 2) {  // every other one shrunk
      p.mass[i] *= 0.5f;
      p.invMass[i] = 1.0f / p.mass[i];
      p.radius[i] *= std::cbrt(0.5f);
    }
    expectSolverMatchesReference(mixed, limit);
    // one shrunk particle: it and its neighbours take the per-pair radius, the others the constant one
    Scene one = squeezedWaterOnCloth("0.1");
    Particles& q = one.state.particles;
    const size_t mid = static_cast<size_t>(one.model.numCloth) + (q.size() - static_cast<size_t>(one.model.numCloth)) / 2;
    q.mass[mid] *= 0.5f;
    q.invMass[mid] = 1.0f / q.mass[mid];
    q.radius[mid] *= std::cbrt(0.5f);
    expectSolverMatchesReference(one, limit);
  }
}

TEST(Fluid, XsphMatchesPairByPairReference) {
  // the XSPH pass against a double-precision pair loop of Macklin 2013 Eq. 17 with soak's volume
  // weights 2 m_j / (rho_i + rho_j), and the hyperviscosity's second sum of the same weights; equal radii, every other one shrunk, and one shrunk (its
  // neighbours take the per-pair radius, the others the constant one); scalar: 16-lane gathers were slower.
  // Cases 0 - 2 take the flags solveFluid marked on the same lists. Cases 3 and 4: the solver marked
  // lists where one particle was shrunk, then another one is shrunk instead and the lists are built
  // again (3: in the same object, 4: in a fresh one): told so, the velocity pass marks them again
  for (const int mixed : {0, 1, 2, 3, 4}) {
    Scene scene = squeezedWaterOnCloth("0");
    const Model& model = scene.model;
    Particles& p = scene.state.particles;
    const size_t nc = static_cast<size_t>(model.numCloth);
    for (size_t i = nc; i < p.size(); ++i) {
      p.v[i] = Vec3(std::sin(0.7f * float(i)), std::cos(1.3f * float(i)), std::sin(2.1f * float(i) + 1.0f));
      const bool shrink = (mixed == 1 && i % 2 == 0) || (mixed == 2 && i == nc + (p.size() - nc) / 2) || (mixed >= 3 && i == nc);
      if (shrink) p.radius[i] *= 0.8f;
    }
    NeighborGrid grid;
    NeighborLists nb;
    buildGrid(p.xPred, maxSupportRadius(p), grid);
    buildNeighborLists(p.xPred, p.radius, grid, nb, static_cast<uint32_t>(nc));
    FluidScratch s;
    computeBoundaryPsi(model, p, nb, s);
    solveFluid(model, {}, p, nb, s, 1);  // the densities the pass reads
    NeighborLists fresh;
    NeighborLists& lists = mixed == 4 ? fresh : nb;
    if (mixed >= 3) {
      p.radius[nc] = p.radius[nc + 1];
      p.radius[p.size() - 1] *= 0.8f;
      buildGrid(p.xPred, maxSupportRadius(p), grid);
      buildNeighborLists(p.xPred, p.radius, grid, lists, static_cast<uint32_t>(nc));
    }
    const std::vector<Vec3> v0 = p.v;
    fluidVelocityPass(model, p, lists, s, 0.015f, mixed < 3);  // 3, 4: not the lists solveFluid marked
    // L u_i = sum_j V_ij W_ij (u_j - u_i); the pass adds c L v (XSPH) and takes k L(L v) (hyperviscosity)
    const auto smooth = [&](const std::vector<Eigen::Vector3d>& u) {
      std::vector<Eigen::Vector3d> out(p.size(), Eigen::Vector3d::Zero());
      for (size_t i = nc; i < p.size(); ++i)
        for (uint32_t k = lists.waterBegin(i, static_cast<uint32_t>(nc)); k < lists.start[i + 1]; ++k) {
          const uint32_t j = lists.index[k];
          const double vol = 2.0 * p.mass[j] / std::max(double(s.density[i]) + s.density[j], 1e-3);
          const double w = poly6((p.xPred[i] - p.xPred[j]).squaredNorm(), pairRadius(p.radius[i], p.radius[j]));
          out[i] += vol * w * (u[j] - u[i]);
        }
      return out;
    };
    std::vector<Eigen::Vector3d> u(p.size());
    for (size_t i = 0; i < p.size(); ++i) u[i] = v0[i].cast<double>();
    const std::vector<Eigen::Vector3d> b = smooth(u), e = smooth(b);
    const double k = hyperviscosityStep(model.water.hyperviscosity, 0.015f);
    ASSERT_GT(k, 0.0);
    float worst = 0.0f, largest = 0.0f;
    for (size_t i = nc; i < p.size(); ++i) {
      const Vec3 dv = (model.water.viscosity * b[i] - k * e[i]).cast<float>();
      largest = std::max(largest, dv.norm());
      worst = std::max(worst, (p.v[i] - v0[i] - dv).norm());
    }
    EXPECT_GT(largest, 1e-3f);  // the velocities really differ between neighbours
    const char* what[] = {"equal radii", "mixed radii", "one shrunk", "lists built again", "lists built in a fresh object"};
    EXPECT_LT(worst, 1e-4f * largest) << what[mixed];
  }
}

namespace {
// the kinetic energy sum m v^2 / 2 of the water particles selected by keep(i)
double kineticOf(const Particles& p, size_t first, const std::function<bool(size_t)>& keep) {
  double e = 0.0;
  for (size_t i = first; i < p.size(); ++i)
    if (keep(i)) e += 0.5 * p.mass[i] * p.v[i].cast<double>().squaredNorm();
  return e;
}
}  // namespace

TEST(Fluid, HyperviscosityDampsParticleNoiseAndKeepsSmoothFlow) {
  // a 0.4 x 0.2 x 0.2 m lattice block of water, no gravity, given three velocity fields in turn: a
  // checkerboard (the particle-scale noise a density solve leaves), a wave one block long and a
  // uniform shear. One velocity pass with the hyperviscosity only, against XSPH alone at the
  // coefficient that damps the checkerboard as much: the hyperviscosity (k L(L v), docs/models.md) must
  // leave the wave 5 times less damped, and the shear untouched away from the surface
  Scene scene = sceneFromJson(R"({
    "solver": {"gravity": [0, 0, 0], "fluidIterations": 1, "domain": {"min": [-1, -1, -1], "max": [1, 1, 1]}},
    "emitters": [{"type": "block", "min": [-0.2, 0.0, -0.1], "max": [0.2, 0.2, 0.1]}]
  })");
  runSteps(scene, 1);
  Model& model = scene.model;
  Particles& p = scene.state.particles;
  ASSERT_EQ(p.size(), 2000u);
  p.xPred = p.x;
  NeighborGrid grid;
  NeighborLists nb;
  buildGrid(p.xPred, maxSupportRadius(p), grid);
  buildNeighborLists(p.xPred, p.radius, grid, nb);
  FluidScratch s;
  computeBoundaryPsi(model, p, nb, s);
  solveFluid(model, {}, p, nb, s, 1);  // the densities the pass reads
  p.xPred = p.x;
  const float h = 0.0075f, spacing = model.water.spacing, support = model.water.supportRadius;
  const auto cell = [&](size_t i, int axis) {
    return static_cast<int>(std::lround((p.x[i][axis] - (axis == 0 ? -0.2f : axis == 1 ? 0.0f : -0.1f)) / spacing - 0.5f));
  };
  const auto inside = [&](size_t i) {  // two supports from every face: a full neighbourhood of full ones
    const Vec3 lo(-0.2f, 0.0f, -0.1f), hi(0.2f, 0.2f, 0.1f);
    return ((p.x[i] - lo).minCoeff() > 2.0f * support) && ((hi - p.x[i]).minCoeff() > 2.0f * support);
  };
  const auto all = [](size_t) { return true; };
  enum Field { Checkerboard, Wave, Shear };
  // the ratio of the selected particles' kinetic energy after one pass to before, and the largest
  // change of an inside particle's velocity
  const auto pass = [&](Field field, float viscosity, float hyperviscosity, float* largestInside = nullptr) {
    for (size_t i = 0; i < p.size(); ++i) {
      const int sign = (cell(i, 0) + cell(i, 1) + cell(i, 2)) % 2 == 0 ? 1 : -1;
      p.v[i] = field == Checkerboard ? Vec3(0.0f, 0.1f * float(sign), 0.0f)
               : field == Wave       ? Vec3(0.0f, 0.1f * std::sin(2.0f * kPi * p.x[i].x() / 0.4f), 0.0f)
                                     : Vec3(0.5f * p.x[i].y(), 0.0f, 0.0f);
    }
    const std::vector<Vec3> before = p.v;
    const double e0 = kineticOf(p, 0, all);
    model.water.viscosity = viscosity;
    model.water.hyperviscosity = hyperviscosity;
    fluidVelocityPass(model, p, nb, s, h, true);
    if (largestInside) {
      *largestInside = 0.0f;
      for (size_t i = 0; i < p.size(); ++i)
        if (inside(i)) *largestInside = std::max(*largestInside, (p.v[i] - before[i]).norm());
    }
    return kineticOf(p, 0, all) / e0;
  };
  const float rate = 50.0f;  // k = 0.375 at h
  EXPECT_FLOAT_EQ(hyperviscosityStep(rate, h), 0.375f);
  EXPECT_FLOAT_EQ(hyperviscosityStep(rate, 0.03f), kMaxHyperviscosityStep);  // a long substep: capped
  const double hyperNoise = pass(Checkerboard, 0.0f, rate), hyperWave = pass(Wave, 0.0f, rate);
  EXPECT_LT(hyperNoise, 0.7);  // the noise loses at least 30% of its energy in one pass
  // XSPH alone at the coefficient with the same damping of the checkerboard (bisection)
  float lo = 0.0f, hi = 1.0f;
  for (int it = 0; it < 30; ++it) {
    const float c = 0.5f * (lo + hi);
    (pass(Checkerboard, c, 0.0f) > hyperNoise ? lo : hi) = c;
  }
  const double xsphWave = pass(Wave, 0.5f * (lo + hi), 0.0f);
  EXPECT_GT(1.0 - xsphWave, 5.0 * (1.0 - hyperWave)) << "hyperviscosity " << hyperWave << ", XSPH " << xsphWave;
  EXPECT_GT(1.0 - hyperWave, 0.0);  // it does act on the wave, a little
  float shearChange = 0.0f;
  pass(Shear, 0.0f, rate, &shearChange);
  EXPECT_LT(shearChange, 1e-3f * 0.5f * 0.2f) << "a linear velocity field is kept inside";
}
