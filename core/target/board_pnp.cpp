// Planar PnP through the camera model: IPPE on undistorted bearings, Gauss-Newton on pixel
// residuals, covariances of the pose and of the board plane.
#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/geometry/geometry.h"
#include "core/target/board_camera.h"

namespace calibench {
namespace {

// Bearings closer than this to the image plane (z of the unit bearing) are left out of the IPPE
// initialisation, which works on their projection onto z = 1; Gauss-Newton still uses them.
constexpr double kMinBearingZ = 1e-3;
// Gauss-Newton stops when the step is this small (metres / radians).
constexpr double kStepTolerance = 1e-12;

struct Linearization {
  Eigen::VectorXd residuals;  // 2n, pixels: Project(T X) - u
  Eigen::MatrixXd jacobian;   // 2n x 6, d residual / d delta for T Exp(delta), [rho; phi]
  double ssr = 0.0;           // sum of squared residuals (px^2)
};

// nullopt when a corner does not project (behind the camera or outside the model's domain).
std::optional<Linearization> Linearize(const CameraModel& camera, const BoardDetection& detection,
                                       const Pose& cam_from_board, bool with_jacobian) {
  const int n = static_cast<int>(detection.pixels.size());
  Linearization lin;
  lin.residuals.resize(2 * n);
  if (with_jacobian) lin.jacobian.resize(2 * n, 6);
  const Mat3 r = cam_from_board.linear();
  for (int i = 0; i < n; ++i) {
    const Vec3& x = detection.board_points[i];
    Eigen::Matrix<double, 2, 3> d_pixel_d_point;
    const auto pixel =
        camera.Project(cam_from_board * x, with_jacobian ? &d_pixel_d_point : nullptr);
    if (!pixel) return std::nullopt;
    lin.residuals.segment<2>(2 * i) = *pixel - detection.pixels[i];
    if (with_jacobian) {
      // d(T Exp(delta) X)/d delta = R [I, -[X]x] at delta = 0.
      Eigen::Matrix<double, 3, 6> d_point_d_delta;
      d_point_d_delta << r, -r * Skew(x);
      lin.jacobian.block<2, 6>(2 * i, 0) = d_pixel_d_point * d_point_d_delta;
    }
  }
  lin.ssr = lin.residuals.squaredNorm();
  return lin;
}

// Gauss-Newton with step halving on pixel residuals; nullopt if the start does not project.
std::optional<Pose> Refine(const CameraModel& camera, const BoardDetection& detection, Pose pose,
                           int max_iterations) {
  auto lin = Linearize(camera, detection, pose, true);
  if (!lin) return std::nullopt;
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    const Mat6 h = lin->jacobian.transpose() * lin->jacobian;
    const Vec6 g = lin->jacobian.transpose() * lin->residuals;
    Vec6 step = -h.ldlt().solve(g);
    if (!step.allFinite()) break;
    // Step halving keeps the cost from rising when the linearization is poor (far start).
    bool improved = false;
    for (int halving = 0; halving < 10; ++halving) {
      const Pose candidate = pose * ExpSE3(step);
      auto next = Linearize(camera, detection, candidate, true);
      if (next && next->ssr <= lin->ssr) {
        pose = candidate;
        lin = std::move(next);
        improved = true;
        break;
      }
      step *= 0.5;
    }
    if (!improved || step.norm() < kStepTolerance) break;
  }
  return pose;
}

// IPPE on the normalized (z = 1) bearings, identity K; both of its solutions, best first.
std::vector<Pose> IppeCandidates(const CameraModel& camera, const BoardDetection& detection,
                                 std::string* why) {
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (size_t i = 0; i < detection.pixels.size(); ++i) {
    const auto bearing = camera.Unproject(detection.pixels[i]);
    if (!bearing) {
      *why = "corner " + std::to_string(i) + " cannot be unprojected";
      return {};
    }
    if (bearing->z() < kMinBearingZ) continue;
    const Vec3& x = detection.board_points[i];
    object.emplace_back(x.x(), x.y(), x.z());
    image.emplace_back(bearing->x() / bearing->z(), bearing->y() / bearing->z());
  }
  if (object.size() < 4) {
    *why = "fewer than 4 corners in front of the camera for the IPPE initialisation";
    return {};
  }
  std::vector<cv::Mat> rvecs, tvecs;
  const cv::Mat identity = cv::Mat::eye(3, 3, CV_64F);
  cv::solvePnPGeneric(object, image, identity, cv::noArray(), rvecs, tvecs, false,
                      cv::SOLVEPNP_IPPE);
  std::vector<Pose> poses;
  for (size_t k = 0; k < rvecs.size(); ++k) {
    cv::Mat rotation;
    cv::Rodrigues(rvecs[k], rotation);
    Pose pose = Pose::Identity();
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) pose.linear()(row, col) = rotation.at<double>(row, col);
      pose.translation()[row] = tvecs[k].at<double>(row);
    }
    if (pose.linear().allFinite() && pose.translation().allFinite()) poses.push_back(pose);
  }
  if (poses.empty()) *why = "IPPE found no pose for the corners";
  return poses;
}

