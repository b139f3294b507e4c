// A rig of one LiDAR (the reference) and N cameras calibrated in one problem. Where two cameras
// see the same board at the same time, the board ties them to each other: a constraint on their
// relative pose that the LiDAR's plane alone cannot give (it fixes the board's plane, not where
// the board lies within it, nor its turn about its normal). Composing two single-camera results
// leaves those directions to each camera's plane fits; the joint solve takes them from the board.
//
// The model (a small bundle adjustment, after COLMAP's rig: one reference sensor and
// sensor_from_rig poses): unknowns are each camera's cam_from_lidar and, per synchronised
// capture k, the board's pose lidar_from_board_k. Measurements, each whitened by its own
// covariance:
//   - per camera c that saw board k: its PnP pose cam_c_from_board_k (6-dof, the corners'
//     information summarised by PnP's covariance), residual Log(measured⁻¹ · cam_c_from_lidar ·
//     lidar_from_board_k);
//   - per capture with a LiDAR board plane: that plane against the board's z = 0 plane under
//     lidar_from_board_k (3-dof, in the plane's tangent coordinates).
// With one camera this is the plane alignment of Ca²Lib with the camera plane taken from the
// full PnP pose: the board's in-plane pose is free and absorbs the camera's in-plane error.
//   - per camera with a prior (its single-camera calibration, which has the LiDAR's planes, the
//     board's edges and the range offset in it): Log(prior⁻¹ · cam_from_lidar) (6-dof). With
//     priors the captures' LiDAR planes are left out (they are in the priors already) and only
//     the boards two cameras saw at once add to it: the cameras' relative pose.
// With priors, the board views' covariances are scaled by their own variance factor (the median
// of their squared whitened norms over χ²₆'s), and the covariance by the whole problem's when
// that exceeds 1: measurements that disagree more than their covariances allow widen σ instead
// of being believed. Medians, so that the few boards the Huber kernel down-weights do not set
// them.
// Gauss-Newton on SE(3) (right perturbations, [rho; phi]) with a Huber kernel on each whitened
// measurement's norm.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/base/types.h"
#include "core/geometry/geometry.h"

namespace calibench {

// One camera's view of a capture's board.
struct RigBoardView {
  int camera = 0;                       // index into the rig's cameras
  Pose cam_from_board;                  // PnP
  Mat6 pose_covariance = Mat6::Zero();  // of cam_from_board, right perturbation; must be > 0
};

// One synchronised capture: the LiDAR's board plane (if found) and every camera's view of it.
struct RigCapture {
  std::string id;
  std::optional<Plane> lidar_plane;      // LiDAR frame, normal towards the LiDAR
  Mat4 lidar_covariance = Mat4::Zero();  // of (n, d), rank 3; must be > 0 on the tangent space
  std::vector<RigBoardView> views;
};

// A camera's pose known from elsewhere (its single-camera calibration), with its covariance
// (right perturbation [rho; phi]).
struct RigCameraPrior {
  Pose cam_from_lidar = Pose::Identity();
  Mat6 covariance = Mat6::Zero();  // must be > 0
};

struct RigSolverOptions {
  double huber_delta = 3.0;  // on each measurement's whitened norm, in standard deviations
  int max_iterations = 50;
  double min_step = 1e-10;  // stop when the step's norm (m, rad) falls below this
  bool Check(std::string* why) const;
};

struct RigSolution {
  std::vector<Pose> cam_from_lidar;  // per camera: x_in_cam = cam_from_lidar * x_in_lidar
  // Joint covariance of the cameras' right perturbations, 6N x 6N in camera order (the board
  // poses marginalised out): what the relative poses' σ come from.
  Eigen::MatrixXd covariance;
  int iterations = 0;
  bool converged = false;
  double cost = 0.0;  // robust cost at the solution (half the sum of squared whitened norms)
  // The median over the terms of the squared whitened norm over its χ² median; the covariance
  // is scaled by it when it exceeds 1. 1 when the problem has no redundancy.
  double variance_factor = 1.0;
  // With priors: the factor the cameras' board-pose covariances were scaled by, estimated from
  // their residuals (PnP's covariance leaves out the lens model's and the print's errors).
  double view_variance_factor = 1.0;
  int used_captures = 0;  // captures with at least one camera view
};

// Solves the rig from `initial` cam_from_lidar guesses (one per camera; single-camera solutions
// are good starts). Captures without a camera view are skipped; every camera without a prior needs
// at least three captures with a LiDAR plane (else its pose is not determined). `priors`: empty,
// or one per camera (nullopt: none for that camera). nullopt with *why when the
// problem cannot be solved (a camera without enough captures, a covariance that is not positive,
// a singular system).
std::optional<RigSolution> SolveRig(const std::vector<RigCapture>& captures,
                                    const std::vector<Pose>& initial,
                                    const RigSolverOptions& options, std::string* why,
                                    const std::vector<std::optional<RigCameraPrior>>& priors = {});

// The rig solve over the cameras' own calibrations (what CalibrateRig runs): each camera's
// solution as its prior, widened by the share of its captures that other cameras saw too (their
// LiDAR planes are in both priors: from independence when nothing is shared to covariance
// intersection's halves when everything is), and the boards two cameras saw at once (their views;
// the LiDAR planes are in the priors) tying the cameras to each other. `captures` holds every
// camera's views of every capture; *shared_captures gets how many two or more cameras saw.
std::optional<RigSolution> SolveRigFromCameras(const std::vector<RigCapture>& captures,
                                               const std::vector<RigCameraPrior>& cameras,
                                               const RigSolverOptions& options, std::string* why,
                                               int* shared_captures = nullptr);

// cam_<to>_from_cam_<from> = cam_from_lidar[to] · cam_from_lidar[from]⁻¹ (x_in_to =
// to_from_from · x_in_from), with its covariance (right perturbation) from the joint covariance.
struct RelativePose {
  Pose to_from_from;
  Mat6 covariance = Mat6::Zero();
};
RelativePose CameraFromCamera(const RigSolution& solution, int to, int from);

}  // namespace calibench
