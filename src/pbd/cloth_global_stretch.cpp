// The PBD cloth's global stretch step (solver.clothGlobalStretch): in each small step, one
// local/global step of projective dynamics (Bouaziz et al. 2014) over the inextensible edges, so that the
// load a pin holds reaches the whole sheet at once instead of a few edges a Gauss-Seidel pass
// (docs/models.md, Eq. 8, "The global stretch step").
#include "pbd/cloth.hpp"

#include "core/parallel.hpp"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace soak {

// the factored system of the step: A = M + w L over the free particles, M their dry masses (the model's,
// so a resumed run factors the same matrix), w = kGlobalStretchWeight times their mean, L the graph
// Laplacian of the inextensible edges (a held end's term on the diagonal)
struct GlobalStretch {
  using Ldlt = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>>;
  std::vector<int> row;         // per cloth particle: its unknown, or -1 (held, implicit or not a PBD piece)
  std::vector<int> free;        // the unknowns' particles
  std::vector<int> edges;       // the stretch constraints in the step: compliance 0, a free end
  size_t constraints = 0;       // model.stretch's size when the unknowns were chosen
  std::vector<int> component;   // per unknown: its connected component over the edges, or -1 if held
  int components = 0;
  double weight = 0.0;          // kg, w
  Ldlt ldlt;
  Eigen::MatrixXd misfit, delta;  // scratch of each call: the right-hand side r and the solution
};

namespace {

// the edge weight over the mean particle mass (the edges' stiffness is w / h_s^2): large enough that the
// validation sheet's edges end within 1e-4 of their length under its load (1e3 left 18% at its corner),
// small enough that A stays well conditioned in double precision (largest eigenvalue about 8 w over m)
constexpr double kGlobalStretchWeight = 1e6;

bool inStep(const Model& model, const Particles& p, int64_t i) {
  return p.invMass[i] > 0.0f && !model.clothPinned[i] && !model.clothImplicit[i];
}

int findRoot(std::vector<int>& parent, int a) {
  while (parent[a] != a) a = parent[a] = parent[parent[a]];
  return a;
}

// the components of the unknowns joined by the step's edges; a component with an edge to a held
// particle gets -1 (the held end takes up its momentum)
void findComponents(const StretchConstraints& st, GlobalStretch& g) {
  const int m = static_cast<int>(g.free.size());
  std::vector<int> parent(static_cast<size_t>(m) + 1);
  for (int r = 0; r <= m; ++r) parent[r] = r;  // m: the held particles' root
  for (int k : g.edges) {
    const int a = g.row[st.ids[k][0]], b = g.row[st.ids[k][1]];
    parent[findRoot(parent, a >= 0 ? a : m)] = findRoot(parent, b >= 0 ? b : m);
  }
  std::vector<int> label(static_cast<size_t>(m) + 1, -2);
  const int held = findRoot(parent, m);
  label[held] = -1;
  g.component.resize(static_cast<size_t>(m));
  g.components = 0;
  for (int r = 0; r < m; ++r) {
    const int root = findRoot(parent, r);
    if (label[root] == -2) label[root] = g.components++;
    g.component[r] = label[root];
  }
}

void build(const Model& model, const Particles& p, GlobalStretch& g) {
  const int n = model.numCloth;
  const StretchConstraints& st = model.stretch;
  g.row.assign(static_cast<size_t>(n), -1);
  g.free.clear();
  for (int i = 0; i < n; ++i)
    if (inStep(model, p, i)) {
      g.row[i] = static_cast<int>(g.free.size());
      g.free.push_back(i);
    }
  g.constraints = st.ids.size();
  g.edges.clear();
  for (size_t k = 0; k < st.ids.size(); ++k)
    if (st.compliance[k] == 0.0f && (g.row[st.ids[k][0]] >= 0 || g.row[st.ids[k][1]] >= 0))
      g.edges.push_back(static_cast<int>(k));
  findComponents(st, g);
  const int m = static_cast<int>(g.free.size());
  const bool dry = model.clothDryMass.size() == static_cast<size_t>(n);
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(static_cast<size_t>(m) + 3 * g.edges.size());
  double mean = 0.0;
  for (int r = 0; r < m; ++r) {
    const double mass = dry ? double(model.clothDryMass[g.free[r]]) : double(p.mass[g.free[r]]);
    mean += mass;
    t.emplace_back(r, r, mass);
  }
  g.weight = kGlobalStretchWeight * mean / std::max(m, 1);
  for (int k : g.edges) {
    const int a = g.row[st.ids[k][0]], b = g.row[st.ids[k][1]];
    if (a >= 0) t.emplace_back(a, a, g.weight);
    if (b >= 0) t.emplace_back(b, b, g.weight);
    if (a >= 0 && b >= 0) t.emplace_back(std::max(a, b), std::min(a, b), -g.weight);
  }
  Eigen::SparseMatrix<double> A(m, m);
  A.setFromTriplets(t.begin(), t.end());
  g.ldlt.compute(A);
  // M + w L with M > 0 is positive definite: a failure means a mass that is not a finite positive number
  if (g.ldlt.info() != Eigen::Success)
    throw std::runtime_error("the PBD cloth's global stretch step could not factor its system (a cloth particle's "
                             "mass is not a finite positive number)");
}

// g.delta = A^-1 g.misfit (a coordinate a thread), then each component that nothing holds shifted so
// that sum_i m_i delta_i = 0 with the present (wet) masses: A's dry M gives sum_i m_dry,i delta_i = 0,
// and L has no other null space, so the shift is all the wet masses change beyond O(m / w)
void solve(const Particles& p, GlobalStretch& g) {
  Eigen::MatrixXd& delta = g.delta;
  delta.resize(g.misfit.rows(), 3);
  parallelFor(3, [&](int64_t c) { delta.col(c) = g.ldlt.solve(g.misfit.col(c)); });
  if (g.components == 0) return;
  Eigen::MatrixXd momentum = Eigen::MatrixXd::Zero(g.components, 3);
  Eigen::VectorXd mass = Eigen::VectorXd::Zero(g.components);
  for (size_t q = 0; q < g.free.size(); ++q) {
    const int c = g.component[q];
    if (c < 0) continue;
    const double m = p.mass[g.free[q]];
    momentum.row(c) += m * delta.row(static_cast<Eigen::Index>(q));
    mass[c] += m;
  }
  for (size_t q = 0; q < g.free.size(); ++q)
    if (g.component[q] >= 0) delta.row(static_cast<Eigen::Index>(q)) -= momentum.row(g.component[q]) / mass[g.component[q]];
}

}  // namespace

