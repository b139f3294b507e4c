// Fisher information of board observations and the Cramér–Rao bound it gives: the LiDAR's board
// plane under range noise along its rays, the camera's board pose and plane under corner noise.
// Guidance scores a candidate board pose with it (core/guidance/next_pose.h); the simulator bounds
// a dataset with it (core/evaluation/crlb.h). The extrinsic's information is Σ Jᵢᵀ Sᵢ⁻¹ Jᵢ of the
// weighted plane residual at the truth (WeightedPlaneInformation, core/lidar_camera/solver.h):
// the bound for estimators that use the board planes; board edges and corners seen by the LiDAR
// carry information it leaves out.
#pragma once

#include <vector>

#include "core/base/types.h"
#include "core/camera/camera.h"
#include "core/geometry/geometry.h"

namespace calibench {

// Inverse Fisher information of (n, d) (4x4, rank 3) for a plane measured by range noise
// `range_sigma_m` (1σ) along the rays from the origin to `points` (noise-free, on `plane`), and
// a beam jitter of `angular_sigma_rad` per axis across the rays, which adds (r σ_θ tan α)² to a
// return's range variance at range r and incidence α (core/target/lidar_noise.h).
Mat4 LidarPlaneBoundCovariance(const std::vector<Vec3>& points, const Plane& plane,
                               double range_sigma_m, double angular_sigma_rad = 0.0);

// Inverse Fisher information of the board pose (right perturbation, [rho; phi]) for corners
// `board_corners` (board frame) seen at `cam_from_board` with pixel noise `corner_sigma_px`.
Mat6 CameraPoseBoundCovariance(const CameraModel& camera, const std::vector<Vec3>& board_corners,
                               const Pose& cam_from_board, double corner_sigma_px);

// Inverse Fisher information of the board plane (n, d) in the camera frame (4x4, rank 3) for
// corners `board_corners` (board frame) seen at `cam_from_board` with pixel noise
// `corner_sigma_px` (1σ per coordinate).
Mat4 CameraPlaneBoundCovariance(const CameraModel& camera, const std::vector<Vec3>& board_corners,
                                const Pose& cam_from_board, double corner_sigma_px);

struct CramerRaoBound {
  Mat6 covariance = Mat6::Zero();  // right perturbation of cam_from_lidar, [rho; phi]
  // Expected RMS of |t_est − t_true| (metres) and of the rotation angle (degrees) of an
  // efficient unbiased estimator: sqrt of the traces of the two blocks.
  double translation_rms_m = 0.0;
  double rotation_rms_deg = 0.0;
};

CramerRaoBound BoundFromInformation(const Mat6& information);

}  // namespace calibench
