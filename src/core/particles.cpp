#include <soak/state.hpp>

namespace soak {

void Particles::resize(size_t n) {
  phase.resize(n);
  id.resize(n);
  mass.resize(n);
  invMass.resize(n);
  radius.resize(n);
  x.resize(n);
  xPred.resize(n);
  v.resize(n);
}

size_t Particles::add(int32_t ph, uint32_t pid, float m, float h, const Vec3& pos, const Vec3& vel) {
  phase.push_back(ph);
  id.push_back(pid);
  mass.push_back(m);
  invMass.push_back(m > 0.0f ? 1.0f / m : 0.0f);
  radius.push_back(h);
  x.push_back(pos);
  xPred.push_back(pos);
  v.push_back(vel);
  return x.size() - 1;
}

template <class T>
static void compactArray(std::vector<T>& a, const std::vector<uint8_t>& keep) {
  size_t w = 0;
  for (size_t i = 0; i < a.size(); ++i)
    if (keep[i]) a[w++] = a[i];
  a.resize(w);
}

void Particles::compact(const std::vector<uint8_t>& keep) {
  compactArray(phase, keep);
  compactArray(id, keep);
  compactArray(mass, keep);
  compactArray(invMass, keep);
  compactArray(radius, keep);
  compactArray(x, keep);
  compactArray(xPred, keep);
  compactArray(v, keep);
}

}  // namespace soak