void GlobalStretchDeleter::operator()(GlobalStretch* g) const { delete g; }

// x* + delta with (M + w L) delta = r, r_i = sum over i's edges of +-w (d_e - x_ij), minimises
// sum_i m_i |delta_i|^2 / 2 + w sum_e |x_ij + delta_ij - d_e|^2 / 2, d_e the edge at its rest length
// along its present direction (the local step); the three coordinates solved on the threads
void globalStretchStep(const Model& model, Particles& p, ClothScratch& scratch) {
  if (!model.solver.clothGlobalStretch || model.numCloth == 0 || model.stretch.ids.empty()) return;
  if (!scratch.globalStretch || scratch.globalStretch->row.size() != static_cast<size_t>(model.numCloth) ||
      scratch.globalStretch->constraints != model.stretch.ids.size()) {
    scratch.globalStretch.reset(new GlobalStretch);
    build(model, p, *scratch.globalStretch);
  }
  GlobalStretch& g = *scratch.globalStretch;
  if (g.free.empty() || g.edges.empty()) return;
  const StretchConstraints& st = model.stretch;
  const Eigen::Index m = static_cast<Eigen::Index>(g.free.size());
  Eigen::MatrixXd& r = g.misfit;
  r.setZero(m, 3);
  for (int k : g.edges) {
    const int i = st.ids[k][0], j = st.ids[k][1];
    const Vec3d e = p.xPred[i].cast<double>() - p.xPred[j].cast<double>();
    const double len = e.norm();
    if (!(len > 1e-12)) continue;  // coincident ends: no direction to restore
    const Vec3d f = g.weight * (double(st.restLength[k]) / len - 1.0) * e;
    if (g.row[i] >= 0) r.row(g.row[i]) += f.transpose();
    if (g.row[j] >= 0) r.row(g.row[j]) -= f.transpose();
  }
  solve(p, g);
  for (Eigen::Index q = 0; q < m; ++q) p.xPred[g.free[q]] += g.delta.row(q).transpose().cast<float>();
}

}  // namespace soak
