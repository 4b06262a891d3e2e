// the passes and the fail-safe of the self-collision (self_collision_resolve.hpp)
#include "garment/self_collision_resolve.hpp"

#include <algorithm>
#include <tuple>
#include <utility>

namespace soak {

namespace {

// the four particles of one test (ids local to the piece), gathered and written back
struct Four {
  std::array<int, 4> id;
  std::array<Vec3, 4> x0, x1, v;
  std::array<float, 4> w;
  Four(const std::array<int, 4>& ids, const Vec3* x0s, const Vec3* x1s, const Vec3* vs, const std::vector<float>& inv)
      : id(ids) {
    for (int k = 0; k < 4; ++k) {
      x0[k] = x0s[id[k]];
      x1[k] = x1s[id[k]];
      v[k] = vs[id[k]];
      w[k] = inv[id[k]];
    }
  }
  void store(Vec3* x1s, Vec3* vs, std::vector<uint8_t>& moved) const {
    for (int k = 0; k < 4; ++k) {
      x1s[id[k]] = x1[k];
      vs[id[k]] = v[k];
      moved[id[k]] = 1;
    }
  }
};

// whether none of a test's four points moved since the push counter stood at `tested`
bool unmovedSince(const std::array<int, 4>& id, const std::vector<uint32_t>& lastMove, uint32_t tested) {
  return lastMove[id[0]] <= tested && lastMove[id[1]] <= tested && lastMove[id[2]] <= tested && lastMove[id[3]] <= tested;
}

constexpr int kZoneRounds = 8;  // at most; a round joins every pair still through into the zones

}  // namespace

// kSelfCollisionPasses Gauss-Seidel passes over the step's pairs, vertex-triangle then edge-edge. A test reads only
// its four points' end positions (their start positions and masses are constant), so a pair found
// clear is skipped until one of its points moves: the same pushes as testing every pair every pass
SelfCollisionPushes pushPairs(const SelfCollisionMesh& mesh, const std::vector<float>& invMass, float thickness,
                              const Vec3* x0, Vec3* x1, Vec3* vel, SelfCollisionScratch& s) {
  const auto& tris = mesh.triangles;
  const auto& edges = mesh.edges;
  uint32_t pushed = 0;  // pushes so far; lastMove[v] = the count after v's last push
  s.lastMove.assign(s.moved.size(), 0);
  s.testedAt.assign(s.pairs.size() + s.edgePairs.size(), 0);
  const auto test = [&](size_t k, const std::array<int, 4>& id, bool pass0, auto&& push) {
    if (!pass0 && unmovedSince(id, s.lastMove, s.testedAt[k])) return false;
    s.testedAt[k] = pushed;
    Four f(id, x0, x1, vel, invMass);
    if (!push(f)) return false;
    f.store(x1, vel, s.moved);
    ++pushed;
    for (int v : id) s.lastMove[v] = pushed;
    return true;
  };
  SelfCollisionPushes pushes;
  for (int pass = 0; pass < kSelfCollisionPasses; ++pass) {
    for (size_t k = 0; k < s.pairs.size(); ++k) {
      const auto& [i, t] = s.pairs[k];
      const auto& tri = tris[t];
      pushes.vertexTriangle += test(k, {i, tri[0], tri[1], tri[2]}, pass == 0, [&](Four& f) {
        return pushVertexOffTriangle(f.x0, f.x1, f.v, f.w, thickness);
      });
    }
    for (size_t k = 0; k < s.edgePairs.size(); ++k) {
      const auto& [a, b] = s.edgePairs[k];
      pushes.edgeEdge += test(s.pairs.size() + k, {edges[a][0], edges[a][1], edges[b][0], edges[b][1]}, pass == 0,
                              [&](Four& f) { return pushEdgeOffEdge(f.x0, f.x1, f.v, f.w, thickness); });
    }
  }
  return pushes;
}

// the fail-safe, rigid impact zones in translation (after Bridson, Fedkiw and Anderson 2002): the
// free points of a pair still through each other after the passes (a push closes at most a thickness,
// and a vertex that went far through ends far) join one zone, and every zone's free points take its
// mass-weighted mean displacement over the step and mean velocity, so the pair keeps the shape it
// started the step with (and its side) while the zone keeps its momentum; zones sharing a point merge,
// and the pairs are tested again until none is through. The pairs are those found for the step's
// motion, whose sweeps a zone's common motion keeps within the boxes for the most part. Returns the
// points moved into zones
int impactZones(const SelfCollisionMesh& mesh, const std::vector<float>& invMass, const Vec3* x0, Vec3* x1,
                Vec3* vel, SelfCollisionScratch& s) {
  const auto through = [&](const std::array<int, 4>& id, bool vertexTriangle) {
    std::array<Vec3, 4> a0, a1;
    for (int k = 0; k < 4; ++k) std::tie(a0[k], a1[k]) = std::pair(x0[id[k]], x1[id[k]]);
    return vertexTriangle ? passedThrough(a0, a1) : edgesPassedThrough(a0, a1);
  };
  const auto pairIds = [&](size_t k) -> std::array<int, 4> {
    if (k < s.pairs.size()) {
      const auto& tri = mesh.triangles[s.pairs[k][1]];
      return {s.pairs[k][0], tri[0], tri[1], tri[2]};
    }
    const auto& [a, b] = s.edgePairs[k - s.pairs.size()];
    return {mesh.edges[a][0], mesh.edges[a][1], mesh.edges[b][0], mesh.edges[b][1]};
  };
  const size_t pairs = s.pairs.size() + s.edgePairs.size();
  std::vector<int>& zone = s.zone;  // union-find over the points; -1: in no zone
  zone.assign(s.moved.size(), -1);
  std::vector<int> members;  // the points in zones, with their motion before the zones
  std::vector<std::pair<Vec3, Vec3>>& before = s.zoneMotion;
  before.resize(s.moved.size());
  const auto root = [&](int v) {
    while (zone[v] != v) v = zone[v] = zone[zone[v]];
    return v;
  };
  for (int round = 0; round < kZoneRounds; ++round) {
    bool joined = false;  // a point joined a zone, or two zones merged
    for (size_t k = 0; k < pairs; ++k) {
      const std::array<int, 4> id = pairIds(k);
      if (!through(id, k < s.pairs.size())) continue;
      int r = -1;
      for (int v : id) {
        if (invMass[v] == 0.0f) continue;  // pinned or disturbed: keeps its own motion
        if (zone[v] < 0) {
          zone[v] = v;
          members.push_back(v);
          before[v] = {x1[v] - x0[v], vel[v]};
          joined = true;
        }
        const int rv = root(v);
        if (r >= 0 && rv != r) {
          zone[std::max(rv, r)] = std::min(rv, r);
          joined = true;
        }
        r = r < 0 ? rv : std::min(rv, r);
      }
    }
    if (!joined) break;  // every pair still through is within one zone already (a held point in it)
    // each zone's mean displacement and velocity, weighted by mass, from its points' own motion
    std::vector<Vec3>& sum = s.zoneSum;
    std::vector<Vec3>& sumV = s.zoneSumV;
    std::vector<float>& mass = s.zoneMass;
    sum.assign(s.moved.size(), Vec3::Zero());
    sumV.assign(s.moved.size(), Vec3::Zero());
    mass.assign(s.moved.size(), 0.0f);
    for (int v : members) {
      const int r = root(v);
      const float m = 1.0f / invMass[v];
      sum[r] += m * before[v].first;
      sumV[r] += m * before[v].second;
      mass[r] += m;
    }
    for (int v : members) {
      const int r = root(v);
      x1[v] = x0[v] + sum[r] / mass[r];
      vel[v] = sumV[r] / mass[r];
      s.moved[v] = 1;
    }
  }
  return static_cast<int>(members.size());
}

}  // namespace soak
