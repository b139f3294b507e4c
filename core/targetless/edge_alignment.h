// The extrinsic that lays the LiDAR's edges onto the image's (docs/targetless.md "Alignment"):
// iterated nearest-edge correspondences, each residual the distance from the projected LiDAR edge
// to the image edge's tangent line (pixels), weighted by what the two sensors can localise and
// robustified (Huber); coarse to fine in the radius an edge may be matched over, so that a start
// a few degrees off still finds its edges. The covariance is the cluster-robust sandwich
// H⁻¹ (Σ_c g_c g_cᵀ) H⁻¹ over image cells, because neighbouring returns along one edge are not
// independent measurements (and a still rig sees the same edge in every frame).
#pragma once

#include <string>
#include <vector>

#include "core/base/types.h"
#include "core/camera/camera.h"
#include "core/targetless/image_edges.h"
#include "core/targetless/lidar_edges.h"

namespace calibench {

// One scene as both sensors saw it, reduced to its edges.
struct EdgeFrame {
  std::string id;
  std::vector<SceneEdgePoint> lidar_edges;  // LiDAR frame
  ImageEdgeMap image_edges;
};

struct EdgeAlignmentOptions {
  // How far from the start the extrinsic may be: sets the first matching radius, and is a prior
  // of this σ about the start (what the scene cannot constrain keeps the start's value).
  double search_deg = 2.0;
  double search_m = 0.1;
  double typical_depth_m = 5.0;  // converts search_m into pixels for the first radius
  double final_radius_px = 4.0;  // the finest matching radius (pixels)
  double image_sigma_px = 0.5;   // an image edge's localisation, 1σ (pixels)
  double huber_k = 1.5;          // in units of a residual's σ
  int max_iterations_per_level = 60;
  double cluster_px = 48.0;  // the sandwich's clusters: image cells this size, over all frames
  int threads = 0;           // 0 = DefaultThreads()
  // Which LiDAR edges take part (the check aligns each kind alone to measure their agreement).
  bool use_depth_edges = true;
  bool use_intensity_edges = true;

  bool Check(std::string* why) const;
};

// Perturbations are on camera axes: t' = t + Δt, R' = Exp(Δφ) R, with δ = [Δt (m); Δφ (rad)].
struct EdgeAlignment {
  Pose cam_from_lidar = Pose::Identity();
  Mat6 information = Mat6::Zero();  // Σ w JᵀJ / σ² at the estimate, plus the prior (units of δ)
  Mat6 covariance = Mat6::Zero();  // sandwich, δ's units
  int points_matched = 0;          // LiDAR edges with an image edge within the final radius
  int points_projected = 0;        // LiDAR edges inside the image
  int clusters = 0;                // image cells holding matched edges
  double rms_sigma = 0.0;          // of the matched residuals, in units of their σ
  std::vector<int> matched_per_frame;
  bool converged = false;
};

// Aligns from `start`, the matching radius from `first_radius_px` (0: the search window's reach;
// the final radius or less: only the final level, for a start already near) down to the final
// one. The search window's prior is about `prior_centre` (nullptr: about the start).
EdgeAlignment AlignEdges(const std::vector<EdgeFrame>& frames, const CameraModel& camera,
                         const Pose& start, const EdgeAlignmentOptions& options,
                         double first_radius_px = 0.0, const Pose* prior_centre = nullptr);

// The robust cost (sum of Huber costs in σ units, unmatched edges at the cap) of an extrinsic at
// a fixed matching radius: what the check plots along its weakest direction.
// radius_px > 0: at that matching radius instead of the final one.
double AlignmentCost(const std::vector<EdgeFrame>& frames, const CameraModel& camera,
                     const Pose& cam_from_lidar, const EdgeAlignmentOptions& options,
                     double radius_px = 0.0);

// The same, frame by frame (in the frames' order): the check's test of rival alignments.
std::vector<double> AlignmentCostPerFrame(const std::vector<EdgeFrame>& frames,
                                          const CameraModel& camera, const Pose& cam_from_lidar,
                                          const EdgeAlignmentOptions& options);

// t' = t + δ.head(3), R' = Exp(δ.tail(3)) R.
Pose PerturbOnCameraAxes(const Pose& cam_from_lidar, const Vec6& delta);
// The δ that takes `from` to `to` (inverse of PerturbOnCameraAxes).
Vec6 DeltaOnCameraAxes(const Pose& from, const Pose& to);

}  // namespace calibench
