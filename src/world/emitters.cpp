// water emitters: a block of water on a cubic lattice (Fig. 3), a nozzle jet of evenly spaced
// discs (Fig. 1) and rain over a rectangle (Chen 2012 Fig. 9). Serial: emission is cheap, and the order of new particles must be deterministic.
#include "world/emitters.hpp"

#include <soak/scene.hpp>

#include "core/kernels.hpp"

#include <algorithm>
#include <cmath>

namespace soak {

namespace {

// appends one water particle unless the cap is reached; returns whether it was added
bool addWater(const Model& model, State& state, const Vec3& x, const Vec3& v) {
  if (state.particles.size() >= static_cast<size_t>(std::max(model.solver.maxParticles, 0))) return false;
  const float m = model.water.particleMass;
  state.particles.add(kWaterPhase, state.nextId++, m, model.water.supportRadius, x, v);
  state.ledger.emitted += m;
  return true;
}

// number of lattice sites of spacing s that fit in [lo, hi] starting at lo + s/2
int latticeCount(float lo, float hi, float s) {
  const double extent = static_cast<double>(hi) - static_cast<double>(lo);
  if (extent <= 0.0) return 0;
  // tolerance so that an extent of exactly n spacings in float gives n sites
  // clamped: a tiny spacing must not overflow the count (the loops stop at solver.maxParticles)
  return static_cast<int>(std::min(std::floor(extent / s + 1e-4), 2147483647.0));
}

size_t emitBlock(const Model& model, State& state, const Emitter& e) {
  const float s = model.water.spacing;
  const int nx = latticeCount(e.boxMin.x(), e.boxMax.x(), s);
  const int ny = latticeCount(e.boxMin.y(), e.boxMax.y(), s);
  const int nz = latticeCount(e.boxMin.z(), e.boxMax.z(), s);
  if (nx == 0 || ny == 0 || nz == 0) return 0;
  // as many sites as fit at the spacing, spread towards the spacing of rest density as far as the box
  // allows, centred: a block given room starts at rest instead of 3.5% compressed at Table 1's spacing,
  // and a block that fills a container exactly stays inside it (a departure, docs/models.md)
  const Vec3 extent = e.boxMax - e.boxMin;
  const float rest = restLatticeSpacing(model.water);
  const float spread = std::min({rest, extent.x() / static_cast<float>(nx), extent.y() / static_cast<float>(ny),
                                 extent.z() / static_cast<float>(nz)});
  const Vec3 first = 0.5f * (e.boxMin + e.boxMax) -
                     0.5f * spread * Vec3(static_cast<float>(nx - 1), static_cast<float>(ny - 1), static_cast<float>(nz - 1));
  size_t created = 0;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const Vec3 x = first + spread * Vec3(static_cast<float>(i), static_cast<float>(j), static_cast<float>(k));
        if (!addWater(model, state, x, e.velocity)) return created;
        ++created;
      }
  return created;
}

// an orthonormal pair spanning the plane orthogonal to unit d, built from the world axis least
// aligned with d so the lattice orientation is fixed for a given direction
void discBasis(const Vec3& d, Vec3* u, Vec3* w) {
  const Vec3 a = d.cwiseAbs();
  Vec3 helper = Vec3::UnitX();
  if (a.y() < a.x() && a.y() <= a.z()) helper = Vec3::UnitY();
  else if (a.z() < a.x() && a.z() < a.y()) helper = Vec3::UnitZ();
  *u = d.cross(helper).normalized();
  *w = d.cross(*u);
}

// the jet travels speed * (overlap of [t, t + dt) with [start, end)); a disc leaves the nozzle each
// time the travelled length crosses a multiple of the spacing, placed where it would be now, so the
// discs stay one spacing apart whatever dt is. Each disc is a square lattice (the cubic lattice of a
// block, so the jet has rest density) clipped to the nozzle radius.
size_t emitJet(const Model& model, State& state, const Emitter& e, EmitterState& es, double t, float dt) {
  const double t0 = std::max(t, static_cast<double>(e.start));
  const double t1 = std::min(t + static_cast<double>(dt), static_cast<double>(e.end));
  if (t1 >= static_cast<double>(e.end)) es.done = true;
  if (!(t1 > t0) || !(e.speed > 0.0f)) return 0;
  const double s = model.water.spacing;
  const double before = es.emittedLength;
  const double after = before + static_cast<double>(e.speed) * (t1 - t0);
  es.emittedLength = after;

  Vec3 d = e.direction;
  d = d.norm() > 0.0f ? Vec3(d.normalized()) : Vec3(0, -1, 0);
  Vec3 u, w;
  discBasis(d, &u, &w);
  const Vec3 vel = e.speed * d;
  const int n = static_cast<int>(std::floor(e.radius / s));
  const double r2 = static_cast<double>(e.radius) * e.radius / (s * s) + 1e-6;

  size_t created = 0;
  const int64_t kFirst = static_cast<int64_t>(std::floor(before / s)) + 1;
  const int64_t kLast = static_cast<int64_t>(std::floor(after / s));
  for (int64_t k = kFirst; k <= kLast; ++k) {
    const Vec3 centre = e.origin + static_cast<float>(after - static_cast<double>(k) * s) * d;
    for (int j = -n; j <= n; ++j)
      for (int i = -n; i <= n; ++i) {
        if (static_cast<double>(i * i + j * j) > r2) continue;
        const Vec3 x = centre + static_cast<float>(s) * (static_cast<float>(i) * u + static_cast<float>(j) * w);
        if (!addWater(model, state, x, vel)) return created;
        ++created;
      }
  }
  return created;
}

// splitmix64 (Steele, Lea, Flood 2014): a fixed, portable hash, so drop positions depend only on
// (emitter, drop number) and never on the machine, the thread count or dt
uint64_t mixBits(uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// uniform in [0, 1) from the top 24 bits
float unitFloat(uint64_t bits) { return static_cast<float>(bits >> 40) * (1.0f / 16777216.0f); }

// drop k is due at start + (k + 1) / (rate * area): the count by time t is floor(rate area (t - start)).
// The state keeps how many were made, so steps that do not tile time exactly lose or repeat none,
// and drop k's place hashes (emitter, k): the same drops for any dt. A drop due at t_k inside the
// step is placed where it would be at t + dt, like the jet's discs. Its mass is one water particle,
// or rho_0 4/3 pi r^3 for a given drop radius, with the SPH support radius scaled by the cube root
// of the mass ratio (the same number of neighbours as a full-size particle).
size_t emitRain(const Model& model, State& state, const Emitter& e, EmitterState& es, size_t index, double t,
                float dt) {
  const double t1 = std::min(t + static_cast<double>(dt), static_cast<double>(e.end));
  if (t1 >= static_cast<double>(e.end)) es.done = true;
  const double area = 4.0 * static_cast<double>(e.halfExtents.x()) * static_cast<double>(e.halfExtents.z());
  const double perSecond = static_cast<double>(e.rate) * area;
  if (!(t1 > static_cast<double>(e.start)) || !(perSecond > 0.0)) return 0;
  // 1e-9 forgives the rounding of a time that should land exactly on a drop
  const uint64_t due = static_cast<uint64_t>(std::floor(perSecond * (t1 - e.start) + 1e-9));
  const Vec3 d = e.direction.norm() > 0.0f ? Vec3(e.direction.normalized()) : Vec3(0, -1, 0);
  const Vec3 vel = e.dropSpeed * d;
  float mass = model.water.particleMass, radius = model.water.supportRadius;
  if (e.dropRadius > 0.0f) {
    mass = model.water.restDensity * 4.0f / 3.0f * kPi * e.dropRadius * e.dropRadius * e.dropRadius;
    radius = model.water.supportRadius * std::cbrt(mass / model.water.particleMass);
  }
  const uint64_t seed = mixBits(0x5241494E00000000ull ^ static_cast<uint64_t>(index));
  size_t created = 0;
  for (uint64_t k = es.dropsEmitted; k < due; ++k) {
    if (state.particles.size() >= static_cast<size_t>(std::max(model.solver.maxParticles, 0))) break;
    const uint64_t hx = mixBits(seed ^ k);
    const uint64_t hz = mixBits(hx);
    const double born = static_cast<double>(e.start) + static_cast<double>(k + 1) / perSecond;
    const float fall = static_cast<float>(std::max(t + static_cast<double>(dt) - born, 0.0));
    const Vec3 x = e.origin + Vec3((2.0f * unitFloat(hx) - 1.0f) * e.halfExtents.x(), 0.0f,
                                   (2.0f * unitFloat(hz) - 1.0f) * e.halfExtents.z()) +
                   fall * vel;
    state.particles.add(kWaterPhase, state.nextId++, mass, radius, x, vel);
    state.ledger.emitted += mass;
    ++created;
  }
  // past the cap the drops are skipped, not owed: rain does not pour down when room frees up
  es.dropsEmitted = std::max(es.dropsEmitted, due);
  return created;
}

}  // namespace

float latticeDensity(const WaterParams& w, float spacing) {
  const int n = static_cast<int>(std::ceil(w.supportRadius / spacing));
  double sum = 0.0;
  for (int z = -n; z <= n; ++z)
    for (int y = -n; y <= n; ++y)
      for (int x = -n; x <= n; ++x) {
        const float r2 = static_cast<float>(x * x + y * y + z * z) * spacing * spacing;
        sum += poly6(r2, w.supportRadius);
      }
  return static_cast<float>(w.particleMass * sum);
}

float restLatticeSpacing(const WaterParams& w) {
  // the SPH sum is close to m / s^3 times a slowly varying factor: a few fixed-point steps converge
  float s = w.spacing;
  for (int it = 0; it < 4; ++it) s *= std::cbrt(latticeDensity(w, s) / w.restDensity);
  return s;
}

size_t emitWater(const Model& model, State& state, double t, float dt) {
  if (state.emitters.size() < model.emitters.size()) state.emitters.resize(model.emitters.size());
  size_t created = 0;
  for (size_t k = 0; k < model.emitters.size(); ++k) {
    const Emitter& e = model.emitters[k];
    EmitterState& es = state.emitters[k];
    if (es.done) continue;
    if (e.kind == EmitterKind::Block) {
      // due once its start time is reached within this step (an overdue block is emitted now)
      if (static_cast<double>(e.start) < t + static_cast<double>(dt) || (t == 0.0 && e.start <= 0.0f)) {
        created += emitBlock(model, state, e);
        es.done = true;
      }
    } else if (e.kind == EmitterKind::Rain) {
      created += emitRain(model, state, e, es, k, t, dt);
    } else {
      created += emitJet(model, state, e, es, t, dt);
    }
  }
  return created;
}

size_t blockParticleCount(const Model& model) {
  // emitBlock's lattice sites, at most solver.maxParticles in all
  const float s = model.water.spacing;
  size_t count = 0;
  for (const Emitter& e : model.emitters)
    if (e.kind == EmitterKind::Block)
      count += static_cast<size_t>(latticeCount(e.boxMin.x(), e.boxMax.x(), s)) *
               static_cast<size_t>(latticeCount(e.boxMin.y(), e.boxMax.y(), s)) *
               static_cast<size_t>(latticeCount(e.boxMin.z(), e.boxMax.z(), s));
  return std::min(count, static_cast<size_t>(std::max(model.solver.maxParticles, 0)));
}

}  // namespace soak
