// The capture meter for the 2D LRF method: σ per axis against the goal, with the LRF paper's own
// adaptive rule (Algorithm 1: add observations until the newest one's Eq. (12) corner-to-line
// error under the estimate from the earlier ones falls below a threshold) as the test that σ is
// final. There is no next-pose model for the three-face target: it says so.
#pragma once

#include <string>

#include "core/guidance/stop_rule.h"
#include "core/lrf/pipeline.h"

namespace calibench {

struct LrfCaptureAdvice {
  int pairs_used = 0;
  std::optional<LrfSolution> solution;
  std::optional<CaptureState> state;
  CaptureGoal goal;
  double error_threshold_m = 0.0;
  std::optional<double> newest_error_m;  // Algorithm 1's last observation error
  bool threshold_reached = false;
};

// From a calibration run with options.adaptive_error_threshold_m > 0 (CalibrateLrfDataset).
LrfCaptureAdvice AdviseLrfCapture(const LrfCalibrationOutcome& outcome, double error_threshold_m,
                                  const CaptureGoal& goal, const StopRuleOptions& options);

// `advise --json` for an LRF dataset: pairs_used, cam_from_lrf, sigma_t_mm, sigma_r_deg, goal,
// done, trustworthy, trust_note, weakest, adaptive {threshold_m, newest_error_m, reached},
// next (always null) and next_failure.
std::string LrfCaptureAdviceJson(const LrfCaptureAdvice& advice);
std::string FormatLrfCaptureAdvice(const LrfCaptureAdvice& advice);

}  // namespace calibench
