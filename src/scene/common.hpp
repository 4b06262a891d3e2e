// helpers shared by the scene readers (scene.cpp, cloth_keys.cpp and chen_keys.cpp)
#pragma once
#include <soak/model.hpp>

#include "scene/reader.hpp"

#include <fmt/format.h>

#include <string>
#include <vector>

namespace soak {

std::string fmtVec(const Vec3& v);
// a's keys then b's: the keys of the other types, which ObjectReader::finish names as misplaced
std::vector<std::string> concat(std::vector<std::string> a, const std::vector<std::string>& b);
Quat axisAngle(const Vec3& unitAxis, float degrees);
// max > min in every component, else an error at maxPath
bool checkOrdered(ErrorLog& log, const std::string& maxPath, const std::string& minName, const Vec3& lo,
                  const Vec3& hi);
// {"axis": unit vec3, "degrees": number}
Quat readRotation(ObjectReader r);
// a collider's pose: position + rotation, or keyframes; a plane may give its normal instead of a rotation
std::vector<Keyframe> readPose(ObjectReader& r, bool isPlane);
// the "keyframes" array of r: each an object with a required "time" (s, >= 0, strictly increasing)
// whose other keys readBody(ObjectReader&, Key&) reads. Errors are logged; bad entries are skipped.
template <class Key, class ReadBody>
std::vector<Key> readKeyframes(ObjectReader& r, const std::string& what, ReadBody readBody) {
  ErrorLog& log = r.log();
  std::vector<Key> out;
  const Json* keys = r.array("keyframes");
  if (!keys) return out;
  if (keys->empty()) log.expected(r.pathOf("keyframes"), "an array of at least one keyframe", *keys);
  for (size_t i = 0; i < keys->size(); ++i) {
    const std::string kp = indexPath(r.pathOf("keyframes"), i);
    if (!(*keys)[i].is_object()) {
      log.expected(kp, "an object (" + what + ")", (*keys)[i]);
      continue;
    }
    ObjectReader k(log, &(*keys)[i], kp);
    Key key;
    key.time = k.number("time", std::nullopt, Range::nonNegative());
    readBody(k, key);
    k.finish();
    if (!out.empty() && !(key.time > out.back().time))
      log.error(k.pathOf("time"), fmt::format("expected a time > the previous keyframe's ({} s), got {}",
                                              out.back().time, key.time));
    out.push_back(key);
  }
  return out;
}

// "friction" (kinetic Coulomb coefficient, >= 0) and "staticFriction" (>= friction, default: friction)
void readFriction(ObjectReader& r, float defaultKinetic, float& kinetic, float& staticCoef);

// a path relative to the scene file's folder
std::string resolvePath(const std::string& file, const std::string& baseDir);

}  // namespace soak
