#include "core/camera/camera.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

namespace calibench {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
// Beyond these incidence angles a point is never imaged: a pinhole cannot see 90 degrees, and a
// fisheye ray at 180 degrees has no direction in the image plane.
constexpr double kPinholeMaxAngle = 89.9 * kDeg;
constexpr double kFisheyeMaxAngle = 179.0 * kDeg;
// Step of the search for the first fold of the distortion; small enough that the low-order
// polynomials of both models cannot dip between two samples.
constexpr double kFoldScanStep = 0.05 * kDeg;
constexpr int kMaxNewtonIterations = 100;

// OpenCV order k1 k2 p1 p2 [k3 [k4 k5 k6]]; missing trailing values are zero.
struct RadTan {
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0, k4 = 0, k5 = 0, k6 = 0;
};

RadTan RadTanOf(const std::vector<double>& d) {
  CALIBENCH_CHECK(d.size() <= 8);
  double v[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  for (size_t i = 0; i < d.size(); ++i) v[i] = d[i];
  return {v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]};
}

struct KannalaBrandt {
  double k[4] = {0, 0, 0, 0};
};

KannalaBrandt KannalaBrandtOf(const std::vector<double>& d) {
  CALIBENCH_CHECK(d.size() <= 4);
  KannalaBrandt kb;
  for (size_t i = 0; i < d.size(); ++i) kb.k[i] = d[i];
  return kb;
}

// Rational radial factor R(r2) = a/b and its derivative dR/dr2; false where the denominator of
// the rational model is not positive (a pole: the model is meaningless there).
bool RadialFactor(const RadTan& c, double r2, double* r, double* dr_dr2) {
  const double a = 1 + r2 * (c.k1 + r2 * (c.k2 + r2 * c.k3));
  const double b = 1 + r2 * (c.k4 + r2 * (c.k5 + r2 * c.k6));
  if (!(b > 0)) return false;
  const double da = c.k1 + r2 * (2 * c.k2 + 3 * c.k3 * r2);
  const double db = c.k4 + r2 * (2 * c.k5 + 3 * c.k6 * r2);
  *r = a / b;
  *dr_dr2 = (da * b - a * db) / (b * b);
  return true;
}

// Distorts normalised coordinates exactly as cv::projectPoints; jacobian = d(xd)/d(x).
Vec2 DistortRadTan(const RadTan& c, const Vec2& p, Eigen::Matrix2d* jacobian) {
  const double x = p.x(), y = p.y();
  const double r2 = x * x + y * y;
  double radial = 0, d_radial = 0;
  RadialFactor(c, r2, &radial, &d_radial);
  const Vec2 d(x * radial + 2 * c.p1 * x * y + c.p2 * (r2 + 2 * x * x),
               y * radial + c.p1 * (r2 + 2 * y * y) + 2 * c.p2 * x * y);
  if (jacobian) {
    const double cross = 2 * x * y * d_radial + 2 * c.p1 * x + 2 * c.p2 * y;
    *jacobian << radial + 2 * x * x * d_radial + 2 * c.p1 * y + 6 * c.p2 * x, cross, cross,
        radial + 2 * y * y * d_radial + 6 * c.p1 * y + 2 * c.p2 * x;
  }
  return d;
}

// r_d(r) = r R(r^2) must increase for the radial mapping to be one-to-one (tangential terms are
// small and ignored here).
bool RadTanIncreasing(const RadTan& c, double r) {
  double radial = 0, d_radial = 0;
  if (!RadialFactor(c, r * r, &radial, &d_radial)) return false;
  return radial + 2 * r * r * d_radial > 0;
}

// theta_d(theta) = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8).
double ThetaD(const KannalaBrandt& kb, double theta) {
  const double t2 = theta * theta;
  return theta * (1 + t2 * (kb.k[0] + t2 * (kb.k[1] + t2 * (kb.k[2] + t2 * kb.k[3]))));
}

double ThetaDDerivative(const KannalaBrandt& kb, double theta) {
  const double t2 = theta * theta;
  return 1 + t2 * (3 * kb.k[0] + t2 * (5 * kb.k[1] + t2 * (7 * kb.k[2] + t2 * 9 * kb.k[3])));
}

// Largest angle in [0, max_angle] up to which `increasing` holds everywhere (sampled, then
// refined by bisection at the first failure).
template <typename Increasing>
double FirstFold(Increasing increasing, double max_angle) {
  double good = 0.0;
  for (double angle = kFoldScanStep; good < max_angle; angle += kFoldScanStep) {
    angle = std::min(angle, max_angle);
    if (!increasing(angle)) {
      double bad = angle;
      for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (good + bad);
        (increasing(mid) ? good : bad) = mid;
      }
      return good;
    }
    good = angle;
  }
  return max_angle;
}

