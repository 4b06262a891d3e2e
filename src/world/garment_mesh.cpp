// procedural garments. The panels are laid out on one lattice in the body's frontal plane (x right-
// to-left, y up): a torso block from the hem to the shoulders, and for a T-shirt two sleeve blocks
// mapped bilinearly along the upper arms. Lattice boundary edges are seams (front and back share
// the vertex, placed on the body's mid plane z = 0 outside its silhouette) or openings (hem, neck,
// sleeve ends, armholes: front and back keep their own vertex). Each non-seam vertex is projected
// along z onto the front / back offset surface of the body (distance margin + ease), found by sphere
// tracing the colliders' exact distance.
#include "world/garment_mesh.hpp"

#include <soak/error.hpp>

#include "world/colliders.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <functional>

namespace soak {

namespace {

// a subset of the body's colliders, posed at one time
struct BodyQuery {
  std::vector<Collider> colliders;
  std::vector<ColliderPose> poses;
  float distance(const Vec3& p) const {
    float d = 1e30f;
    for (size_t c = 0; c < colliders.size(); ++c) d = std::min(d, colliderDistance(colliders[c], poses[c], p, nullptr));
    return d;
  }
};

BodyQuery select(const std::vector<Collider>& all, const std::function<bool(const std::string&)>& keep) {
  BodyQuery q;
  for (const Collider& c : all)
    if (keep(c.name)) {
      q.colliders.push_back(c);
      q.poses.push_back(colliderPose(c, c.keys.empty() ? 0.0 : c.keys.front().time));
    }
  return q;
}

bool has(const std::string& name, const char* part) { return name.find(part) != std::string::npos; }
bool isLowerArm(const std::string& n) { return has(n, "forearm") || has(n, "hand"); }
bool isArm(const std::string& n) { return isLowerArm(n) || has(n, "upper_arm"); }

// first s in [0, length] where the body is within `offset` of o + s dir, or -1. Sphere tracing is
// safe: the union's distance (a min of exact distances) never overestimates
float march(const BodyQuery& b, const Vec3& o, const Vec3& dir, float length, float offset) {
  float s = 0.0f;
  for (int it = 0; it < 512 && s <= length; ++it) {
    const float d = b.distance(o + s * dir) - offset;
    if (d <= 1e-4f) return s;
    s += d;
  }
  return -1.0f;
}

// largest |x| of the body over heights [y0, y1] (and all depths), by tracing from both sides
float silhouetteHalfWidth(const BodyQuery& b, float y0, float y1, float H, float step) {
  const float far = 0.6f * H;
  float w = 0.0f;
  const int ny = std::max(2, static_cast<int>(std::ceil((y1 - y0) / step)) + 1);
  const int nz = static_cast<int>(std::ceil(2.0f * far / step)) + 1;
  for (int j = 0; j < ny; ++j) {
    const float y = y0 + (y1 - y0) * static_cast<float>(j) / static_cast<float>(ny - 1);
    for (int k = 0; k < nz; ++k) {
      const float z = -far + 2.0f * far * static_cast<float>(k) / static_cast<float>(nz - 1);
      for (float side : {1.0f, -1.0f}) {
        const float s = march(b, Vec3(side * far, y, z), Vec3(-side, 0, 0), far, 0.0f);
        if (s >= 0.0f) w = std::max(w, far - s);
      }
    }
  }
  return w;
}

// highest point of the body over |x| in [x0, x1] (all depths), tracing downwards
float topOf(const BodyQuery& b, float x0, float x1, float H, float step) {
  const float far = 0.6f * H, y0 = 1.2f * H;
  float top = -1e30f;
  const int nx = std::max(2, static_cast<int>(std::ceil((x1 - x0) / step)) + 1);
  const int nz = static_cast<int>(std::ceil(2.0f * far / step)) + 1;
  for (int i = 0; i < nx; ++i) {
    const float x = x0 + (x1 - x0) * static_cast<float>(i) / static_cast<float>(nx - 1);
    for (int k = 0; k < nz; ++k) {
      const float z = -far + 2.0f * far * static_cast<float>(k) / static_cast<float>(nz - 1);
      for (float side : {1.0f, -1.0f}) {
        const float s = march(b, Vec3(side * x, y0, z), Vec3(0, -1, 0), y0, 0.0f);
        if (s >= 0.0f) top = std::max(top, y0 - s);
      }
    }
  }
  return top;
}

using Vec2 = Eigen::Vector2f;

// one sleeve in the side's mirrored frame (x grows away from the body's mid plane)
struct SleeveFrame {
  Vec2 shoulder, axis, up;  // joint, unit arm direction, unit normal pointing up
  float radius = 0.0f, length = 0.0f;
};

void checkParams(const GarmentPattern& g, const std::string& source) {
  const std::string w = "garment";
  if (!(g.edgeLength > 0.0f)) throw errorAt(source, w + ".edgeLength", "must be a positive length in m");
  if (!(g.margin >= 0.0f)) throw errorAt(source, w + ".margin", "must be >= 0 m");
  if (!(g.ease >= 0.0f)) throw errorAt(source, w + ".ease", "must be >= 0 m");
  if (!(g.hem >= 0.0f && g.hem < 0.75f)) throw errorAt(source, w + ".hem", "must be a fraction of the height in [0, 0.75)");
  if (!(g.sleeveLength > 0.0f && g.sleeveLength <= 1.0f))
    throw errorAt(source, w + ".sleeveLength", "must be a fraction of the upper arm in (0, 1]");
  if (!(g.neckOpening >= 0.0f)) throw errorAt(source, w + ".neckOpening", "must be >= 0 m");
  if (!(g.flare >= 0.0f && g.flare < 1.2f)) throw errorAt(source, w + ".flare", "must be an angle in [0, 1.2) rad");
}

// the body in the garment's frame: at the origin without yaw or root offset, standing in `pose`
MannequinParams garmentFrameBody(const MannequinParams& bodyIn, const MannequinPose& pose) {
  MannequinParams body = bodyIn;
  body.position = Vec3::Zero();
  body.yaw = 0.0f;
  body.pose = pose;
  body.pose.rootOffset = Vec3::Zero();
  return body;
}

// the subsets of the body the panels are traced against: all of it (sleeves), all but the forearms and
// hands (torso panels), the torso alone (side seams), the torso and upper arms (shoulder line)
struct BodyParts {
  BodyQuery whole, noLowerArms, torso, shoulders;
};

BodyParts bodyParts(const std::vector<Collider>& all) {
  BodyParts b;
  b.whole = select(all, [](const std::string&) { return true; });
  b.noLowerArms = select(all, [](const std::string& n) { return !isLowerArm(n); });
  b.torso = select(all, [](const std::string& n) { return !isArm(n); });
  b.shoulders =
      select(all, [](const std::string& n) { return !isLowerArm(n) && !has(n, "head") && !has(n, "neck"); });
  return b;
}

// both upper arms in their sides' mirrored frames; throws when an arm hangs too steeply for a sleeve
// or an armhole
std::array<SleeveFrame, 2> sleeveFrames(const MannequinParams& body, const MannequinJoints& J, float H,
                                        const std::string& source) {
  std::array<SleeveFrame, 2> arm;
  for (int s = 0; s < 2; ++s) {
    const float sgn = s == kLeft ? 1.0f : -1.0f;
    SleeveFrame& a = arm[s];
    a.shoulder = Vec2(sgn * J.shoulder[s].x(), J.shoulder[s].y());
    const Vec3 d3 = J.elbow[s] - J.shoulder[s];
    a.length = d3.norm();
    a.axis = Vec2(sgn * d3.x(), d3.y()).normalized();
    a.up = Vec2(-a.axis.y(), a.axis.x());
    if (a.up.y() < 0.0f) a.up = -a.up;
    a.radius = body.upperArmRadius * H;
    if (!(a.up.y() > 0.25f) || !(a.axis.x() > 0.0f))
      throw errorAt(source, "garment", "the arms hang too close to the body for a garment; raise the pose's "
                                       "shoulderAbduction (>= 0.3 rad for a dress, 0.7 rad for a tshirt)");
  }
  return arm;
}

// the armpit: where the side seam x = xSide passes (radius + gap) below the upper arm's axis
float armpitFor(const std::array<SleeveFrame, 2>& arm, float gap, float xSide) {
  float y = 1e30f;
  for (const SleeveFrame& a : arm)
    y = std::min(y, a.shoulder.y() + (-(a.radius + gap) - (xSide - a.shoulder.x()) * a.up.x()) / a.up.y());
  return y;
}

// the torso panels' outline in the frontal plane (m, body frame): hem, armpit and shoulder-top heights,
// the half-width at the side seams and of the neck opening
struct TorsoOutline {
  float hemY = 0.0f, armpitY = 0.0f, yTop = 0.0f, halfWidth = 0.0f, neckHalf = 0.0f;
};

// the side seams clear the torso's silhouette by gap up to the armpit, which itself depends on the
// seams' x: traced twice
TorsoOutline torsoOutline(const BodyParts& b, const std::array<SleeveFrame, 2>& arm, const MannequinParams& body,
                          const GarmentPattern& gp, bool tshirt, const std::string& source) {
  const float H = body.height, e = gp.edgeLength, gap = gp.margin + gp.ease;
  TorsoOutline o;
  o.hemY = (gp.hem > 0.0f ? gp.hem : (tshirt ? 0.48f : 0.25f)) * H;
  float hwTorso = silhouetteHalfWidth(b.torso, o.hemY, 0.70f * H, H, 0.5f * e) + gap;
  float armpitY = armpitFor(arm, gap, hwTorso);
  hwTorso = std::max(hwTorso, silhouetteHalfWidth(b.torso, o.hemY, armpitY, H, 0.5f * e) + gap);
  armpitY = armpitFor(arm, gap, hwTorso);
  o.halfWidth = hwTorso;
  o.armpitY = armpitY;
  o.neckHalf = body.neckRadius * H + gap + gp.neckOpening;
  o.yTop = topOf(b.shoulders, o.neckHalf, hwTorso, H, 0.5f * e) + gap;
  if (!(armpitY > o.hemY + 2.0f * e) || !(o.yTop > armpitY + 2.0f * e))
    throw errorAt(source, "garment", "the armpit falls below the hem; raise the pose's shoulderAbduction or the hem");
  return o;
}

// the panels' lattice in the frontal plane: rows j in [0, Ht] (Hb from the hem to the armpit, K on to
// the shoulders), columns i in [iMin, iMax]: the torso's [0, W], then for a T-shirt S[kRight] columns
// of the right sleeve (-x) before it and S[kLeft] of the left sleeve after it
struct Lattice {
  bool tshirt = false;
  TorsoOutline outline;
  float pelvisY = 0.0f, flare = 0.0f;
  int Hb = 0, K = 0, Ht = 0, W = 0;
  std::array<Vec2, 2> A0, A1, E0, E1;  // sleeve corners: armpit, shoulder (at the torso), lower and upper end
  std::array<int, 2> S{0, 0};
  int iMin = 0, iMax = 0, nI = 0, nJ = 0;

