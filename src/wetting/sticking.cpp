// sticking of wet cloth, section 4.5 of Shao et al. 2017 (Eq. 20): touching wet cloth particles attract,
//   f_i = sum_j (eta^ad - kappa^ad |(S_i - S^T)(S_j - S^T)|) W(x_j - x_i, h) along x_j - x_i,
// largest at S^T and gone when the cloth is too wet. As NOTES.md asks, the force is kept non-negative;
// soak adds a wetness ramp min(1, S/S^T) per particle so dry cloth does not stick (the printed force
// is eta^ad - kappa^ad (S^T)^2 > 0 at S = 0), and normalises W by W(0, h) so eta^ad and kappa^ad are
// newtons (docs/models.md). "Touching" means close in space but not on the rest shape: mesh
// neighbours are held by the cloth constraints, not by water.
#include "wetting/wetting.hpp"

#include "core/kernels.hpp"
#include "core/parallel.hpp"

#include <algorithm>
#include <cmath>

namespace soak {

namespace {

// Forces are gathered per particle; the pair's force is bit for bit opposite seen from the other side.
// The pairs' terms in a vectorised loop (plain floats and selects; it calls stickingCoefficient and
// poly6Coef) into a per-thread buffer, summed in list order: the scalar loop's result (a skipped pair
// adds +0). Pointers copied to locals: the compiler does not vectorise through captures

// what the pair loops read: the particles' arrays (x, rest position, radius, phase, saturation), the
// neighbour lists' indices, each particle's areaShare and the law's S^T, kappa^ad and eta^ad
struct StickingInputs {
  const float* xAll;
  const float* restAll;
  const float* radiusAll;
  const int32_t* phaseAll;
  const float* satAll;
  const uint32_t* indexAll;
  const float* shareAll;
  float st, rate, strength;
};

// Eq. 20's force on wet cloth particle i from the touching wet cloth particles around it
Vec3 stickingForce(const StickingInputs& in, const NeighborLists& nb, int64_t nc, WettingScratch& s, int64_t i) {
  Vec3 f = Vec3::Zero();
  const uint32_t begin = nb.start[i], count = nb.clothEnd(i, static_cast<uint32_t>(nc)) - begin;
  const uint32_t* const J = in.indexAll + begin;
  const float* const X = in.xAll;
  const float* const R = in.restAll;
  const float* const H = in.radiusAll;
  const int32_t* const P = in.phaseAll;
  const float* const S = in.satAll;
  const float* const A = in.shareAll;
  float* const Tx = s.pairFloat.get(3 * static_cast<size_t>(count));
  float* const Ty = Tx + count;
  float* const Tz = Ty + count;
  const uint32_t cloth = static_cast<uint32_t>(nc), self = static_cast<uint32_t>(i);
  const float si = S[i], ai = A[i], hi = H[i], xi = X[3 * i], yi = X[3 * i + 1], zi = X[3 * i + 2];
  const float rxi = R[3 * i], ryi = R[3 * i + 1], rzi = R[3 * i + 2];
  const int32_t phi = P[i];
  const float stL = in.st, rateL = in.rate, strengthL = in.strength;
  // neighbours on the rest shape are not "touching": the cloth holds them, not the water
  const auto onRest = [=](uint32_t jj, float hij) {
    const float ex = rxi - R[3 * jj], ey = ryi - R[3 * jj + 1], ez = rzi - R[3 * jj + 2];
    return (P[jj] == phi) & (ex * ex + (ey * ey + ez * ez) < 2.25f * hij * hij);
  };
  // most of a sheet touches only its rest-shape neighbours: count the wet pairs that are not
  // (a cheap loop) and skip the particle when there are none
  int touching = 0;
#pragma omp simd reduction(+ : touching)
  for (uint32_t k = 0; k < count; ++k) {
    const uint32_t j = J[k];
    const bool isCloth = j < cloth;
    const uint32_t jj = isCloth ? j : self;
    touching += isCloth & (S[jj] > 0.0f) & !onRest(jj, pairRadius(hi, H[jj])) ? 1 : 0;
  }
  if (touching == 0) return f;
#pragma omp simd
  for (uint32_t k = 0; k < count; ++k) {
    const uint32_t j = J[k];
    const bool isCloth = j < cloth;
    const uint32_t jj = isCloth ? j : self;  // water entries read i's own row, then drop out
    const float sj = S[jj];
    const float hij = pairRadius(hi, H[jj]);
    const float coef = stickingCoefficient(si, sj, stL, strengthL, rateL);  // 0 for a dry neighbour
    const float rx = X[3 * jj] - xi, ry = X[3 * jj + 1] - yi, rz = X[3 * jj + 2] - zi;  // x_j - x_i
    const float r2 = rx * rx + (ry * ry + rz * rz);
    const float h2 = hij * hij;
    const bool ok = isCloth & !onRest(jj, hij) & (coef > 0.0f) & (r2 < h2) & (r2 >= 1e-18f);
    // poly6(r2, h_ij) / poly6(0, h_ij)
    const float kern = poly6Coef(hij, h2);
    const float d = h2 - r2;
    const float w6 = kern * d * d * d, w0 = kern * h2 * h2 * h2;
    const float rs = ok ? r2 : 1.0f;
    // eta^ad and kappa^ad are per pair of referenceArea particles: times both areaShares
    const float sc = ok ? coef * (ai * A[jj]) * w6 / w0 / std::sqrt(rs) : 0.0f;
    Tx[k] = sc * rx;
    Ty[k] = sc * ry;
    Tz[k] = sc * rz;
  }
  for (uint32_t k = 0; k < count; ++k) f += Vec3(Tx[k], Ty[k], Tz[k]);
  return f;
}

}  // namespace

void applySticking(const Model& model, State& state, const NeighborLists& nb, WettingScratch& s, float h) {
  s.pairFloat.prepare();  // the per-thread pair buffers of the loops below
  s.pairDouble.prepare();
  const WettingParams& w = model.wetting;
  const int64_t nc = model.numCloth;
  if (!w.enabled || !w.sticking || nc == 0) return;
  Particles& p = state.particles;
  const std::vector<float>& sat = state.clothSaturation;
  s.force.resize(static_cast<size_t>(nc));
  const StickingInputs in{p.x[0].data(), model.clothRestPosition[0].data(), p.radius.data(), p.phase.data(),
                          sat.data(), nb.index.data(), s.areaShare.data(), w.saturationSticky, w.stickingRate, w.stickingStrength};
  parallelForDynamic(nc, kWetChunk, [&](int64_t i) {
    s.force[i] = sat[i] > 0.0f ? stickingForce(in, nb, nc, s, i) : Vec3(Vec3::Zero());
  });
  parallelFor(nc, [&](int64_t i) { p.v[i] += (h * p.invMass[i]) * s.force[i]; });
}

}  // namespace soak
