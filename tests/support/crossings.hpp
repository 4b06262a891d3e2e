// counts water particles that pass through a cloth sheet, step by step: a vertical ray from a water
// particle meets the sheet an odd or even number of times, and that parity changes only when the
// particle crosses the sheet or its ray sweeps past the sheet's border. A parity change whose path
// (in the horizontal plane) stayed clear of the border is a crossing. For open sheets (a border), no
// self-intersection; particles are followed by their stable id.
#pragma once
#include <soak/model.hpp>
#include <soak/state.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <unordered_map>
#include <utility>
#include <vector>

namespace soak::testing {

class CrossingCounter {
 public:
  // margin: how close (m, horizontally) to the border a path may pass and not be judged
  explicit CrossingCounter(const Model& model, float margin = 0.03f) : margin_(margin) {
    std::map<std::pair<int, int>, int> uses;
    for (const auto& t : model.triangles)
      for (int e = 0; e < 3; ++e) {
        const int a = t[e], b = t[(e + 1) % 3];
        ++uses[{std::min(a, b), std::max(a, b)}];
      }
    for (const auto& [edge, n] : uses)
      if (n == 1) border_.push_back(edge);
  }

  // crossings since the last call (none on the first); call after every step
  size_t update(const Model& model, const Particles& p) {
    buildColumns(model, p);
    std::unordered_map<uint32_t, Entry> now;
    crossed_.clear();
    for (size_t i = static_cast<size_t>(model.numCloth); i < p.size(); ++i) {
      const Entry e{parityAt(model, p, p.x[i]), p.x[i].x(), p.x[i].z()};
      now[p.id[i]] = e;
      const auto before = last_.find(p.id[i]);
      if (before == last_.end() || before->second.parity == e.parity) continue;
      if (!pathNearBorder(p, before->second.x, before->second.z, e.x, e.z)) crossed_.push_back(p.id[i]);
    }
    last_ = std::move(now);
    return crossed_.size();
  }

  // the ids of the particles that crossed in the last update
  const std::vector<uint32_t>& crossedIds() const { return crossed_; }

 private:
  struct Entry {
    int parity;
    float x, z;
  };
  static constexpr float kCell = 0.05f;

  void buildColumns(const Model& model, const Particles& p) {
    columns_.clear();
    for (size_t t = 0; t < model.triangles.size(); ++t) {
      const auto& f = model.triangles[t];
      float x0 = p.x[f[0]].x(), x1 = x0, z0 = p.x[f[0]].z(), z1 = z0;
      for (int k = 1; k < 3; ++k) {
        x0 = std::min(x0, p.x[f[k]].x()), x1 = std::max(x1, p.x[f[k]].x());
        z0 = std::min(z0, p.x[f[k]].z()), z1 = std::max(z1, p.x[f[k]].z());
      }
      for (long cx = cellOf(x0); cx <= cellOf(x1); ++cx)
        for (long cz = cellOf(z0); cz <= cellOf(z1); ++cz) columns_[key(cx, cz)].push_back(static_cast<int>(t));
    }
  }

  // sheet layers above x (triangles whose vertical projection holds x and that lie above it), mod 2
  int parityAt(const Model& model, const Particles& p, const Vec3& x) const {
    const auto col = columns_.find(key(cellOf(x.x()), cellOf(x.z())));
    if (col == columns_.end()) return 0;
    int above = 0;
    for (int t : col->second) {
      const auto& f = model.triangles[static_cast<size_t>(t)];
      const Vec3 &a = p.x[f[0]], &b = p.x[f[1]], &c = p.x[f[2]];
      const float det = (b.z() - c.z()) * (a.x() - c.x()) + (c.x() - b.x()) * (a.z() - c.z());
      if (std::fabs(det) < 1e-12f) continue;
      const float l1 = ((b.z() - c.z()) * (x.x() - c.x()) + (c.x() - b.x()) * (x.z() - c.z())) / det;
      const float l2 = ((c.z() - a.z()) * (x.x() - c.x()) + (a.x() - c.x()) * (x.z() - c.z())) / det;
      const float l3 = 1.0f - l1 - l2;
      // half-open on one edge so a ray through a shared edge counts one of its two triangles
      if (l1 < 0 || l2 < 0 || l3 <= 0) continue;
      if (l1 * a.y() + l2 * b.y() + l3 * c.y() > x.y()) ++above;
    }
    return above & 1;
  }

  // does the horizontal segment (x0, z0) -> (x1, z1) pass within margin of the border's projection?
  bool pathNearBorder(const Particles& p, float x0, float z0, float x1, float z1) const {
    for (const auto& [a, b] : border_) {
      if (segmentDistance(x0, z0, x1, z1, p.x[a].x(), p.x[a].z(), p.x[b].x(), p.x[b].z()) < margin_) return true;
    }
    return false;
  }

  static float pointSegment(float px, float pz, float ax, float az, float bx, float bz) {
    const float dx = bx - ax, dz = bz - az, l2 = dx * dx + dz * dz;
    const float u = l2 > 0 ? std::clamp(((px - ax) * dx + (pz - az) * dz) / l2, 0.0f, 1.0f) : 0.0f;
    return std::hypot(px - ax - u * dx, pz - az - u * dz);
  }
  static float segmentDistance(float ax, float az, float bx, float bz, float cx, float cz, float dx, float dz) {
    const auto orient = [](float px, float pz, float qx, float qz, float rx, float rz) {
      return (qx - px) * (rz - pz) - (qz - pz) * (rx - px);
    };
    const float o1 = orient(ax, az, bx, bz, cx, cz), o2 = orient(ax, az, bx, bz, dx, dz);
    const float o3 = orient(cx, cz, dx, dz, ax, az), o4 = orient(cx, cz, dx, dz, bx, bz);
    if (((o1 > 0) != (o2 > 0)) && ((o3 > 0) != (o4 > 0))) return 0.0f;  // they intersect
    return std::min({pointSegment(ax, az, cx, cz, dx, dz), pointSegment(bx, bz, cx, cz, dx, dz),
                     pointSegment(cx, cz, ax, az, bx, bz), pointSegment(dx, dz, ax, az, bx, bz)});
  }

  static long cellOf(float v) { return static_cast<long>(std::floor(v / kCell)); }
  static long long key(long cx, long cz) { return (static_cast<long long>(cx) << 32) ^ (cz & 0xffffffffLL); }

  float margin_;
  std::vector<std::pair<int, int>> border_;
  std::unordered_map<long long, std::vector<int>> columns_;
  std::unordered_map<uint32_t, Entry> last_;
  std::vector<uint32_t> crossed_;
};

}  // namespace soak::testing
