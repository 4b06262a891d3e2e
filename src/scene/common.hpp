// helpers shared by the scene readers (scene.cpp and chen_keys.cpp)
#pragma once
#include <soak/model.hpp>

#include "scene/reader.hpp"

#include <string>
#include <vector>

namespace soak {

std::string fmtVec(const Vec3& v);
Quat axisAngle(const Vec3& unitAxis, float degrees);
// max > min in every component, else an error at maxPath
bool checkOrdered(ErrorLog& log, const std::string& maxPath, const std::string& minName, const Vec3& lo,
                  const Vec3& hi);
// {"axis": unit vec3, "degrees": number}
Quat readRotation(ObjectReader r);
// a collider's pose: position + rotation, or keyframes; a plane may give its normal instead of a rotation
std::vector<Keyframe> readPose(ObjectReader& r, bool isPlane);
// a path relative to the scene file's folder
std::string resolvePath(const std::string& file, const std::string& baseDir);

}  // namespace soak
