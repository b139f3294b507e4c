#include "core/guidance/stop_rule.h"

#include <cstdio>

#include "core/estimation/uncertainty.h"

namespace calibench {

bool StopRuleOptions::Check(std::string* why) const {
  if (min_pairs < 4) return *why = "the stop rule needs min_pairs >= 4 (the jackknife)", false;
  if (!(max_jackknife_ratio >= 1)) return *why = "max_jackknife_ratio must be >= 1", false;
  return true;
}

MeterInputs MeterFrom(const SolverResult& solution) {
  MeterInputs m;
  m.cam_from_sensor = solution.cam_from_lidar;
  m.covariance = solution.covariance;
  m.converged = solution.converged;
  m.well_constrained = solution.observability.well_constrained;
  m.jackknife_pairs = solution.jackknife_pairs;
  m.jackknife_sigma_t_m = solution.jackknife_sigma_t_m;
  m.jackknife_sigma_r_deg = solution.jackknife_sigma_r_deg;
  m.jackknife_skipped = solution.jackknife_skipped;
  return m;
}

CaptureState JudgeCapture(const MeterInputs& solution, int pairs_used, const CaptureGoal& goal,
                          const StopRuleOptions& options) {
  CaptureState state;
  state.pairs_used = pairs_used;
  state.sigma_t_mm = TranslationStd(solution.covariance, solution.cam_from_sensor) * 1e3;
  state.sigma_r_deg = RotationStdDeg(solution.covariance, solution.cam_from_sensor);
  state.goal_met = (state.sigma_t_mm.array() <= goal.translation_mm).all() &&
                   (state.sigma_r_deg.array() <= goal.rotation_deg).all();
  char text[240];
  static const char* kAxes[3] = {"x", "y", "z"};
  int t_axis = 0, r_axis = 0;
  const double t_ratio = (state.sigma_t_mm / goal.translation_mm).maxCoeff(&t_axis);
  const double r_ratio = (state.sigma_r_deg / goal.rotation_deg).maxCoeff(&r_axis);
  if (t_ratio >= r_ratio)
    std::snprintf(text, sizeof(text), "translation along camera %s (%.1f mm, goal %.1f mm)",
                  kAxes[t_axis], state.sigma_t_mm[t_axis], goal.translation_mm);
  else
    std::snprintf(text, sizeof(text), "rotation about camera %s (%.3f deg, goal %.3f deg)",
                  kAxes[r_axis], state.sigma_r_deg[r_axis], goal.rotation_deg);
  state.weakest = text;
  if (pairs_used < options.min_pairs) {
    std::snprintf(text, sizeof(text), "%d pairs: σ is trusted from %d pairs on", pairs_used,
                  options.min_pairs);
    state.trust_note = text;
  } else if (!solution.converged) {
    state.trust_note = "the solver did not converge";
  } else if (!solution.well_constrained) {
    state.trust_note = "the pose is not well constrained (see the weak directions)";
  } else if (!solution.other_trust_note.empty()) {
    state.trust_note = solution.other_trust_note;
  } else if (!solution.has_jackknife) {
    // The method's own rule (above) stands in for the leave-one-out check.
  } else if (solution.jackknife_pairs == 0) {
    state.trust_note = "no leave-one-out check: " + (solution.jackknife_skipped.empty()
                                                         ? std::string("it did not run")
                                                         : solution.jackknife_skipped);
  } else if (solution.jackknife_pairs < options.min_pairs) {
    std::snprintf(text, sizeof(text),
                  "the leave-one-out check ran over %d pairs (the solve set the others aside as "
                  "outliers); σ is trusted from %d",
                  solution.jackknife_pairs, options.min_pairs);
    state.trust_note = text;
  } else {
    const Vec3 t = solution.jackknife_sigma_t_m * 1e3;
    const Vec3 r = solution.jackknife_sigma_r_deg;
    const double ratio = std::max((t.array() / state.sigma_t_mm.array().max(1e-9)).maxCoeff(),
                                  (r.array() / state.sigma_r_deg.array().max(1e-12)).maxCoeff());
    if (ratio > options.max_jackknife_ratio) {
      std::snprintf(text, sizeof(text),
                    "the leave-one-out spread is %.1f× the reported σ: the σ understates the "
                    "pairs' scatter",
                    ratio);
      state.trust_note = text;
    }
  }
  state.trustworthy = state.trust_note.empty();
  state.done = state.goal_met && state.trustworthy;
  return state;
}

std::string DescribeCaptureState(const CaptureState& state, const CaptureGoal& goal) {
  char text[480];
  std::snprintf(text, sizeof(text),
                "%d pairs: σ %.1f/%.1f/%.1f mm, %.3f/%.3f/%.3f deg against %.1f mm / %.3f deg; "
                "weakest: %s — %s",
                state.pairs_used, state.sigma_t_mm.x(), state.sigma_t_mm.y(), state.sigma_t_mm.z(),
                state.sigma_r_deg.x(), state.sigma_r_deg.y(), state.sigma_r_deg.z(),
                goal.translation_mm, goal.rotation_deg, state.weakest.c_str(),
                state.done       ? "done"
                : state.goal_met ? ("goal met, not trusted yet: " + state.trust_note).c_str()
                                 : "not done");
  return text;
}

}  // namespace calibench
