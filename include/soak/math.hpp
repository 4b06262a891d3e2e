// math aliases shared by every part of soak: float32 particle data, Eigen fixed-size types
#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>

namespace soak {

using Vec3 = Eigen::Vector3f;
using Vec3d = Eigen::Vector3d;
using Quat = Eigen::Quaternionf;
using Mat3 = Eigen::Matrix3f;

constexpr float kPi = 3.14159265358979323846f;

}  // namespace soak
