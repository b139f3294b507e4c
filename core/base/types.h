// Basic Eigen aliases and the error type used at I/O boundaries.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <stdexcept>
#include <string>

namespace calibench {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Vector4d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat3 = Eigen::Matrix3d;
using Mat4 = Eigen::Matrix4d;
using Mat6 = Eigen::Matrix<double, 6, 6>;
constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

// A rigid transform named b_from_a maps points: x_in_b = b_from_a * x_in_a.
using Pose = Eigen::Isometry3d;

// Thrown only at I/O boundaries (files, manifests); the message names the file and the problem.
class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Programmer errors: a broken invariant, never bad user input.
#define CALIBENCH_CHECK(cond)                                                              \
  do {                                                                                     \
    if (!(cond))                                                                           \
      throw std::logic_error(std::string("check failed: " #cond " at ") + __FILE__ + ":" + \
                             std::to_string(__LINE__));                                    \
  } while (0)

}  // namespace calibench