  float rowY(int j) const {
    const float hemY = outline.hemY, armpitY = outline.armpitY, yTop = outline.yTop;
    return j <= Hb ? hemY + (armpitY - hemY) * static_cast<float>(j) / static_cast<float>(Hb)
                   : armpitY + (yTop - armpitY) * static_cast<float>(j - Hb) / static_cast<float>(K);
  }
  // the torso's half-width at row j: a dress flares out below the pelvis
  float rowHalfWidth(int j) const {
    const float y = rowY(j);
    if (tshirt || y >= pelvisY) return outline.halfWidth;
    return outline.halfWidth + (pelvisY - y) * std::tan(flare);
  }
  // whether the lattice cell with lower left corner (i, j) is cloth
  bool cell(int i, int j) const {
    if (j < 0 || j >= Ht) return false;
    if (i >= 0 && i < W) return true;
    return tshirt && j >= Hb && i >= iMin && i < iMax;
  }
  // lattice vertex (i, j) in the frontal plane: rows across the torso, bilinear across a sleeve
  Vec2 pos2(int i, int j) const {
    if (i >= 0 && i <= W) {
      const float hw = rowHalfWidth(j);
      return Vec2(-hw + 2.0f * hw * static_cast<float>(i) / static_cast<float>(W), rowY(j));
    }
    const int s = i > W ? kLeft : kRight;
    const float u = s == kLeft ? static_cast<float>(i - W) / static_cast<float>(S[s])
                               : static_cast<float>(-i) / static_cast<float>(S[s]);
    const float v = static_cast<float>(j - Hb) / static_cast<float>(K);
    Vec2 p = (1.0f - u) * ((1.0f - v) * A0[s] + v * A1[s]) + u * ((1.0f - v) * E0[s] + v * E1[s]);
    if (s == kRight) p.x() = -p.x();
    return p;
  }
  int id2(int i, int j) const { return (i - iMin) + nI * j; }
  size_t numVertices() const { return static_cast<size_t>(nI) * nJ; }
};

// a T-shirt's sleeves: each a quad from the torso's side (armpit to shoulder top) to a cut across the
// upper arm at sleeveLength, with its number of columns; throws when a sleeve would reach into the torso
void laySleeves(Lattice& L, const std::array<SleeveFrame, 2>& arm, const GarmentPattern& gp,
                const std::string& source) {
  const float e = gp.edgeLength, gap = gp.margin + gp.ease;
  const float hwTorso = L.outline.halfWidth, armpitY = L.outline.armpitY, yTop = L.outline.yTop;
  for (int s = 0; s < 2; ++s) {
    const SleeveFrame& a = arm[s];
    const Vec2 c = a.shoulder + gp.sleeveLength * a.length * a.axis;
    const float r = a.radius + gap;
    L.A0[s] = Vec2(hwTorso, armpitY);
    L.A1[s] = Vec2(hwTorso, yTop);
    L.E0[s] = c - r * a.up;
    L.E1[s] = c + r * a.up;
    if (!(L.E0[s].x() > hwTorso + 0.5f * e))
      throw errorAt(source, "garment", std::string("the ") + (s == kLeft ? "left" : "right") +
                                           " sleeve would run into the torso; raise the pose's shoulderAbduction "
                                           "(0.7 rad works at default proportions) or the sleeveLength");
    L.S[s] = std::max(2, static_cast<int>(std::lround((c - 0.5f * (L.A0[s] + L.A1[s])).norm() / e)));
  }
}

// the lattice's sizes at about one edgeLength per step
Lattice layLattice(const TorsoOutline& o, const std::array<SleeveFrame, 2>& arm, const MannequinJoints& J,
                   const GarmentPattern& gp, bool tshirt, const std::string& source) {
  const float e = gp.edgeLength;
  Lattice L;
  L.tshirt = tshirt;
  L.outline = o;
  L.flare = gp.flare;
  L.Hb = std::max(2, static_cast<int>(std::lround((o.armpitY - o.hemY) / e)));
  L.K = std::max(2, static_cast<int>(std::lround((o.yTop - o.armpitY) / e)));
  L.Ht = L.Hb + L.K;
  L.W = std::max(4, 2 * static_cast<int>(std::lround(o.halfWidth / e)));
  if (tshirt) laySleeves(L, arm, gp, source);
  L.pelvisY = J.pelvis.y();
  L.iMin = -L.S[kRight];
  L.iMax = L.W + L.S[kLeft];
  L.nI = L.iMax - L.iMin + 1;
  L.nJ = L.Ht + 1;
  return L;
}

// per lattice vertex: exists (a corner of a cloth cell) and shared (on a seam: one vertex for front
// and back); seams are the boundary lattice edges that are not openings (hem, neck, sleeve ends,
// armholes)
struct LatticeVertices {
  std::vector<uint8_t> exists, shared;
};

LatticeVertices markSeams(const Lattice& L) {
  const int iMin = L.iMin, iMax = L.iMax;
  LatticeVertices v;
  std::vector<uint8_t>& exists = v.exists;
  std::vector<uint8_t>& shared = v.shared;
  exists.assign(L.numVertices(), 0);
  shared.assign(exists.size(), 0);
  for (int j = 0; j < L.nJ; ++j)
    for (int i = iMin; i <= iMax; ++i)
      if (L.cell(i, j) || L.cell(i - 1, j) || L.cell(i, j - 1) || L.cell(i - 1, j - 1)) exists[L.id2(i, j)] = 1;
  for (int j = 0; j < L.nJ; ++j)
    for (int i = iMin; i <= iMax; ++i) {
      if (i < iMax && (L.cell(i, j) != L.cell(i, j - 1))) {  // horizontal edge (i, j)-(i + 1, j)
        const float xm = 0.5f * (L.pos2(i, j).x() + L.pos2(i + 1, j).x());
        const bool neck = j == L.Ht && i >= 0 && i < L.W && std::fabs(xm) < L.outline.neckHalf;
        if (j != 0 && !neck) shared[L.id2(i, j)] = shared[L.id2(i + 1, j)] = 1;
      }
      if (j < L.Ht && (L.cell(i, j) != L.cell(i - 1, j))) {  // vertical edge (i, j)-(i, j + 1)
        const bool sleeveEnd = L.tshirt && (i == iMin || i == iMax);
        const bool armhole = !L.tshirt && j >= L.Hb;
        if (!sleeveEnd && !armhole) shared[L.id2(i, j)] = shared[L.id2(i, j + 1)] = 1;
      }
    }
  return v;
}

// lattice steps to the nearest seam (breadth first): the cloth leaves the mid plane over two steps
std::vector<int> stepsToSeam(const Lattice& L, const LatticeVertices& lv) {
  const int iMin = L.iMin, iMax = L.iMax, nI = L.nI, nJ = L.nJ;
  const std::vector<uint8_t>& exists = lv.exists;
  std::vector<int> steps(exists.size(), 1 << 20);
  std::deque<int> queue;
  for (size_t v = 0; v < exists.size(); ++v)
    if (exists[v] && lv.shared[v]) steps[v] = 0, queue.push_back(static_cast<int>(v));
  while (!queue.empty()) {
    const int v = queue.front();
    queue.pop_front();
    const int i = v % nI + iMin, j = v / nI;
    const int ni[4] = {i + 1, i - 1, i, i}, nj[4] = {j, j, j + 1, j - 1};
    for (int k = 0; k < 4; ++k) {
      if (ni[k] < iMin || ni[k] > iMax || nj[k] < 0 || nj[k] >= nJ) continue;
      const int w = L.id2(ni[k], nj[k]);
      if (!exists[w] || steps[w] <= steps[v] + 1) continue;
      steps[w] = steps[v] + 1;
      queue.push_back(w);
    }
  }
  return steps;
}

// the mesh vertex of each lattice vertex on the front and on the back panel (the same one on a seam)
struct PanelIndices {
  std::vector<int> front, back;
};

// the garment's vertices in the world: a seam vertex on the mid plane z = 0, the others projected
// along z onto the body's front / back offset surface (gap), at least `bulge` off the mid plane near
// a seam; then moved with the body's yaw and position
PanelIndices placeVertices(Garment& g, const Lattice& L, const LatticeVertices& lv, const std::vector<int>& steps,
                           const BodyParts& b, const MannequinParams& bodyIn, const MannequinPose& pose,
                           const GarmentPattern& gp) {
  const float gap = gp.margin + gp.ease;
  const int iMin = L.iMin, iMax = L.iMax, nJ = L.nJ, W = L.W;
  const Quat root(Eigen::AngleAxisf(bodyIn.yaw, Vec3::UnitY()));
  const Vec3 origin = bodyIn.position + pose.rootOffset;
  const float far = 0.6f * bodyIn.height;
  PanelIndices idx{std::vector<int>(lv.exists.size(), -1), std::vector<int>(lv.exists.size(), -1)};
  for (int j = 0; j < nJ; ++j)
    for (int i = iMin; i <= iMax; ++i) {
      const int v = L.id2(i, j);
      if (!lv.exists[v]) continue;
      const Vec2 p = L.pos2(i, j);
      const bool sleeve = i < 0 || i > W;
      const int sleevePanel = i > W ? kPanelLeftSleeve : kPanelRightSleeve;
      auto add = [&](float z, int panel) {
        g.mesh.vertices.push_back(origin + root * Vec3(p.x(), p.y(), z));
        g.panelOfVertex.push_back(panel);
        return static_cast<int>(g.mesh.vertices.size()) - 1;
      };
      if (lv.shared[v]) {
        idx.front[v] = idx.back[v] = add(0.0f, sleeve ? sleevePanel : kPanelFront);
        continue;
      }
      const BodyQuery& q = sleeve ? b.whole : b.noLowerArms;
      const float bulge = gap * static_cast<float>(std::min(steps[v], 2)) / 2.0f;
      const float sf = march(q, Vec3(p.x(), p.y(), far), Vec3(0, 0, -1), 2.0f * far, gap);
      const float sb = march(q, Vec3(p.x(), p.y(), -far), Vec3(0, 0, 1), 2.0f * far, gap);
      const float zf = sf >= 0.0f ? std::max(far - sf, bulge) : bulge;
      const float zb = sb >= 0.0f ? std::min(-far + sb, -bulge) : -bulge;
      idx.front[v] = add(zf, sleeve ? sleevePanel : kPanelFront);
      idx.back[v] = add(zb, sleeve ? sleevePanel : kPanelBack);
    }
  return idx;
}

// two triangles per cell, on the diagonal that does not join two seam vertices (that edge would
// be in four triangles); front wound towards +z, back towards -z
void triangulate(Garment& g, const Lattice& L, const LatticeVertices& lv, const PanelIndices& panels,
                 const std::string& source) {
  const std::vector<uint8_t>& shared = lv.shared;
  for (int j = 0; j < L.Ht; ++j)
    for (int i = L.iMin; i < L.iMax; ++i) {
      if (!L.cell(i, j)) continue;
      const int c00 = L.id2(i, j), c10 = L.id2(i + 1, j), c11 = L.id2(i + 1, j + 1), c01 = L.id2(i, j + 1);
      const bool badMain = shared[c00] && shared[c11], badAnti = shared[c10] && shared[c01];
      if (badMain && badAnti)
        throw errorAt(source, "garment", "the panels are too narrow for the edge length; use a smaller edgeLength");
      const bool anti = badMain || (!badAnti && ((i + j) & 1));
      for (int side = 0; side < 2; ++side) {
        const std::vector<int>& idx = side == 0 ? panels.front : panels.back;
        std::array<int, 3> t0, t1;
        if (anti) {
          t0 = {idx[c00], idx[c10], idx[c01]};
          t1 = {idx[c10], idx[c11], idx[c01]};
        } else {
          t0 = {idx[c00], idx[c10], idx[c11]};
          t1 = {idx[c00], idx[c11], idx[c01]};
        }
        if (side == 1) std::swap(t0[1], t0[2]), std::swap(t1[1], t1[2]);
        g.mesh.triangles.push_back(t0);
        g.mesh.triangles.push_back(t1);
      }
    }
}

}  // namespace

PosedBody::PosedBody(const std::vector<Collider>& body, double t) : colliders(&body) {
  poses.reserve(body.size());
  for (const Collider& c : body) poses.push_back(colliderPose(c, t));
}

float PosedBody::distance(const Vec3& p, Vec3* normal) const {
  float best = 1e30f;
  for (size_t c = 0; c < colliders->size(); ++c) {
    Vec3 n = Vec3::UnitY();
    const float d = colliderDistance((*colliders)[c], poses[c], p, &n);
    if (d < best) {
      best = d;
      if (normal) *normal = n;
    }
  }
  return best;
}

float bodyDistance(const std::vector<Collider>& body, double t, const Vec3& p, Vec3* normal) {
  return PosedBody(body, t).distance(p, normal);
}

std::vector<int> verticesInsideBody(const TriangleMesh& mesh, const std::vector<Collider>& body, double t,
                                    float margin) {
  std::vector<int> inside;
  const PosedBody posed(body, t);
  for (int v = 0; v < static_cast<int>(mesh.vertices.size()); ++v)
    if (posed.distance(mesh.vertices[v], nullptr) < margin - 1e-5f) inside.push_back(v);
  return inside;
}

size_t pushOutOfBody(TriangleMesh& mesh, const std::vector<Collider>& body, double t, float margin, int iterations) {
  size_t left = 0;
  const PosedBody posed(body, t);
  for (Vec3& x : mesh.vertices) {
    for (int it = 0; it < iterations; ++it) {
      Vec3 n = Vec3::UnitY();
      const float d = posed.distance(x, &n);
      if (d >= margin) break;
      // a little past the margin so rounding leaves it outside
      x += (margin - d + 1e-5f) * n;
    }
    if (posed.distance(x, nullptr) >= margin - 1e-5f) continue;
    // stuck in a crease where two parts push it back and forth: the shortest way out along the 26
    // lattice directions, in 2 mm steps up to half a metre
    float bestS = 1e30f;
    Vec3 best = x;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          if (dx == 0 && dy == 0 && dz == 0) continue;
          const Vec3 dir = Vec3(static_cast<float>(dx), static_cast<float>(dy), static_cast<float>(dz)).normalized();
          for (float s = 0.002f; s < std::min(bestS, 0.5f); s += 0.002f)
            if (posed.distance(x + s * dir, nullptr) >= margin) {
              bestS = s;
              best = x + s * dir;
              break;
            }
        }
    x = best;
    if (posed.distance(x, nullptr) < margin - 1e-5f) ++left;
  }
  return left;
}