// Validity limit of the model: pinhole -> largest normalised radius r = |(x, y)/z|, fisheye ->
// largest theta. Computed from the coefficients only; memoised per thread because CameraModel is
// a plain struct that callers may change between calls.
double ValidityLimit(const CameraModel& camera) {
  struct Memo {
    bool valid = false;
    CameraModelType type = CameraModelType::kPinholeRadTan;
    std::vector<double> coefficients;
    double limit = 0;
  };
  thread_local Memo memo;
  if (memo.valid && memo.type == camera.type && memo.coefficients == camera.distortion) {
    return memo.limit;
  }
  double limit = 0;
  if (camera.type == CameraModelType::kPinholeRadTan) {
    const RadTan c = RadTanOf(camera.distortion);
    const auto increasing = [&c](double angle) { return RadTanIncreasing(c, std::tan(angle)); };
    limit = std::tan(FirstFold(increasing, kPinholeMaxAngle));
  } else {
    const KannalaBrandt kb = KannalaBrandtOf(camera.distortion);
    const auto increasing = [&kb](double theta) { return ThetaDDerivative(kb, theta) > 0; };
    limit = FirstFold(increasing, kFisheyeMaxAngle);
  }
  memo = {true, camera.type, camera.distortion, limit};
  return limit;
}

std::optional<Vec2> ProjectPinhole(const CameraModel& cam, const Vec3& p,
                                   Eigen::Matrix<double, 2, 3>* jacobian) {
  if (!(p.z() > 0)) return std::nullopt;
  const Vec2 normalised(p.x() / p.z(), p.y() / p.z());
  const double r_max = ValidityLimit(cam);
  if (!(normalised.squaredNorm() < r_max * r_max)) return std::nullopt;
  Eigen::Matrix2d d_distorted;
  const Vec2 d = DistortRadTan(RadTanOf(cam.distortion), normalised, &d_distorted);
  if (jacobian) {
    Eigen::Matrix<double, 2, 3> d_normalised;
    d_normalised << 1 / p.z(), 0, -normalised.x() / p.z(), 0, 1 / p.z(), -normalised.y() / p.z();
    *jacobian = Eigen::Vector2d(cam.fx, cam.fy).asDiagonal() * d_distorted * d_normalised;
  }
  return Vec2(cam.fx * d.x() + cam.cx, cam.fy * d.y() + cam.cy);
}

// w = (rho dtheta/drho - theta) / rho^3 for theta = atan2(rho, z). Near the axis the two terms
// cancel, so there we use the series of (t/(1+t^2) - atan t) / t^3, t = rho/z.
double FisheyeW(double rho, double z, double n2, double theta) {
  const double t = rho / z;
  if (z > 0 && t < 1e-2) {
    const double t2 = t * t;
    const double series =
        -2.0 / 3 + t2 * (4.0 / 5 + t2 * (-6.0 / 7 + t2 * (8.0 / 9 - t2 * 10.0 / 11)));
    return series / (z * z * z);
  }
  return (rho * z / n2 - theta) / (rho * rho * rho);
}

// As cv::fisheye::projectPoints for z > 0, with theta = atan2(rho, z) so that rays beyond 90
// degrees keep their direction.
std::optional<Vec2> ProjectFisheye(const CameraModel& cam, const Vec3& p,
                                   Eigen::Matrix<double, 2, 3>* jacobian) {
  const double rho = std::hypot(p.x(), p.y());
  const double n2 = p.squaredNorm();
  const double theta = std::atan2(rho, p.z());
  if (!(n2 > 0) || !(theta < ValidityLimit(cam))) return std::nullopt;
  if (rho == 0 || theta == 0) {  // On the optical axis (z > 0): the general formula's limit.
    if (jacobian) *jacobian << cam.fx / p.z(), 0, 0, 0, cam.fy / p.z(), 0;
    return Vec2(cam.cx, cam.cy);
  }
  const KannalaBrandt kb = KannalaBrandtOf(cam.distortion);
  const double t2 = theta * theta;
  const double h = ThetaD(kb, theta) / theta;  // theta_d / theta, even in theta
  const double q = theta / rho;
  const double s = h * q;  // pixel offset = f * s * (x, y)
  if (jacobian) {
    // s = h(theta) q(theta, rho): ds/dx = x c, ds/dy = y c, ds/dz below.
    const double h1 = 2 * kb.k[0] + t2 * (4 * kb.k[1] + t2 * (6 * kb.k[2] + t2 * 8 * kb.k[3]));
    const double c = h1 * q * q * p.z() / n2 + h * FisheyeW(rho, p.z(), n2, theta);
    const double ds_dz = -(h1 * t2 + h) / n2;
    Eigen::Matrix<double, 2, 3> d;
    d << s + p.x() * p.x() * c, p.x() * p.y() * c, p.x() * ds_dz,  //
        p.x() * p.y() * c, s + p.y() * p.y() * c, p.y() * ds_dz;
    *jacobian = Eigen::Vector2d(cam.fx, cam.fy).asDiagonal() * d;
  }
  return Vec2(cam.fx * s * p.x() + cam.cx, cam.fy * s * p.y() + cam.cy);
}

