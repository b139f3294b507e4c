// `calibench advise` (and, later, `watch`): the state of a capture and the next pose, from a
// calibrated dataset — σ against the goal, the stop rule, each pair's pre-flight findings and
// where to hold the board next.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/guidance/next_pose.h"
#include "core/guidance/preflight.h"
#include "core/guidance/stop_rule.h"
#include "core/intrinsics/intrinsics.h"
#include "core/io/dataset.h"
#include "core/lidar_camera/pipeline.h"
#include "core/results/pair_status.h"

namespace calibench {

struct AdviseOptions {
  CaptureGoal goal;
  StopRuleOptions stop;
  GuidanceOptions guidance;
  PreflightOptions preflight;
  PipelineOptions pipeline;     // the pipeline's options (gates, solver for the information)
  double min_distance_m = 0.0;  // usable board distance from the camera; 0 = from the data
  double max_distance_m = 0.0;
  int clouds_for_beams = 8;  // accepted pairs' clouds read to learn the LiDAR's rings
  // The camera's intrinsics are being estimated from the same pairs (`--estimate-intrinsics`):
  // the meter includes them (σ per parameter, RMS, coverage: IntrinsicsResult::good) and the
  // next pose also covers the image cells without corners.
  bool estimate_intrinsics = false;
  IntrinsicsOptions intrinsics;
  bool Check(std::string* why) const;
};

struct PairAdvice : PairStanding {
  std::vector<PreflightFinding> findings;
};

struct CaptureAdvice {
  int pairs_used = 0;
  std::optional<SolverResult> solution;
  std::optional<CaptureState> state;  // with a solution
  CaptureGoal goal;
  std::vector<PairAdvice> pairs;
  // The camera detector's reach measured on these pairs (LearnDetectionReach); a pair it missed
  // also gets a "reach" finding saying why, in words.
  DetectionReach reach;
  std::optional<PoseSuggestion> next;  // absent when done, or when nothing feasible was found
  std::string next_failure;            // why `next` is absent while not done
  // AdviseOptions::estimate_intrinsics: the camera from the pairs' corners, or why not; the
  // capture is done (state->done) only once they are good too.
  std::optional<IntrinsicsResult> intrinsics;
  std::string intrinsics_failure;
};

// From a dataset and its calibration (CalibrateDataset with options.pipeline).
CaptureAdvice AdviseCapture(const Dataset& dataset, const CalibrationOutcome& outcome,
                            const AdviseOptions& options);

// The JSON object of `advise --json` (one object, no trailing newline): pairs_used,
// cam_from_lidar (4x4 nested rows, null without a solution), sigma_t_mm, sigma_r_deg, goal
// {t_mm, r_deg}, done, trustworthy, trust_note, weakest, next (null when done, else
// {lidar_from_board, cam_from_board, words, predicted_sigma_t_mm, predicted_sigma_r_deg,
// usable_share, tolerance {translation_m, rotation_deg, usable_share, words}}), detection_reach
// {min_square_px, max_incidence_deg, max_off_axis_deg (null where nothing was measured),
// boards_found, boards_missed} and
// pairs [{name, status, reason, findings [{check, severity, words}]}]; with estimate_intrinsics,
// intrinsics {good, verdict, rms_px, parameters {name: value}, sigmas {name: σ}, cells_covered,
// border_covered, missing [words]} or {failure}.
std::string CaptureAdviceJson(const CaptureAdvice& advice);

// The same for people: the state line, the pairs with findings, the next pose in words.
std::string FormatCaptureAdvice(const CaptureAdvice& advice);
// One line of it, as a followed capture says it after each solve: σ against the goal (or the
// pairs accepted so far, without a calibration) and the next pose in words.
std::string DescribeCaptureProgress(const CaptureAdvice& advice);

}  // namespace calibench
