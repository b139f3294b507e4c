// The pipeline's intrinsics steps (joint_intrinsics.h): every pair posed again under another
// camera, the intrinsics' covariance carried into the extrinsic's by re-solving, and
// --refine-intrinsics around the joint problem.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/base/parallel.h"
#include "core/lidar_camera/joint_intrinsics.h"

namespace calibench {

std::string IntrinsicsToRefineName(IntrinsicsToRefine which) {
  switch (which) {
    case IntrinsicsToRefine::kFocal:
      return "focal";
    case IntrinsicsToRefine::kPinhole:
      return "pinhole";
    case IntrinsicsToRefine::kAll:
      return "all";
  }
  return "focal";
}

std::optional<IntrinsicsToRefine> ParseIntrinsicsToRefine(const std::string& name) {
  for (const auto which :
       {IntrinsicsToRefine::kFocal, IntrinsicsToRefine::kPinhole, IntrinsicsToRefine::kAll})
    if (IntrinsicsToRefineName(which) == name) return which;
  return std::nullopt;
}

bool JointIntrinsicsOptions::Check(std::string* why) const {
  if (!(huber_delta > 0)) {
    *why = "huber_delta must be positive";
    return false;
  }
  if (max_iterations < 1 || variance_rounds < 0) {
    *why = "max_iterations must be at least 1 and variance_rounds not negative";
    return false;
  }
  if (!(function_tolerance > 0)) {
    *why = "function_tolerance must be positive";
    return false;
  }
  return true;
}

void PoseCornersAgain(const CameraModel& camera, const PnpOptions& pnp,
                      std::vector<PairFeatures>* pairs) {
  for (PairFeatures& f : *pairs) {
    if (!f.camera || f.camera->corners.pixels.empty()) continue;
    std::string why;
    auto posed = EstimateBoardPose(camera, f.camera->corners, pnp, &why);
    if (!posed) {
      f.camera.reset();
      if (f.status == PairStatus::kAccepted) {
        f.status = PairStatus::kFailed;
        f.reason = "camera: " + why;
      }
      continue;
    }
    f.camera = std::move(posed);
  }
}

void AddIntrinsicsUncertainty(const std::vector<PairFeatures>& pairs, const CameraModel& camera,
                              const PipelineOptions& options, SolverResult* solution) {
  if (camera.covariance.empty()) return;
  const std::vector<double> k0 = IntrinsicParameters(camera);
  const size_t n = k0.size();
  std::vector<int> parameters;  // those with a variance
  for (size_t j = 0; j < n; ++j)
    if (camera.covariance[j * n + j] > 0) parameters.push_back(static_cast<int>(j));
  if (parameters.empty()) return;
  // The solve as the solution was made, started from it, without its reweighting rounds: only the
  // pose's response to the camera is wanted.
  SolverOptions solver = options.solver;
  solver.outlier_gate = 0.0;
  solver.sandwich_covariance = false;
  solver.jackknife_covariance = false;
  const double offset = solution->range_offset ? solution->range_offset->value_m : 0.0;
  std::vector<const PairFeatures*> used;  // accepted and not gated by the solve
  size_t solved = 0;
  for (const PairFeatures& f : pairs) {
    if (f.status != PairStatus::kAccepted || !f.lidar || !f.camera) continue;
    const size_t index = solved++;
    if (index < solution->robust_weights.size() && solution->robust_weights[index] == 0.0) continue;
    used.push_back(&f);
  }
  // Column j of G: (X(k + σ_j e_j) ⊖ X(k − σ_j e_j)) / 2σ_j, X ⊖ Y = Log(Y⁻¹ X) (right
  // perturbation).
  Eigen::MatrixXd response = Eigen::MatrixXd::Zero(6, static_cast<Eigen::Index>(parameters.size()));
  std::vector<char> failed(parameters.size(), 0);
  ParallelFor(parameters.size(), options.threads, [&](size_t c) {
    const int j = parameters[c];
    const double sigma = std::sqrt(camera.covariance[j * n + j]);
    Pose moved[2];
    for (int side = 0; side < 2; ++side) {
      std::vector<double> k = k0;
      k[j] += side == 0 ? sigma : -sigma;
      CameraModel shifted = camera;
      SetIntrinsicParameters(k, &shifted);
      std::vector<PlanePair> planes;
      for (const PairFeatures* f : used) {
        std::string why;
        const auto posed = EstimateBoardPose(shifted, f->camera->corners, options.pnp, &why);
        if (!posed) continue;
        planes.push_back(MakePlanePair(f->id, *f->lidar, *posed));
      }
      if (static_cast<int>(planes.size()) < options.min_pairs) {
        failed[c] = 1;
        return;
      }
      PlaneAlignmentSolver again(planes, solver, solution->cam_from_lidar, offset);
      again.SetVarianceFactors(solution->plane_variance_factor, solution->edge_variance_factor);
      moved[side] = again.Run().cam_from_lidar;
    }
    response.col(static_cast<Eigen::Index>(c)) =
        LogSE3(moved[1].inverse() * moved[0]) / (2.0 * sigma);
  });
  if (std::any_of(failed.begin(), failed.end(), [](char f) { return f != 0; })) return;
  Eigen::MatrixXd sub(parameters.size(), parameters.size());
  for (size_t a = 0; a < parameters.size(); ++a)
    for (size_t b = 0; b < parameters.size(); ++b)
      sub(a, b) = camera.covariance[parameters[a] * n + parameters[b]];
  // The response is about the pose at the solution: the right perturbation as the covariance.
  const Mat6 added = response * sub * response.transpose();
  solution->intrinsics_covariance = 0.5 * (added + added.transpose());
  solution->covariance += solution->intrinsics_covariance;
}

void RefineIntrinsics(const CameraModel& camera, const PipelineOptions& options,
                      CalibrationOutcome* outcome) {
  IntrinsicsRefinement refinement;
  refinement.before = camera;
  if (!outcome->solution) return;
  JointIntrinsicsOptions joint_options;
  joint_options.refine = options.intrinsics_to_refine;
  // A wrong camera bends the planes, so the first solve may have down-weighted pairs that agree
  // under the refined one: refine again while the pairs used change (at most three rounds).
  CalibrationOutcome current = *outcome;
  JointIntrinsicsResult joint;
  std::vector<std::string> used_before;
  for (int round = 0; round < 3; ++round) {
    try {
      // The solve's own pairs (its weights index them; a pair the last camera could not pose is
      // out), started from their poses; the camera file's values start the intrinsics and, with
      // its covariance, are the prior.
      joint = RefineIntrinsicsJointly(current.pairs, *current.solution, camera, options.solver,
                                      joint_options);
    } catch (const std::invalid_argument& e) {
      refinement.failure = e.what();
      outcome->intrinsics_refinement = refinement;
      return;
    }
    if (joint.pair_ids == used_before) break;
    used_before = joint.pair_ids;
    std::vector<PairFeatures> pairs = outcome->pairs;
    PoseCornersAgain(joint.camera, options.pnp, &pairs);
    PipelineOptions again = options;
    again.initial_cam_from_lidar = joint.cam_from_lidar;
    CalibrationOutcome refined = SolveFromFeatures(std::move(pairs), again);
    if (!refined.solution) {
      refinement.failure = "the extrinsic under the refined camera: " + refined.failure;
      outcome->intrinsics_refinement = refinement;
      return;
    }
    current = std::move(refined);
  }
  if (options.propagate_intrinsics)
    AddIntrinsicsUncertainty(current.pairs, joint.camera, options, &*current.solution);
  refinement.after = joint.camera;
  refinement.refined = joint.refined;
  refinement.joint_cam_from_lidar = joint.cam_from_lidar;
  refinement.corner_rms_px = joint.corner_rms_px;
  refinement.corner_sigma_px = joint.corner_sigma_px;
  refinement.plane_variance_factor = joint.plane_variance_factor;
  refinement.pairs = static_cast<int>(joint.pair_ids.size());
  refinement.corners = joint.corners;
  refinement.edge_points = joint.edge_points;
  refinement.iterations = joint.iterations;
  refinement.converged = joint.converged;
  current.background_note = outcome->background_note;
  current.initial_cam_from_lidar = outcome->initial_cam_from_lidar;
  *outcome = std::move(current);
  outcome->intrinsics_refinement = refinement;
}

}  // namespace calibench