// Damped Newton on the rad-tan distortion, from the distorted point (as cv::undistortPoints
// starts), to 1e-12 in normalised coordinates.
std::optional<Vec2> UndistortRadTan(const CameraModel& cam, const Vec2& distorted) {
  const RadTan c = RadTanOf(cam.distortion);
  const double r_max = ValidityLimit(cam);
  Vec2 p = distorted;
  Eigen::Matrix2d jacobian;
  Vec2 residual = DistortRadTan(c, p, &jacobian) - distorted;
  for (int i = 0; i < kMaxNewtonIterations; ++i) {
    const Vec2 step = jacobian.partialPivLu().solve(residual);
    if (!step.allFinite()) return std::nullopt;
    // Halve the step while it leaves the one-to-one region or does not reduce the residual.
    double scale = 1.0;
    bool inside = false;
    Vec2 next, next_residual;
    Eigen::Matrix2d next_jacobian;
    for (int k = 0; k < 40; ++k, scale *= 0.5) {
      next = p - scale * step;
      if (!(next.norm() < r_max)) continue;
      inside = true;
      next_residual = DistortRadTan(c, next, &next_jacobian) - distorted;
      if (next_residual.norm() <= residual.norm()) break;
    }
    if (!inside) return std::nullopt;
    p = next;
    residual = next_residual;
    jacobian = next_jacobian;
    if (scale * step.norm() < 1e-12) {
      if (residual.norm() > 1e-10 || !(p.norm() < r_max)) return std::nullopt;
      return p;
    }
  }
  return std::nullopt;
}

// Solves theta_d(theta) = |x_d| by Newton, kept inside a bisection bracket of the monotonic range.
std::optional<double> UndistortTheta(const CameraModel& cam, double theta_d) {
  const KannalaBrandt kb = KannalaBrandtOf(cam.distortion);
  double lo = 0, hi = ValidityLimit(cam);
  if (!(theta_d < ThetaD(kb, hi))) return std::nullopt;
  double theta = std::min(theta_d, 0.5 * (lo + hi));
  for (int i = 0; i < kMaxNewtonIterations; ++i) {
    const double f = ThetaD(kb, theta) - theta_d;
    if (f == 0) return theta;
    (f > 0 ? hi : lo) = theta;
    const double newton = theta - f / ThetaDDerivative(kb, theta);
    const bool inside = newton > lo && newton < hi;
    if (inside && std::abs(newton - theta) < 1e-12 * std::max(1.0, theta)) return newton;
    theta = inside ? newton : 0.5 * (lo + hi);
    if (hi - lo < 1e-15) return theta;
  }
  return std::nullopt;
}

bool AllFinite(const CameraModel& c) {
  for (double v : c.distortion) {
    if (!std::isfinite(v)) return false;
  }
  return std::isfinite(c.fx) && std::isfinite(c.fy) && std::isfinite(c.cx) && std::isfinite(c.cy);
}

// An n x n row-major covariance that is finite, symmetric and has a non-negative diagonal (empty
// is valid: unknown).
bool CovarianceValid(const std::vector<double>& c, size_t n) {
  if (c.empty()) return true;
  for (size_t i = 0; i < n; ++i) {
    if (!(c[i * n + i] >= 0)) return false;
    for (size_t j = 0; j < n; ++j) {
      // Symmetric to the precision a file's 17 digits and an inversion keep.
      const double a = c[i * n + j], b = c[j * n + i];
      const double scale = std::sqrt(std::abs(c[i * n + i] * c[j * n + j]));
      if (!std::isfinite(a) || std::abs(a - b) > 1e-6 * scale) return false;
    }
  }
  return true;
}

// The unit bearing of a pixel (CameraModel::Unproject without its Jacobian).
std::optional<Vec3> UnprojectBearing(const CameraModel& camera, const Vec2& pixel) {
  const Vec2 distorted((pixel.x() - camera.cx) / camera.fx, (pixel.y() - camera.cy) / camera.fy);
  if (!distorted.allFinite()) return std::nullopt;
  if (camera.type == CameraModelType::kPinholeRadTan) {
    const std::optional<Vec2> p = UndistortRadTan(camera, distorted);
    if (!p) return std::nullopt;
    return Vec3(p->x(), p->y(), 1.0).normalized();
  }
  const double theta_d = distorted.norm();
  if (theta_d == 0) return Vec3(0, 0, 1);
  const std::optional<double> theta = UndistortTheta(camera, theta_d);
  if (!theta) return std::nullopt;
  const Vec2 direction = distorted / theta_d;
  return Vec3(std::sin(*theta) * direction.x(), std::sin(*theta) * direction.y(), std::cos(*theta));
}

}  // namespace

