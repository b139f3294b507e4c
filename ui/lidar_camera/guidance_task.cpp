// The meter against the goal and the next pose, as `advise` and `watch` judge them.
#include "ui/lidar_camera/guidance_task.h"

#include <algorithm>
#include <mutex>
#include <string>

namespace calibench::ui {

void GuidanceTask::Judge(bool record) {
  host_.mutex.AssertHeld(__func__);
  Snapshot& state = host_.state;
  if (!state.solver.result) {
    state.meter.reset();
    controls_.judged();
    return;
  }
  // The pairs the solve used; a reopened session's result: the pairs accepted in it.
  int pairs = static_cast<int>(state.solver.solved_pair_ids.size());
  if (pairs == 0)
    pairs = static_cast<int>(
        std::count_if(state.pairs.begin(), state.pairs.end(),
                      [](const PairView& p) { return p.status == PairStatus::kAccepted; }));
  state.meter = JudgeCapture(*state.solver.result, pairs, state.goal, StopRuleOptions{});
  controls_.judged();
  if (!record) return;
  const MeterPoint point{pairs, state.meter->sigma_t_mm, state.meter->sigma_r_deg};
  // One point per number of pairs: a solve again at the same count replaces it.
  if (!state.meter_history.empty() && state.meter_history.back().pairs == pairs)
    state.meter_history.back() = point;
  else
    state.meter_history.push_back(point);
}

void GuidanceTask::Apply(const SetGoal& request) {
  host_.mutex.AssertHeld(__func__);
  Snapshot& state = host_.state;
  std::string why;
  if (!request.goal.Check(&why)) {
    host_.SetStatus("goal: " + why, true);
    return;
  }
  if (!(request.hand_tolerance_m >= 0 && request.hand_tolerance_m <= 1.0) ||
      !(request.hand_tolerance_deg >= 0 && request.hand_tolerance_deg <= 45.0)) {
    host_.SetStatus("hand tolerance: must be within 0-100 cm and 0-45 deg", true);
    return;
  }
  state.goal = request.goal;
  Judge(/*record=*/false);
  if (request.hand_tolerance_m != state.hand_tolerance_m ||
      request.hand_tolerance_deg != state.hand_tolerance_deg) {
    state.hand_tolerance_m = request.hand_tolerance_m;
    state.hand_tolerance_deg = request.hand_tolerance_deg;
    // The next pose again, robust to the new tolerance.
    state.next_pose.reset();
    host_.worker.Enqueue([this] { AdviseFromState(); });
  }
  ++state.generation;
}

void GuidanceTask::AdviseFromState() {
  std::optional<SolverResult> at;
  {
    std::lock_guard lock(host_.mutex);
    const Snapshot& state = host_.state;
    CalibrationJob* job = controls_.job();
    if (!job || !state.solver.result || state.next_pose) return;
    at = job->OutcomeAt(*state.solver.result, state.solver.solved_pair_ids).solution;
  }
  Advise(at);
}

void GuidanceTask::Advise(const std::optional<SolverResult>& at) {
  CalibrationJob* job = nullptr;
  {
    std::lock_guard lock(host_.mutex);
    job = controls_.job();
    if (!job) return;
    job->SetGoal(host_.state.goal);
    job->SetHandTolerance(host_.state.hand_tolerance_m, host_.state.hand_tolerance_deg);
  }
  // The job's solve (pairs that joined since are judged after the next solve).
  const CaptureAdvice& advice = job->Advise(at);
  std::lock_guard lock(host_.mutex);
  Snapshot& state = host_.state;
  state.next_pose = advice.next;
  state.next_pose_failure = advice.state && advice.state->done
                                ? "the goal is met: no more poses needed"
                                : advice.next_failure;
  // Following a capture, pre-flight's rejections apply, as `watch` applies them; on a dataset
  // they are shown on the rows (the findings) and the user decides.
  const bool rejected = !state.watching.empty() && job->ApplyPreflightRejections();
  controls_.publish();
  if (rejected) controls_.rejected();
}

}  // namespace calibench::ui
