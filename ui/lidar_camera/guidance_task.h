// The meter and the next pose (a task of the controller, ui/lidar_camera/controller.h): the
// solve's σ per camera axis judged against the user's goal by the stop rule `advise` and `watch`
// use (core/guidance), its history over the solves, and where to hold the board next with
// pre-flight's findings (the job's Advise). No GL, GLFW or ImGui.
#pragma once

#include <functional>
#include <optional>
#include <utility>

#include "core/session/calibration_job.h"
#include "ui/lidar_camera/controller_snapshot.h"
#include "ui/lidar_camera/intents.h"

namespace calibench::ui {

class GuidanceTask {
 public:
  // What the controller does around guidance.
  struct Controls {
    std::function<CalibrationJob*()> job;  // the open dataset's job; null before one (mutex)
    std::function<void()> judged;          // the meter changed: the rig's rows follow (mutex)
    std::function<void()> publish;         // the job's records into the view (mutex)
    // Pre-flight rejected pairs of a followed capture: the edit recorded, solved again (mutex).
    std::function<void()> rejected;
  };
  GuidanceTask(TaskHost<Snapshot> host, Controls controls)
      : host_(host), controls_(std::move(controls)) {}

  // The meter from the current result and goal; `record` adds the point to the history (a
  // solve). Mutex held.
  void Judge(bool record);
  // SetGoal: the goal and the hand's tolerance, checked; the next pose again for a new
  // tolerance. Mutex held.
  void Apply(const SetGoal& request);
  // After a solve (worker, mutex not held): pre-flight and the next pose (the job's Advise), at
  // `at` if given.
  void Advise(const std::optional<SolverResult>& at = std::nullopt);
  // The same for a reopened or restored result, over the pairs as detected again (worker).
  void AdviseFromState();

 private:
  TaskHost<Snapshot> host_;
  Controls controls_;
};

}  // namespace calibench::ui
