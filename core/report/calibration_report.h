// What a calibration report says about a LiDAR-camera solve (`calibench report`, `calibrate
// --report`, the workbench's File → Report…): per pair its residuals, its weight and how far the
// result moves without it; held-out cross-validation (leave one pair out, predict it); σ as pairs
// accumulate; where the boards were. Computed from the pipeline's own outcome by re-solving with
// the pipeline's own solver, never by a copy of it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/lidar_camera/pipeline.h"
#include "core/results/pair_status.h"

namespace calibench {

struct ReportOptions {
  bool cross_validate = true;  // leave-one-pair-out re-solves (influence and held-out error)
  bool sigma_history = true;   // re-solves on the first k pairs, k = min_pairs..all
  // A pair disagrees when its held-out plane error, in units of its own σ (both planes'
  // covariances, the LiDAR's ring biases and the pipeline's floors for what neither model holds,
  // PipelineOptions::guided_floor_sigma_*), stands out of the other pairs' by this many robust
  // standard deviations (1.4826 MAD) and exceeds min_sigmas: a board that moved a little between
  // the two captures passes the camera-guided gate but not this comparison with its peers.
  double disagree_sigmas = 3.5;
  double min_sigmas = 2.0;

  bool Check(std::string* why) const;
};

// One row per pair of the dataset, in the dataset's order.
struct PairReportRow : PairStanding {
  BoardOrigin origin;   // where its LiDAR board came from
  bool solved = false;  // it took part in the solve
  double weight = 0.0;  // its planes' robust weight (0 = gated)
  bool down_weighted = false;
  // Training residuals at the solution: the angle between the LiDAR plane carried into the
  // camera and the camera's plane (degrees), and their offset (mm, signed along the camera's
  // normal); the LiDAR's board-edge crossings (ring ends on the sheet's edge) and their RMS
  // distance to the edges the camera's board pose puts there (mm; beam footprint included).
  std::optional<double> plane_angle_deg, plane_distance_mm;
  int edge_points = 0;
  std::optional<double> edge_rms_mm;
  // Leave-one-out: how far the result moves without this pair (translation mm, rotation deg) and
  // its plane error predicted by the solve of the other pairs (held out).
  std::optional<double> influence_mm, influence_deg;
  std::optional<double> heldout_angle_deg, heldout_distance_mm;
  std::optional<double> heldout_sigmas;  // the held-out error in units of its σ (Mahalanobis)
  bool disagrees = false;                // held-out error beyond ReportOptions' gate
  std::string remark;                    // the worst rows, in words ("" for the unremarkable)
  // Coverage: the board's centre in the image (pixels) and its direction from the LiDAR
  // (azimuth, elevation in degrees; x forward, z up), where each side saw it.
  std::optional<Vec2> image_centre_px;
  std::optional<Vec2> lidar_azimuth_elevation_deg;
};

struct CrossValidation {
  int folds = 0;  // pairs held out, one at a time
  // RMS over the solved pairs of their plane errors: at the full solution (training) and
  // predicted by the solve without them (held out).
  double train_rms_angle_deg = 0.0, train_rms_distance_mm = 0.0;
  double heldout_rms_angle_deg = 0.0, heldout_rms_distance_mm = 0.0;
  std::vector<std::string> disagreeing;  // pair ids
  std::string verdict;                   // "consistent: ..." or "pair X disagrees: ..."
};

// σ per camera axis after the first `pairs` usable pairs (capture order).
struct SigmaStep {
  int pairs = 0;
  Vec3 sigma_t_mm = Vec3::Zero();
  Vec3 sigma_r_deg = Vec3::Zero();
};

struct CalibrationReport {
  Pose cam_from_lidar = Pose::Identity();
  Mat6 covariance = Mat6::Zero();
  Vec3 sigma_t_mm = Vec3::Zero(), sigma_r_deg = Vec3::Zero();  // camera axes
  std::string method;                                          // SolverMethodName
  std::string options;                                         // the options that matter, in words
  std::string summary;  // FormatSummary of the outcome (the terminal's text)
  std::string termination;
  std::vector<double> cost_history;
  std::vector<PairReportRow> pairs;
  std::optional<CrossValidation> cross_validation;  // absent: off, or too few pairs
  std::string cross_validation_skipped;             // why it is absent
  std::vector<SigmaStep> sigma_history;
  int image_width = 0, image_height = 0;
  std::string distrust;  // which pairs to distrust, in words ("" when none stands out)
  // The clocks' offset as the solve found it, with its profile (the planes' disagreement against
  // the offset; empty for still holds or a given offset): the report plots it.
  TimeOffsetEstimate time_offset;
};

// Analyses a solved outcome (outcome.solution present; throws std::invalid_argument otherwise).
CalibrationReport AnalyseCalibration(const Dataset& dataset, const CalibrationOutcome& outcome,
                                     const PipelineOptions& options,
                                     const ReportOptions& report_options = {});

}  // namespace calibench
