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
  double cost = 0.0;      // robust cost at the solution (half the sum of squared whitened norms)
  int used_captures = 0;  // captures with at least one camera view
};

// Solves the rig from `initial` cam_from_lidar guesses (one per camera; single-camera solutions
// are good starts). Captures without a camera view are skipped; every camera needs at least three
// captures with a LiDAR plane (else its pose is not determined). nullopt with *why when the
// problem cannot be solved (a camera without enough captures, a covariance that is not positive,
// a singular system).
std::optional<RigSolution> SolveRig(const std::vector<RigCapture>& captures,
                                    const std::vector<Pose>& initial,
                                    const RigSolverOptions& options, std::string* why);

// cam_<to>_from_cam_<from> = cam_from_lidar[to] · cam_from_lidar[from]⁻¹ (x_in_to =
// to_from_from · x_in_from), with its covariance (right perturbation) from the joint covariance.
struct RelativePose {
  Pose to_from_from;
  Mat6 covariance = Mat6::Zero();
};
RelativePose CameraFromCamera(const RigSolution& solution, int to, int from);

}  // namespace calibench
