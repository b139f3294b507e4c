// Camera models: pinhole + radial-tangential (OpenCV k1 k2 p1 p2 [k3 [k4 k5 k6]]) and
// Kannala-Brandt / equidistant fisheye (OpenCV cv::fisheye, k1..k4). Pixels have their origin at
// the centre of the top-left pixel, as in OpenCV.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/base/types.h"

namespace calibench {

enum class CameraModelType { kPinholeRadTan, kKannalaBrandt };

// "pinhole-radtan" / "kannala-brandt" (the manifest names).
std::string CameraModelName(CameraModelType type);
// Accepts the manifest names and nothing else; the model is never guessed from a count.
std::optional<CameraModelType> ParseCameraModelName(const std::string& name);

struct CameraModel {
  CameraModelType type = CameraModelType::kPinholeRadTan;
  int width = 0;                          // pixels
  int height = 0;                         // pixels
  double fx = 0, fy = 0, cx = 0, cy = 0;  // pixels
  // pinhole-radtan: 4, 5 or 8 values; kannala-brandt: exactly 4.
  std::vector<double> distortion;
  // Covariance of the intrinsic parameters [fx fy cx cy distortion...] (IntrinsicParameters'
  // order), row-major, as a calibration estimated it; empty = unknown. The extrinsic's σ carries
  // it when present (AddIntrinsicsUncertainty).
  std::vector<double> covariance;

  // False (with the reason) for a wrong coefficient count, non-positive focal length or size,
  // or non-finite values.
  bool Check(std::string* why) const;

  // Projects a point in the camera frame (metres) to pixels. nullopt for points with z <= 0
  // (pinhole) or that cannot be imaged. d_pixel_d_point, if given, receives the 2x3 Jacobian.
  std::optional<Vec2> Project(const Vec3& point_in_cam,
                              Eigen::Matrix<double, 2, 3>* d_pixel_d_point = nullptr) const;

  // Unit bearing vector in the camera frame for a pixel (inverse of Project up to scale), by
  // Newton iteration on the distortion. nullopt if the iteration does not converge.
  // d_bearing_d_pixel, if given, receives the 3x2 Jacobian of the unit bearing.
  std::optional<Vec3> Unproject(const Vec2& pixel,
                                Eigen::Matrix<double, 3, 2>* d_bearing_d_pixel = nullptr) const;

  bool InImage(const Vec2& pixel, double margin_px = 0.0) const {
    return pixel.x() >= -0.5 + margin_px && pixel.y() >= -0.5 + margin_px &&
           pixel.x() <= width - 0.5 - margin_px && pixel.y() <= height - 0.5 - margin_px;
  }
};

// The intrinsic parameters as one vector: fx fy cx cy, then the distortion coefficients.
std::vector<double> IntrinsicParameters(const CameraModel& camera);
// Names in that order ("fx" ... "k1" "k2" "p1" "p2" "k3" ..., or "k1".."k4" for a fisheye).
std::vector<std::string> IntrinsicParameterNames(const CameraModel& camera);
// Sets the parameters from such a vector (its size must be 4 + distortion.size()).
void SetIntrinsicParameters(const std::vector<double>& parameters, CameraModel* camera);

}  // namespace calibench