// d(n, d)/d delta for the plane n = s R e_z, d = -n·t under T Exp(delta), [rho; phi] columns.
Eigen::Matrix<double, 4, 6> PlaneJacobian(const Pose& cam_from_board, double sign) {
  const Mat3 r = cam_from_board.linear();
  const Vec3 t = cam_from_board.translation();
  const Mat3 dn_dphi = -sign * r * Skew(Vec3::UnitZ());
  Eigen::Matrix<double, 4, 6> jacobian = Eigen::Matrix<double, 4, 6>::Zero();
  jacobian.block<3, 3>(0, 3) = dn_dphi;
  jacobian.block<1, 3>(3, 0) = -sign * Vec3::UnitZ().transpose();  // -n^T R = -s e_z^T
  jacobian.block<1, 3>(3, 3) = -t.transpose() * dn_dphi;
  return jacobian;
}

}  // namespace

bool PnpOptions::Check(std::string* why) const {
  if (!(min_corner_sigma_px > 0.0) || !std::isfinite(min_corner_sigma_px)) {
    *why = "min_corner_sigma_px must be a positive number of pixels";
    return false;
  }
  if (max_iterations < 1) {
    *why = "max_iterations must be >= 1";
    return false;
  }
  if (!(max_rms_px > 0.0)) {
    *why = "max_rms_px must be positive";
    return false;
  }
  return true;
}

std::optional<CameraBoardObservation> EstimateBoardPose(const CameraModel& camera,
                                                        const BoardDetection& detection,
                                                        const PnpOptions& options,
                                                        std::string* why) {
  std::string local_why;
  if (!why) why = &local_why;
  if (!options.Check(why) || !camera.Check(why)) return std::nullopt;
  CALIBENCH_CHECK(detection.pixels.size() == detection.board_points.size());
  const int n = static_cast<int>(detection.pixels.size());
  if (n < 4) {
    *why = "only " + std::to_string(n) + " corners (a planar pose needs 4)";
    return std::nullopt;
  }

  // Refine both IPPE solutions: the one IPPE ranks first in normalized coordinates is not
  // always the better one in pixels through a strong distortion.
  const std::vector<Pose> starts = IppeCandidates(camera, detection, why);
  if (starts.empty()) return std::nullopt;
  std::optional<Pose> best;
  double best_ssr = std::numeric_limits<double>::infinity();
  for (const Pose& start : starts) {
    const auto refined = Refine(camera, detection, start, options.max_iterations);
    if (!refined) continue;
    const auto lin = Linearize(camera, detection, *refined, false);
    if (lin && lin->ssr < best_ssr) {
      best = refined;
      best_ssr = lin->ssr;
    }
  }
  if (!best) {
    *why = "no board pose projects all corners into the camera";
    return std::nullopt;
  }
  const Pose& pose = *best;
  if (pose.translation().z() <= 0.0) {
    *why = "the board is behind the camera";
    return std::nullopt;
  }
  const auto lin = Linearize(camera, detection, pose, true);
  CALIBENCH_CHECK(lin.has_value());

  CameraBoardObservation obs;
  obs.cam_from_board = pose;
  obs.num_corners = n;
  obs.corners = detection;
  obs.reprojection_rms_px = std::sqrt(lin->ssr / n);
  if (obs.reprojection_rms_px > options.max_rms_px) {
    *why = "reprojection RMS " + std::to_string(obs.reprojection_rms_px) + " px exceeds " +
           std::to_string(options.max_rms_px) + " px";
    return std::nullopt;
  }
  // 2n residuals, 6 pose parameters; n >= 4 keeps the degrees of freedom positive.
  const double sigma2 = std::max(lin->ssr / (2.0 * n - 6.0),
                                 options.min_corner_sigma_px * options.min_corner_sigma_px);
  obs.corner_sigma_px = std::sqrt(sigma2);
  const Mat6 h = lin->jacobian.transpose() * lin->jacobian;
  const Eigen::FullPivLU<Mat6> lu(h);
  if (lu.rank() < 6) {
    *why = "degenerate corner configuration (pose not observable)";
    return std::nullopt;
  }
  obs.pose_covariance = sigma2 * lu.inverse();

  SetBoardPlaneFromPose(&obs);
  return obs;
}

void SetBoardPlaneFromPose(CameraBoardObservation* observation) {
  // Board plane z = 0 in the camera frame, oriented towards the camera (d > 0).
  const Pose& pose = observation->cam_from_board;
  const Plane in_cam = TransformPlane(pose, Plane{Vec3::UnitZ(), 0.0});
  observation->plane = OrientTowardsOrigin(in_cam);
  const double sign = observation->plane.normal.dot(in_cam.normal) > 0.0 ? 1.0 : -1.0;
  const Eigen::Matrix<double, 4, 6> jp = PlaneJacobian(pose, sign);
  observation->plane_covariance = jp * observation->pose_covariance * jp.transpose();
}

}  // namespace calibench
