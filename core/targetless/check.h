// Is a calibration still right? A check without a target (docs/targetless.md): the scene's edges
// as the LiDAR and the camera see them are aligned around the calibration R, and the verdict says
// whether R is consistent with them, off (and by how much, with the estimate and its σ), or
// whether this scene cannot tell, naming the axes it cannot constrain.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "core/base/types.h"
#include "core/camera/camera.h"
#include "core/targetless/edge_alignment.h"

namespace calibench {

struct CheckOptions {
  LidarEdgeOptions lidar_edges;
  ImageEdgeOptions image_edges;
  EdgeAlignmentOptions alignment;  // search_deg / search_m: how far from R to look
  // The smallest change worth calling a miscalibration, per rotation and per translation (the
  // norm on camera axes). An axis the scene resolves to tolerance / 2 at 1σ is "constrained".
  double tolerance_deg = 0.5;
  double tolerance_m = 0.03;
  // A change is significant at this many σ (the χ² of the constrained axes, as a Gaussian's
  // two-sided level: 3 = 99.73 %).
  double significance_sigma = 3.0;
  // Evidence needed for any verdict but "cannot tell": matched LiDAR edges and image cells.
  int min_matched_edges = 150;
  int min_clusters = 20;
  // A frame counts as used when this many of its LiDAR edges matched an image edge.
  int min_frame_matches = 20;
  // The pose checked is a rough guess (a CAD mount, a pose typed in), not a calibration: a change
  // the scene supports refines it ("refined"), never judges it "miscalibrated".
  bool reference_is_guess = false;

  bool Check(std::string* why) const;
};

enum class CheckVerdict { kConsistent, kMiscalibrated, kCannotTell, kRefined };
// "consistent", "miscalibrated", "cannot tell", "refined"
std::string CheckVerdictName(CheckVerdict verdict);

// The six camera axes of a change, for words: "translation along camera x (right)", ...
std::string CameraAxisName(int axis);  // 0..5: tx ty tz rx ry rz

struct CheckReport {
  CheckVerdict verdict = CheckVerdict::kCannotTell;
  std::string why;                  // one paragraph, in words
  bool reference_is_guess = false;  // CheckOptions::reference_is_guess
  int frames_given = 0;
  int frames_used = 0;
  Pose reference = Pose::Identity();  // R, the calibration checked
  bool has_estimate = false;          // false: too little evidence to offer one
  Pose estimate = Pose::Identity();   // the targetless cam_from_lidar
  // Of the estimate, δ = [Δt (m); Δφ (rad)] on camera axes (edge_alignment.h): the sandwich
  // covariance scaled by the model's dispersion (>= 1: how much more independent parts of the
  // evidence disagree than their own σ say; check.cpp ModelDispersion).
  Mat6 covariance = Mat6::Zero();
  double model_dispersion = 1.0;
  Vec3 sigma_t_m = Vec3::Zero();
  Vec3 sigma_r_deg = Vec3::Zero();
  Vec3 change_t_m = Vec3::Zero();       // estimate minus R, camera axes
  Vec3 change_r_deg = Vec3::Zero();     // rotation from R to the estimate, camera axes
  double change_sigmas = 0.0;           // the change's significance over the constrained axes
  std::vector<int> unconstrained_axes;  // 0..5 as CameraAxisName
  // Other alignments the frames do not reject (check.cpp AddRivalMinima): each one's offset from
  // the estimate (δ), and in how many of the frames that tell them apart it fits better. Their
  // offsets are in the covariance.
  std::vector<Vec6> rival_offsets;
  std::vector<int> rival_frames_preferring, rival_frames_decided;
  // The cost along the estimate's least constrained direction (in units of tolerance), for the
  // plot of the workbench and the report: offsets in [-2, 2] tolerances and costs.
  Vec6 weakest_direction = Vec6::Zero();  // unit in tolerance units
  std::vector<double> weakest_offsets, weakest_costs;
  EdgeAlignment alignment;
  std::vector<int> lidar_edges_per_frame;
  std::vector<std::string> frame_ids;
};

// Reduces one scene to its edges.
EdgeFrame MakeEdgeFrame(const std::string& id, const LidarCloud& cloud, const ImageU8& image,
                        const CheckOptions& options);

// The check. `reference_covariance` is R's own (δ's units above; zero when unknown): a change
// within both uncertainties is consistent.
CheckReport CheckCalibration(const std::vector<EdgeFrame>& frames, const CameraModel& camera,
                             const Pose& reference, const Mat6& reference_covariance,
                             const CheckOptions& options);

// R's covariance from a result file's (right perturbation R·Exp([ρ; φ])) into δ's, and back.
Mat6 CameraAxesCovariance(const Mat6& right_covariance, const Pose& cam_from_lidar);
Mat6 RightPerturbationCovariance(const Mat6& camera_axes_covariance, const Pose& cam_from_lidar);

}  // namespace calibench
