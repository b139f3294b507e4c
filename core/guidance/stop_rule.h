// When are the poses enough? σ per axis against the user's goal, and whether that σ can be
// trusted yet.
#pragma once

#include <string>

#include "core/guidance/next_pose.h"
#include "core/lidar_camera/solver.h"

namespace calibench {

struct StopRuleOptions {
  // The jackknife behind the reported σ has pairs − 1 degrees of freedom: below this many pairs
  // its own scatter is too large to call any σ final, however small.
  int min_pairs = 8;
  // The leave-one-out spread (before its small-sample widening) may exceed the reported σ by this
  // factor on an axis before the σ is called inconsistent with the data.
  double max_jackknife_ratio = 1.05;
  bool Check(std::string* why) const;
};

struct CaptureState {
  int pairs_used = 0;
  Vec3 sigma_t_mm = Vec3::Zero();   // 1σ, camera axes
  Vec3 sigma_r_deg = Vec3::Zero();  // 1σ, camera axes
  bool goal_met = false;            // every σ under the goal
  bool trustworthy = false;         // enough pairs, σ consistent with the leave-one-out spread
  bool done = false;                // both
  std::string trust_note;           // why the σ is not trusted yet ("" when it is)
  std::string weakest;              // the weakest axis against the goal, in words
};

// What the stop rule reads of a solution, whichever method made it.
struct MeterInputs {
  Pose cam_from_sensor = Pose::Identity();
  Mat6 covariance = Mat6::Zero();  // right perturbation, [rho; phi]
  bool converged = false;
  bool well_constrained = false;
  // The leave-one-out check (SolverResult::jackknife_*); methods without one say so here and
  // name their own rule in other_trust_note.
  bool has_jackknife = true;
  int jackknife_pairs = 0;
  Vec3 jackknife_sigma_t_m = Vec3::Zero();
  Vec3 jackknife_sigma_r_deg = Vec3::Zero();
  std::string jackknife_skipped;  // why it did not run (SolverResult::jackknife_skipped)
  std::string other_trust_note;   // non-empty: a method's own rule says σ is not final yet
};
MeterInputs MeterFrom(const SolverResult& solution);

// The state of a capture from its current solution (accepted pairs: pairs_used).
CaptureState JudgeCapture(const MeterInputs& solution, int pairs_used, const CaptureGoal& goal,
                          const StopRuleOptions& options);
inline CaptureState JudgeCapture(const SolverResult& solution, int pairs_used,
                                 const CaptureGoal& goal, const StopRuleOptions& options) {
  return JudgeCapture(MeterFrom(solution), pairs_used, goal, options);
}

// One line for people: "12 pairs: σ 3.1/2.0/6.2 mm, 0.05/0.08/0.04 deg against 5 mm / 0.1 deg:
// weakest translation along camera z (6.2 mm) — not done".
std::string DescribeCaptureState(const CaptureState& state, const CaptureGoal& goal);

}  // namespace calibench
