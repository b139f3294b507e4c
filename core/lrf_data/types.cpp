#include "core/lrf_data/types.h"

#include <algorithm>
#include <cstdio>

namespace calibench {
namespace {

// Unit normal of triangle (p, q, r), turned towards +z of the target frame (the sensors' side).
Plane TrianglePlane(const Vec3& p, const Vec3& q, const Vec3& r) {
  Vec3 normal = (q - p).cross(r - p).normalized();
  if (normal.z() < 0) normal = -normal;
  return Plane{normal, -normal.dot(p)};
}

// A tent flatter than this makes the three planes (paper Eq. (6)) nearly dependent: the lines of
// Eq. (7) and the scan corners F, G, H are then ill-defined.
constexpr double kMinFaceAngleDeg = 5.0;

}  // namespace

bool FailCheck(std::string* why, const std::string& message) {
  if (why) *why = message;
  return false;
}

bool DepthIntrinsics::Check(std::string* why) const {
  if (width <= 0 || height <= 0) return FailCheck(why, "depth camera width and height must be > 0");
  if (!(std::isfinite(fx) && std::isfinite(fy) && fx > 0 && fy > 0))
    return FailCheck(why, "depth camera fx and fy must be finite and > 0 (pixels)");
  if (!(std::isfinite(cx) && std::isfinite(cy)))
    return FailCheck(why, "depth camera cx and cy must be finite (pixels)");
  if (!(std::isfinite(depth_scale) && depth_scale > 0))
    return FailCheck(why, "depth_scale must be finite and > 0 (metres per PNG unit)");
  return true;
}

std::optional<Vec2> DepthIntrinsics::Project(const Vec3& point,
                                             Eigen::Matrix<double, 2, 3>* d_pixel_d_point) const {
  if (!(point.z() > 0)) return std::nullopt;
  const double inverse_z = 1.0 / point.z();
  const Vec2 pixel(fx * point.x() * inverse_z + cx, fy * point.y() * inverse_z + cy);
  if (d_pixel_d_point)
    *d_pixel_d_point << fx * inverse_z, 0, -fx * point.x() * inverse_z * inverse_z,  //
        0, fy * inverse_z, -fy * point.y() * inverse_z * inverse_z;
  return pixel;
}

Vec3 DepthIntrinsics::Unproject(const Vec2& pixel, double z,
                                Eigen::Matrix<double, 3, 2>* d_point_d_pixel) const {
  if (d_point_d_pixel) *d_point_d_pixel << z / fx, 0, 0, z / fy, 0, 0;
  return Vec3((pixel.x() - cx) / fx * z, (pixel.y() - cy) / fy * z, z);
}

bool ThreeFaceTarget::Check(std::string* why) const {
  const double values[] = {base_width, base_height, tent_half_width, apex_y, foot_y, ridge_height};
  if (!std::all_of(std::begin(values), std::end(values), [](double v) { return std::isfinite(v); }))
    return FailCheck(why, "three-face target sizes must be finite");
  if (!(base_width > 0 && base_height > 0))
    return FailCheck(why, "three-face target base_width and base_height must be > 0 (metres)");
  if (!(tent_half_width > 0))
    return FailCheck(why, "three-face target tent_half_width must be > 0");
  if (!(ridge_height > 0)) return FailCheck(why, "three-face target ridge_height must be > 0");
  if (!(apex_y > foot_y)) return FailCheck(why, "three-face target apex_y must be above foot_y");
  // The scan must cross the base on both sides of the tent (segments E…F and H…I).
  if (!(tent_half_width < 0.5 * base_width))
    return FailCheck(why,
                     "three-face target tent_half_width must be < base_width / 2 (tent on base)");
  if (apex_y > 0.5 * base_height || foot_y < -0.5 * base_height)
    return FailCheck(why, "three-face target apex_y and foot_y must lie within ±base_height / 2");
  const auto planes = FacePlanes();
  for (int i = 0; i < 3; ++i) {
    for (int j = i + 1; j < 3; ++j) {
      const double cosine = std::clamp(planes[i].normal.dot(planes[j].normal), -1.0, 1.0);
      if (std::acos(cosine) * kRadToDeg < kMinFaceAngleDeg)
        return FailCheck(why, "three-face target faces " + std::to_string(i) + " and " +
                                  std::to_string(j) + " are nearly parallel (< 5 degrees)");
    }
  }
  return true;
}

std::array<Plane, 3> ThreeFaceTarget::FacePlanes() const {
  return {Plane{Vec3::UnitZ(), 0.0}, TrianglePlane(A(), B(), C()), TrianglePlane(A(), C(), D())};
}

const char* FaceName(int face) {
  static const char* const kNames[3] = {"base PBDQ", "face ABC", "face ACD"};
  CALIBENCH_CHECK(face >= 0 && face < 3);
  return kNames[face];
}

double UnsignedAngleDeg(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return std::acos(std::clamp(std::abs(a.dot(b)), 0.0, 1.0)) * kRadToDeg;
}

std::string NearParallelReason(const std::string& a, const std::string& b, double limit_deg,
                               double angle_deg) {
  char limit[32], angle[32];
  std::snprintf(limit, sizeof(limit), "%.1f", limit_deg);
  std::snprintf(angle, sizeof(angle), "%.1f", angle_deg);
  return a + " and " + b + " are within " + limit + "° of parallel (" + angle + "°)";
}

}  // namespace calibench
