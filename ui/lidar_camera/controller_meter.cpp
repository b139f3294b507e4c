// The workbench's meter: the solve's σ per camera axis against the user's goal, judged by the
// stop rule `advise` and `watch` use (core/guidance), with its history over the solves.
#include <algorithm>

#include "ui/lidar_camera/controller.h"

namespace calibench::ui {

void Controller::JudgeMeter(bool record) {
  mutex_.AssertHeld(__func__);
  if (!state_.solver.result) {
    state_.meter.reset();
    rig_.UpdateActiveCamera();
    return;
  }
  // The pairs the solve used; a reopened session's result: the pairs accepted in it.
  int pairs = static_cast<int>(state_.solver.solved_pair_ids.size());
  if (pairs == 0)
    pairs = static_cast<int>(
        std::count_if(state_.pairs.begin(), state_.pairs.end(),
                      [](const PairView& p) { return p.status == PairStatus::kAccepted; }));
  state_.meter = JudgeCapture(*state_.solver.result, pairs, state_.goal, StopRuleOptions{});
  rig_.UpdateActiveCamera();
  if (!record) return;
  const MeterPoint point{pairs, state_.meter->sigma_t_mm, state_.meter->sigma_r_deg};
  // One point per number of pairs: a solve again at the same count replaces it.
  if (!state_.meter_history.empty() && state_.meter_history.back().pairs == pairs)
    state_.meter_history.back() = point;
  else
    state_.meter_history.push_back(point);
}

template <>
void Controller::Handle(const SetGoal& request) {
  std::string why;
  if (!request.goal.Check(&why)) {
    SetStatus("goal: " + why, true);
    return;
  }
  if (!(request.hand_tolerance_m >= 0 && request.hand_tolerance_m <= 1.0) ||
      !(request.hand_tolerance_deg >= 0 && request.hand_tolerance_deg <= 45.0)) {
    SetStatus("hand tolerance: must be within 0-100 cm and 0-45 deg", true);
    return;
  }
  state_.goal = request.goal;
  JudgeMeter(/*record=*/false);
  if (request.hand_tolerance_m != state_.hand_tolerance_m ||
      request.hand_tolerance_deg != state_.hand_tolerance_deg) {
    state_.hand_tolerance_m = request.hand_tolerance_m;
    state_.hand_tolerance_deg = request.hand_tolerance_deg;
    // The next pose again, robust to the new tolerance.
    state_.next_pose.reset();
    worker_.Enqueue([this] { AdviseFromState(); });
  }
  ++state_.generation;
}

}  // namespace calibench::ui
