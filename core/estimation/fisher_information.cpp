#include "core/estimation/fisher_information.h"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace calibench {

Mat4 LidarPlaneBoundCovariance(const std::vector<Vec3>& points, const Plane& plane,
                               double range_sigma_m, double angular_sigma_rad) {
  CALIBENCH_CHECK(range_sigma_m > 0 && angular_sigma_rad >= 0);
  // The Jacobian of FitPlaneRangeMl's range residual, at the true plane.
  const Eigen::Matrix<double, 3, 2> basis = PlaneTangentBasis(plane.normal);
  Mat3 information = Mat3::Zero();
  for (const Vec3& x : points) {
    const Vec3 ray = x.normalized();
    const double cos_incidence = plane.normal.dot(ray);
    if (std::abs(cos_incidence) < 0.02) continue;
    Eigen::RowVector3d j;
    j.head<2>() = -plane.distance * ray.transpose() * basis / (cos_incidence * cos_incidence);
    j(2) = 1.0 / cos_incidence;
    const double r = x.norm();
    const double tan2 = (1.0 - cos_incidence * cos_incidence) / (cos_incidence * cos_incidence);
    const double variance =
        range_sigma_m * range_sigma_m + angular_sigma_rad * angular_sigma_rad * r * r * tan2;
    information += j.transpose() * j / variance;
  }
  return TangentToPlaneCovariance(information.inverse(), plane.normal);
}

Mat6 CameraPoseBoundCovariance(const CameraModel& camera, const std::vector<Vec3>& board_corners,
                               const Pose& cam_from_board, double corner_sigma_px) {
  CALIBENCH_CHECK(corner_sigma_px > 0);
  // Fisher information of the board pose (right perturbation) from the corner pixels.
  Mat6 pose_information = Mat6::Zero();
  Eigen::Matrix<double, 2, 3> d_pixel_d_point;
  for (const Vec3& corner : board_corners) {
    const Vec3 in_cam = cam_from_board * corner;
    if (!camera.Project(in_cam, &d_pixel_d_point)) continue;
    // d(R (X + δρ + δφ × X) + t) = R δρ − R [X]× δφ.
    Eigen::Matrix<double, 3, 6> d_point;
    d_point.leftCols<3>() = cam_from_board.linear();
    d_point.rightCols<3>() = -cam_from_board.linear() * Skew(corner);
    const Eigen::Matrix<double, 2, 6> j = d_pixel_d_point * d_point;
    pose_information += j.transpose() * j / (corner_sigma_px * corner_sigma_px);
  }
  return pose_information.inverse();
}

Mat4 CameraPlaneBoundCovariance(const CameraModel& camera, const std::vector<Vec3>& board_corners,
                                const Pose& cam_from_board, double corner_sigma_px) {
  const Mat6 pose_covariance =
      CameraPoseBoundCovariance(camera, board_corners, cam_from_board, corner_sigma_px);
  // The board plane in the camera frame: n = R e_z (sign fixed by OrientTowardsOrigin),
  // d = −n·t. dn = −R [e_z]× δφ, dt = R δρ.
  const Mat3& r = cam_from_board.linear();
  const Vec3 n = r.col(2);
  const Vec3& t = cam_from_board.translation();
  Eigen::Matrix<double, 4, 6> d_plane = Eigen::Matrix<double, 4, 6>::Zero();
  d_plane.block<3, 3>(0, 3) = -r * Skew(Vec3::UnitZ());
  d_plane.block<1, 3>(3, 0) = -n.transpose() * r;
  d_plane.block<1, 3>(3, 3) = t.transpose() * r * Skew(Vec3::UnitZ());
  const Mat4 covariance = d_plane * pose_covariance * d_plane.transpose();
  return covariance;  // a sign flip of (n, d) leaves the covariance unchanged
}

CramerRaoBound BoundFromInformation(const Mat6& information) {
  CramerRaoBound bound;
  Eigen::SelfAdjointEigenSolver<Mat6> eigen(information);
  Vec6 inverse = Vec6::Zero();
  for (int i = 0; i < 6; ++i)
    inverse[i] = eigen.eigenvalues()[i] > 1e-12 * eigen.eigenvalues()[5]
                     ? 1.0 / eigen.eigenvalues()[i]
                     : 1e12;
  bound.covariance = eigen.eigenvectors() * inverse.asDiagonal() * eigen.eigenvectors().transpose();
  bound.translation_rms_m = std::sqrt(bound.covariance.topLeftCorner<3, 3>().trace());
  bound.rotation_rms_deg =
      std::sqrt(bound.covariance.bottomRightCorner<3, 3>().trace()) * kRadToDeg;
  return bound;
}

}  // namespace calibench