Garment buildGarment(const MannequinParams& bodyIn, const MannequinPose& pose, const GarmentPattern& gp,
                     const std::string& source) {
  checkParams(gp, source);
  const bool tshirt = gp.style == GarmentStyle::TShirt;
  // the body frame: garment built there, then moved with the body's yaw and position
  const MannequinParams body = garmentFrameBody(bodyIn, pose);
  const std::vector<Collider> all = buildMannequin(body, {}, 0.5f, "body", source);
  const BodyParts parts = bodyParts(all);
  const MannequinJoints J = mannequinJoints(body, body.pose);
  const std::array<SleeveFrame, 2> arm = sleeveFrames(body, J, body.height, source);
  const TorsoOutline outline = torsoOutline(parts, arm, body, gp, tshirt, source);
  const Lattice lattice = layLattice(outline, arm, J, gp, tshirt, source);
  const LatticeVertices lv = markSeams(lattice);
  const std::vector<int> steps = stepsToSeam(lattice, lv);

  Garment g;
  g.panelNames = tshirt ? std::vector<std::string>{"front", "back", "left_sleeve", "right_sleeve"}
                        : std::vector<std::string>{"front", "back"};
  const PanelIndices panels = placeVertices(g, lattice, lv, steps, parts, bodyIn, pose, gp);
  triangulate(g, lattice, lv, panels, source);
  // start clear of the body everywhere (chords near round parts and seams by the shoulders)
  MannequinParams world = bodyIn;
  world.pose = pose;
  const std::vector<Collider> posed = buildMannequin(world, {}, 0.5f, "body", source);
  const size_t left = pushOutOfBody(g.mesh, posed, 0.0, gp.margin);
  if (left > 0)
    throw errorAt(source, "garment", std::to_string(left) + " vertices stay inside the body; raise the pose's "
                                                           "shoulderAbduction or the ease");
  return g;
}

}  // namespace soak
