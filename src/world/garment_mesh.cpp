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

}  // namespace

float bodyDistance(const std::vector<Collider>& body, double t, const Vec3& p, Vec3* normal) {
  float best = 1e30f;
  for (const Collider& c : body) {
    Vec3 n = Vec3::UnitY();
    const float d = colliderDistance(c, colliderPose(c, t), p, &n);
    if (d < best) {
      best = d;
      if (normal) *normal = n;
    }
  }
  return best;
}

std::vector<int> verticesInsideBody(const TriangleMesh& mesh, const std::vector<Collider>& body, double t,
                                    float margin) {
  std::vector<int> inside;
  for (int v = 0; v < static_cast<int>(mesh.vertices.size()); ++v)
    if (bodyDistance(body, t, mesh.vertices[v], nullptr) < margin - 1e-5f) inside.push_back(v);
  return inside;
}

size_t pushOutOfBody(TriangleMesh& mesh, const std::vector<Collider>& body, double t, float margin, int iterations) {
  size_t left = 0;
  for (Vec3& x : mesh.vertices) {
    for (int it = 0; it < iterations; ++it) {
      Vec3 n = Vec3::UnitY();
      const float d = bodyDistance(body, t, x, &n);
      if (d >= margin) break;
      // a little past the margin so rounding leaves it outside
      x += (margin - d + 1e-5f) * n;
    }
    if (bodyDistance(body, t, x, nullptr) >= margin - 1e-5f) continue;
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
            if (bodyDistance(body, t, x + s * dir, nullptr) >= margin) {
              bestS = s;
              best = x + s * dir;
              break;
            }
        }
    x = best;
    if (bodyDistance(body, t, x, nullptr) < margin - 1e-5f) ++left;
  }
  return left;
}

