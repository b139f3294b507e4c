// The camera's intrinsics with the extrinsic (`calibrate --refine-intrinsics`), and the
// intrinsics' uncertainty carried into the extrinsic's (the camera file's covariance).
//
// One joint problem: the intrinsics, every board pose and the extrinsic, from the board's corners
// in the images, the LiDAR's board planes and the rings' crossings of the sheet's edges. The
// corners alone cannot tell a longer focal length from a farther board when the boards face the
// camera; the LiDAR measures that distance, so the joint problem fixes the focal length the
// corners leave loose, and corners and LiDAR agree on one camera.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/camera/camera.h"
#include "core/lidar_camera/pipeline.h"

namespace calibench {

// IntrinsicsToRefine (core/lidar_camera/pipeline.h): the LiDAR measures the boards' distances,
// which is what the focal length sets; the principal point and the distortion only the corners
// tell, and an error there turns the extrinsic (a principal point 1 px off turns it by 1/f rad):
// freeing them pays only where the camera file's are wrong and the corners cover the image.
std::string IntrinsicsToRefineName(IntrinsicsToRefine which);  // "focal", "pinhole", "all"
std::optional<IntrinsicsToRefine> ParseIntrinsicsToRefine(const std::string& name);

struct JointIntrinsicsOptions {
  IntrinsicsToRefine refine = IntrinsicsToRefine::kFocal;
  // Huber threshold on every whitened residual (corners, planes, edges), in standard deviations.
  double huber_delta = 3.0;
  // Levenberg–Marquardt: at most this many iterations per round; a round ends when a step
  // changes the cost by at most function_tolerance of itself.
  int max_iterations = 100;
  double function_tolerance = 1e-10;
  // Rounds of variance component estimation: the corners', the planes' and the edges' noise
  // scaled to what their residuals show, so that each group weighs what it is worth.
  int variance_rounds = 4;
  bool Check(std::string* why) const;
};

// What the joint problem found.
struct JointIntrinsicsResult {
  CameraModel camera;         // refined, its covariance the joint problem's marginal
  std::vector<bool> refined;  // per IntrinsicParameters entry: estimated (false: held fixed)
  Pose cam_from_lidar = Pose::Identity();
  Mat6 cam_from_lidar_covariance = Mat6::Zero();  // marginal, intrinsics included
  std::vector<std::string> pair_ids;              // the pairs it used
  int corners = 0, planes = 0, edge_points = 0;
  double corner_rms_px = 0.0;  // at the solution, over the used pairs' corners
  // A-posteriori standard deviation of a corner (px) and variance factors of the planes and edges
  // relative to their own noise models.
  double corner_sigma_px = 0.0;
  double plane_variance_factor = 1.0;
  double edge_variance_factor = 1.0;
  int iterations = 0;
  bool converged = false;
};

// Solves the joint problem from a finished solve: its accepted pairs that kept a weight (their
// corners, LiDAR planes with covariances, edge crossings), starting from `camera`, the pairs'
// board poses and the solution's extrinsic. Estimates options.refine's parameters (the
// distortion's k3 is held where the camera has it at 0, a lens calibrated without it, as are the
// rational model's k4..k6); the camera's own covariance, when it has one, is a prior on them.
// Throws std::invalid_argument when fewer than 3 pairs have corners and planes.
JointIntrinsicsResult RefineIntrinsicsJointly(const std::vector<PairFeatures>& pairs,
                                              const SolverResult& solution,
                                              const CameraModel& camera,
                                              const SolverOptions& solver,
                                              const JointIntrinsicsOptions& options = {});

// Poses every pair's corners again under `camera` (the camera side of the features); a pair whose
// pose cannot be solved fails with the reason.
void PoseCornersAgain(const CameraModel& camera, const PnpOptions& pnp,
                      std::vector<PairFeatures>* pairs);

// The extrinsic's covariance gains what the camera's intrinsics covariance (camera.covariance)
// does to it: G Σ_K Gᵀ, G the solution's response to each parameter (each pair posed again under
// the camera moved by one σ either way and the extrinsic re-solved from the solution). Sets
// solution->intrinsics_covariance to that part. Nothing happens without a covariance.
void AddIntrinsicsUncertainty(const std::vector<PairFeatures>& pairs, const CameraModel& camera,
                              const PipelineOptions& options, SolverResult* solution);

// `calibrate --refine-intrinsics` on a finished outcome: the joint problem, then every pair posed
// under the refined camera and the extrinsic solved again (as without refinement: edges, gating,
// the honest σ), with the refined intrinsics' covariance propagated. Fills
// outcome->intrinsics_refinement; on failure leaves the outcome as it was and says why there.
void RefineIntrinsics(const CameraModel& camera, const PipelineOptions& options,
                      CalibrationOutcome* outcome);

}  // namespace calibench