std::string CameraModelName(CameraModelType type) {
  return type == CameraModelType::kKannalaBrandt ? "kannala-brandt" : "pinhole-radtan";
}

std::optional<CameraModelType> ParseCameraModelName(const std::string& name) {
  if (name == "pinhole-radtan") return CameraModelType::kPinholeRadTan;
  if (name == "kannala-brandt") return CameraModelType::kKannalaBrandt;
  return std::nullopt;
}

bool CameraModel::Check(std::string* why) const {
  std::ostringstream problem;
  const size_t n = distortion.size();
  if (type == CameraModelType::kPinholeRadTan && n != 4 && n != 5 && n != 8) {
    problem << "pinhole-radtan needs 4, 5 or 8 distortion coefficients "
               "(k1 k2 p1 p2 [k3 [k4 k5 k6]]), got "
            << n;
  } else if (type == CameraModelType::kKannalaBrandt && n != 4) {
    problem << "kannala-brandt needs exactly 4 distortion coefficients (k1 k2 k3 k4), got " << n;
  } else if (!AllFinite(*this)) {
    problem << "camera parameters must be finite (fx, fy, cx, cy and distortion)";
  } else if (!(fx > 0 && fy > 0)) {
    problem << "focal lengths must be positive, got fx=" << fx << " fy=" << fy;
  } else if (width <= 0 || height <= 0) {
    problem << "image size must be positive, got " << width << "x" << height;
  } else if (!covariance.empty() && covariance.size() != (4 + n) * (4 + n)) {
    problem << "the intrinsics' covariance needs " << (4 + n) << "x" << (4 + n)
            << " values (fx fy cx cy and the distortion), got " << covariance.size();
  } else if (!CovarianceValid(covariance, 4 + n)) {
    problem << "the intrinsics' covariance must be finite and symmetric with a non-negative "
               "diagonal";
  } else {
    return true;
  }
  if (why) *why = problem.str();
  return false;
}

std::vector<double> IntrinsicParameters(const CameraModel& camera) {
  std::vector<double> parameters = {camera.fx, camera.fy, camera.cx, camera.cy};
  parameters.insert(parameters.end(), camera.distortion.begin(), camera.distortion.end());
  return parameters;
}

std::vector<std::string> IntrinsicParameterNames(const CameraModel& camera) {
  std::vector<std::string> names = {"fx", "fy", "cx", "cy"};
  static const char* const kRadTan[] = {"k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6"};
  for (size_t i = 0; i < camera.distortion.size(); ++i)
    names.push_back(camera.type == CameraModelType::kKannalaBrandt ? "k" + std::to_string(i + 1)
                                                                   : kRadTan[i % 8]);
  return names;
}

void SetIntrinsicParameters(const std::vector<double>& parameters, CameraModel* camera) {
  CALIBENCH_CHECK(parameters.size() == 4 + camera->distortion.size());
  camera->fx = parameters[0];
  camera->fy = parameters[1];
  camera->cx = parameters[2];
  camera->cy = parameters[3];
  std::copy(parameters.begin() + 4, parameters.end(), camera->distortion.begin());
}

std::optional<Vec2> CameraModel::Project(const Vec3& point_in_cam,
                                         Eigen::Matrix<double, 2, 3>* d_pixel_d_point) const {
  return type == CameraModelType::kPinholeRadTan
             ? ProjectPinhole(*this, point_in_cam, d_pixel_d_point)
             : ProjectFisheye(*this, point_in_cam, d_pixel_d_point);
}

std::optional<Vec3> CameraModel::Unproject(const Vec2& pixel,
                                           Eigen::Matrix<double, 3, 2>* d_bearing_d_pixel) const {
  const std::optional<Vec3> bearing = UnprojectBearing(*this, pixel);
  if (!bearing || !d_bearing_d_pixel) return bearing;
  // The bearing b moves so that Project(b) follows the pixel and b stays unit: J db = dp with
  // J = dProject/dpoint at b, and bᵀ db = 0. The 3x3 system [J; bᵀ] is regular wherever Project
  // is (its Jacobian's null space is b itself: moving along the ray does not move the pixel).
  Eigen::Matrix<double, 2, 3> project_jacobian;
  if (!Project(*bearing, &project_jacobian)) return std::nullopt;
  Mat3 system;
  system.topRows<2>() = project_jacobian;
  system.row(2) = bearing->transpose();
  Eigen::Matrix<double, 3, 2> right = Eigen::Matrix<double, 3, 2>::Zero();
  right.topRows<2>().setIdentity();
  *d_bearing_d_pixel = system.partialPivLu().solve(right);
  return bearing;
}

}  // namespace calibench
