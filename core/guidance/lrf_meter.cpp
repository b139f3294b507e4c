#include "core/guidance/lrf_meter.h"

#include <cstdio>
#include <nlohmann/json.hpp>

#include "core/guidance/meter_json.h"

namespace calibench {

namespace {
constexpr const char* kNoNextPose =
    "no next-pose model for the three-face target: hold it at new distances and turns until "
    "the newest observation's error stays under the threshold";
}  // namespace

LrfCaptureAdvice AdviseLrfCapture(const LrfCalibrationOutcome& outcome, double error_threshold_m,
                                  const CaptureGoal& goal, const StopRuleOptions& options) {
  LrfCaptureAdvice advice;
  advice.goal = goal;
  advice.error_threshold_m = error_threshold_m;
  for (const LrfPairFeatures& p : outcome.pairs)
    advice.pairs_used += p.status == PairStatus::kAccepted;
  if (!outcome.solution || !outcome.solution->ok) return advice;
  advice.solution = outcome.solution;
  if (outcome.adaptive) {
    advice.threshold_reached = outcome.adaptive->reached_threshold;
    if (!outcome.adaptive->newest_error_m.empty())
      advice.newest_error_m = outcome.adaptive->newest_error_m.back();
    advice.pairs_used = outcome.adaptive->observations_used;
  }
  MeterInputs meter;
  meter.cam_from_sensor = outcome.solution->cam_from_lrf;
  meter.covariance = outcome.solution->covariance;
  meter.converged = outcome.solution->converged;
  meter.well_constrained = outcome.solution->observability.well_constrained;
  meter.has_jackknife = false;
  if (!advice.threshold_reached) {
    char text[200];
    std::snprintf(text, sizeof(text),
                  "Algorithm 1 has not reached its threshold: the newest observation is %.1f mm "
                  "off the estimate from the earlier ones (threshold %.1f mm)",
                  advice.newest_error_m.value_or(0.0) * 1e3, error_threshold_m * 1e3);
    meter.other_trust_note = text;
  }
  advice.state = JudgeCapture(meter, advice.pairs_used, goal, options);
  return advice;
}

std::string LrfCaptureAdviceJson(const LrfCaptureAdvice& advice) {
  nlohmann::json out =
      MeterJson(advice.pairs_used, advice.goal, "cam_from_lrf",
                advice.solution ? std::optional<Pose>(advice.solution->cam_from_lrf) : std::nullopt,
                advice.state, "no calibration yet");
  out["adaptive"] = {
      {"threshold_m", advice.error_threshold_m},
      {"newest_error_m",
       advice.newest_error_m ? nlohmann::json(*advice.newest_error_m) : nlohmann::json()},
      {"reached", advice.threshold_reached}};
  out["next"] = nullptr;
  if (!(advice.state && advice.state->done)) out["next_failure"] = kNoNextPose;
  return out.dump();
}

std::string FormatLrfCaptureAdvice(const LrfCaptureAdvice& advice) {
  std::string out;
  if (!advice.state)
    return std::to_string(advice.pairs_used) + " observations: no calibration yet\n";
  out += DescribeCaptureState(*advice.state, advice.goal) + "\n";
  char text[200];
  std::snprintf(text, sizeof(text),
                "Algorithm 1: newest observation %.1f mm off the earlier ones' estimate "
                "(threshold %.1f mm): %s\n",
                advice.newest_error_m.value_or(0.0) * 1e3, advice.error_threshold_m * 1e3,
                advice.threshold_reached ? "reached" : "not reached");
  out += text;
  if (!advice.state->done) out += std::string("next pose: ") + kNoNextPose + "\n";
  return out;
}

}  // namespace calibench