Garment buildGarment(const MannequinParams& bodyIn, const MannequinPose& pose, const GarmentPattern& gp,
                     const std::string& source) {
  checkParams(gp, source);
  const bool tshirt = gp.style == GarmentStyle::TShirt;
  // the body frame: garment built there, then moved with the body's yaw and position
  MannequinParams body = bodyIn;
  body.position = Vec3::Zero();
  body.yaw = 0.0f;
  body.pose = pose;
  body.pose.rootOffset = Vec3::Zero();
  const std::vector<Collider> all = buildMannequin(body, {}, 0.5f, "body", source);
  const BodyQuery whole = select(all, [](const std::string&) { return true; });
  const BodyQuery noLowerArms = select(all, [](const std::string& n) { return !isLowerArm(n); });
  const BodyQuery torso = select(all, [](const std::string& n) { return !isArm(n); });
  const BodyQuery shoulders =
      select(all, [](const std::string& n) { return !isLowerArm(n) && !has(n, "head") && !has(n, "neck"); });
  const MannequinJoints J = mannequinJoints(body, body.pose);
  const float H = body.height, e = gp.edgeLength, gap = gp.margin + gp.ease;
  const float hemY = (gp.hem > 0.0f ? gp.hem : (tshirt ? 0.48f : 0.25f)) * H;

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
  // the armpit: where the side seam x = xSide passes (radius + gap) below the upper arm's axis
  auto armpitFor = [&](float xSide) {
    float y = 1e30f;
    for (const SleeveFrame& a : arm)
      y = std::min(y, a.shoulder.y() + (-(a.radius + gap) - (xSide - a.shoulder.x()) * a.up.x()) / a.up.y());
    return y;
  };
  float hwTorso = silhouetteHalfWidth(torso, hemY, 0.70f * H, H, 0.5f * e) + gap;
  float armpitY = armpitFor(hwTorso);
  hwTorso = std::max(hwTorso, silhouetteHalfWidth(torso, hemY, armpitY, H, 0.5f * e) + gap);
  armpitY = armpitFor(hwTorso);
  const float neckHalf = body.neckRadius * H + gap + gp.neckOpening;
  const float yTop = topOf(shoulders, neckHalf, hwTorso, H, 0.5f * e) + gap;
  if (!(armpitY > hemY + 2.0f * e) || !(yTop > armpitY + 2.0f * e))
    throw errorAt(source, "garment", "the armpit falls below the hem; raise the pose's shoulderAbduction or the hem");

  // lattice sizes
  const int Hb = std::max(2, static_cast<int>(std::lround((armpitY - hemY) / e)));
  const int K = std::max(2, static_cast<int>(std::lround((yTop - armpitY) / e)));
  const int Ht = Hb + K;
  const int W = std::max(4, 2 * static_cast<int>(std::lround(hwTorso / e)));
  std::array<Vec2, 2> A0, A1, E0, E1;
  std::array<int, 2> S{0, 0};
  if (tshirt) {
    for (int s = 0; s < 2; ++s) {
      const SleeveFrame& a = arm[s];
      const Vec2 c = a.shoulder + gp.sleeveLength * a.length * a.axis;
      const float r = a.radius + gap;
      A0[s] = Vec2(hwTorso, armpitY);
      A1[s] = Vec2(hwTorso, yTop);
      E0[s] = c - r * a.up;
      E1[s] = c + r * a.up;
      if (!(E0[s].x() > hwTorso + 0.5f * e))
        throw errorAt(source, "garment", std::string("the ") + (s == kLeft ? "left" : "right") +
                                             " sleeve would run into the torso; raise the pose's shoulderAbduction "
                                             "(0.7 rad works at default proportions) or the sleeveLength");
      S[s] = std::max(2, static_cast<int>(std::lround((c - 0.5f * (A0[s] + A1[s])).norm() / e)));
    }
  }
  const float pelvisY = J.pelvis.y();
  auto rowY = [&](int j) {
    return j <= Hb ? hemY + (armpitY - hemY) * static_cast<float>(j) / static_cast<float>(Hb)
                   : armpitY + (yTop - armpitY) * static_cast<float>(j - Hb) / static_cast<float>(K);
  };
  auto rowHalfWidth = [&](int j) {
    const float y = rowY(j);
    if (tshirt || y >= pelvisY) return hwTorso;
    return hwTorso + (pelvisY - y) * std::tan(gp.flare);
  };
  // lattice columns i in [-S_right, W + S_left]; the right sleeve (-x) is on the left of the index range
  const int iMin = -S[kRight], iMax = W + S[kLeft];
  const int nI = iMax - iMin + 1, nJ = Ht + 1;
  auto cell = [&](int i, int j) {
    if (j < 0 || j >= Ht) return false;
    if (i >= 0 && i < W) return true;
    return tshirt && j >= Hb && i >= iMin && i < iMax;
  };
  auto pos2 = [&](int i, int j) -> Vec2 {
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
  };
  auto id2 = [&](int i, int j) { return (i - iMin) + nI * j; };
  std::vector<uint8_t> exists(static_cast<size_t>(nI) * nJ, 0), shared(exists.size(), 0);
  for (int j = 0; j < nJ; ++j)
    for (int i = iMin; i <= iMax; ++i)
      if (cell(i, j) || cell(i - 1, j) || cell(i, j - 1) || cell(i - 1, j - 1)) exists[id2(i, j)] = 1;
  // seams: boundary lattice edges that are not openings
  for (int j = 0; j < nJ; ++j)
    for (int i = iMin; i <= iMax; ++i) {
      if (i < iMax && (cell(i, j) != cell(i, j - 1))) {  // horizontal edge (i, j)-(i + 1, j)
        const float xm = 0.5f * (pos2(i, j).x() + pos2(i + 1, j).x());
        const bool neck = j == Ht && i >= 0 && i < W && std::fabs(xm) < neckHalf;
        if (j != 0 && !neck) shared[id2(i, j)] = shared[id2(i + 1, j)] = 1;
      }
      if (j < Ht && (cell(i, j) != cell(i - 1, j))) {  // vertical edge (i, j)-(i, j + 1)
        const bool sleeveEnd = tshirt && (i == iMin || i == iMax);
        const bool armhole = !tshirt && j >= Hb;
        if (!sleeveEnd && !armhole) shared[id2(i, j)] = shared[id2(i, j + 1)] = 1;
      }
    }
  // lattice steps to the nearest seam: the cloth leaves the mid plane over two steps
  std::vector<int> steps(exists.size(), 1 << 20);
  std::deque<int> queue;
  for (size_t v = 0; v < exists.size(); ++v)
    if (exists[v] && shared[v]) steps[v] = 0, queue.push_back(static_cast<int>(v));
  while (!queue.empty()) {
    const int v = queue.front();
    queue.pop_front();
    const int i = v % nI + iMin, j = v / nI;
    const int ni[4] = {i + 1, i - 1, i, i}, nj[4] = {j, j, j + 1, j - 1};
    for (int k = 0; k < 4; ++k) {
      if (ni[k] < iMin || ni[k] > iMax || nj[k] < 0 || nj[k] >= nJ) continue;
      const int w = id2(ni[k], nj[k]);
      if (!exists[w] || steps[w] <= steps[v] + 1) continue;
      steps[w] = steps[v] + 1;
      queue.push_back(w);
    }
  }

  Garment g;
  g.panelNames = tshirt ? std::vector<std::string>{"front", "back", "left_sleeve", "right_sleeve"}
                        : std::vector<std::string>{"front", "back"};
  const Quat root(Eigen::AngleAxisf(bodyIn.yaw, Vec3::UnitY()));
  const Vec3 origin = bodyIn.position + pose.rootOffset;
  const float far = 0.6f * H;
  std::vector<int> frontIdx(exists.size(), -1), backIdx(exists.size(), -1);
  for (int j = 0; j < nJ; ++j)
    for (int i = iMin; i <= iMax; ++i) {
      const int v = id2(i, j);
      if (!exists[v]) continue;
      const Vec2 p = pos2(i, j);
      const bool sleeve = i < 0 || i > W;
      const int sleevePanel = i > W ? kPanelLeftSleeve : kPanelRightSleeve;
      auto add = [&](float z, int panel) {
        g.mesh.vertices.push_back(origin + root * Vec3(p.x(), p.y(), z));
        g.panelOfVertex.push_back(panel);
        return static_cast<int>(g.mesh.vertices.size()) - 1;
      };
      if (shared[v]) {
        frontIdx[v] = backIdx[v] = add(0.0f, sleeve ? sleevePanel : kPanelFront);
        continue;
      }
      const BodyQuery& b = sleeve ? whole : noLowerArms;
      const float bulge = gap * static_cast<float>(std::min(steps[v], 2)) / 2.0f;
      const float sf = march(b, Vec3(p.x(), p.y(), far), Vec3(0, 0, -1), 2.0f * far, gap);
      const float sb = march(b, Vec3(p.x(), p.y(), -far), Vec3(0, 0, 1), 2.0f * far, gap);
      const float zf = sf >= 0.0f ? std::max(far - sf, bulge) : bulge;
      const float zb = sb >= 0.0f ? std::min(-far + sb, -bulge) : -bulge;
      frontIdx[v] = add(zf, sleeve ? sleevePanel : kPanelFront);
      backIdx[v] = add(zb, sleeve ? sleevePanel : kPanelBack);
    }
  // two triangles per cell, on the diagonal that does not join two seam vertices (that edge would
  // be in four triangles); front wound towards +z, back towards -z
  for (int j = 0; j < Ht; ++j)
    for (int i = iMin; i < iMax; ++i) {
      if (!cell(i, j)) continue;
      const int c00 = id2(i, j), c10 = id2(i + 1, j), c11 = id2(i + 1, j + 1), c01 = id2(i, j + 1);
      const bool badMain = shared[c00] && shared[c11], badAnti = shared[c10] && shared[c01];
      if (badMain && badAnti)
        throw errorAt(source, "garment", "the panels are too narrow for the edge length; use a smaller edgeLength");
      const bool anti = badMain || (!badAnti && ((i + j) & 1));
      for (int side = 0; side < 2; ++side) {
        const std::vector<int>& idx = side == 0 ? frontIdx : backIdx;
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
