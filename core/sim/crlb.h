// The Cramér–Rao bound of the extrinsic for board observations of known geometry.
//
// Each pair contributes its two plane features; their bound covariances follow from the noise
// models: LiDAR range noise along the rays of the noise-free board returns (the Fisher
// information of FitPlaneRangeMl), and corner noise in pixels through the camera model at the
// true board pose (the Fisher information of planar PnP, mapped to the board plane). The
// extrinsic's information is then Σ Jᵢᵀ Sᵢ⁻¹ Jᵢ of the weighted plane residual at the truth
// (WeightedPlaneInformation). It is the bound for estimators that use the board planes: board
// edges and corners seen by the LiDAR carry information this bound leaves out.
#pragma once

#include <vector>

#include "core/camera/camera.h"
#include "core/geometry/geometry.h"
#include "core/lidar_camera/solver.h"
#include "core/sim/sim.h"

namespace calibench {

// Inverse Fisher information of (n, d) (4x4, rank 3) for a plane measured by range noise
// `range_sigma_m` (1σ) along the rays from the origin to `points` (noise-free, on `plane`).
Mat4 LidarPlaneBoundCovariance(const std::vector<Vec3>& points, const Plane& plane,
                               double range_sigma_m);

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

// The bound for a simulated dataset's pairs (all, or the indices in `subset`), with the
// simulator's range noise and `corner_sigma_px`. Both noises must be > 0.
struct SimulationBoundInput {
  std::vector<SimPairTruth> pairs;
  CameraModel camera;
  BoardSpec board;
  Pose cam_from_lidar = Pose::Identity();
  double range_sigma_m = 0.0;
  double corner_sigma_px = 0.0;
};
SimulationBoundInput MakeSimulationBoundInput(const SimOptions& options, double corner_sigma_px);
// Per pair: the true planes with their bound covariances (the weighted solver's input at truth).
std::vector<PlanePair> BoundPlanePairs(const SimulationBoundInput& input);
CramerRaoBound SimulationBound(const SimulationBoundInput& input,
                               const std::vector<int>& subset = {});

}  // namespace calibench
