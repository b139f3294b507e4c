// What a report says about a 2D LRF solve (`calibench report` on an LRF result): both directions
// with σ, per observation its residual, its weight and how far the result moves without it;
// held-out cross-validation (leave one observation out, predict its residual); a drawing of each
// scan with the camera's faces (or board) carried into the LRF plane by the result. Computed from
// the LRF pipeline's own outcome, re-solving with its own solver (SolveLrfFromFeatures).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/lrf/pipeline.h"
#include "core/report/report_html.h"
#include "core/results/pair_status.h"

namespace calibench {

struct LrfReportOptions {
  bool cross_validate = true;
  // An observation disagrees when its held-out residual stands out of the others' by this many
  // robust standard deviations (1.4826 MAD) and exceeds min_ratio times their median.
  double disagree_sigmas = 3.5;
  double min_ratio = 2.0;
  bool Check(std::string* why) const;
};

struct LrfPairReportRow : PairStanding {
  bool solved = false;
  // The target's own residual at the solution (mm): Eq. (12)'s mean corner-to-line distance for
  // the three-face target, the board scan points' RMS distance to the camera's board plane for
  // the checkerboard; the refined method's scan-point-to-face RMS and Huber weight.
  std::optional<double> residual_mm, point_to_plane_mm, weight;
  // Leave-one-out: how far the result moves without it, its residual under the others' solve.
  std::optional<double> influence_mm, influence_deg, heldout_mm;
  bool disagrees = false;
  std::string svg;  // the scan from above with the camera's target carried in ("" without one)
};

struct LrfReport {
  LrfTargetType target = LrfTargetType::kThreeFace;
  std::string method;  // LrfMethodName
  Pose cam_from_lrf = Pose::Identity();
  Mat6 covariance = Mat6::Zero();
  Vec3 sigma_t_mm = Vec3::Zero(), sigma_r_deg = Vec3::Zero();  // camera axes
  // The solve's observability: the directions no observation fixes, in words (empty when well
  // constrained).
  bool well_constrained = false;
  std::vector<std::string> weak_directions;
  std::string residual_name;  // what residual_mm is, in words
  std::string summary;        // FormatLrfSummary
  std::vector<double> cost_history;
  std::vector<LrfPairReportRow> pairs;
  int folds = 0;  // 0: not cross-validated (cross_validation_skipped says why)
  double train_rms_mm = 0.0, heldout_rms_mm = 0.0;
  std::string verdict;  // "consistent: ..." or "observation X disagrees: ..."
  std::string cross_validation_skipped;
};

// Analyses a solved outcome (outcome.solution present; throws std::invalid_argument otherwise).
LrfReport AnalyseLrfCalibration(const LrfDataset& dataset, const LrfCalibrationOutcome& outcome,
                                const LrfPipelineOptions& options,
                                const LrfReportOptions& report_options = {});

std::string LrfReportHtml(const LrfReport& report, const ReportProvenance& provenance,
                          const ReportAssets& assets);

}  // namespace calibench
