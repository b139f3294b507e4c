// The solve (a task of the controller, ui/lidar_camera/controller.h): the job's solve on the
// worker, asked for (Run) or by auto-solve after an edit, watched iteration by iteration; the
// solver's settings and its reset as edits of the job's record; the solution exported as `calibench
// calibrate` writes it, or in another tool's format. No GL, GLFW or ImGui.
#pragma once

#include <functional>
#include <utility>

#include "core/session/calibration_job.h"
#include "ui/lidar_camera/controller_snapshot.h"
#include "ui/lidar_camera/guidance_task.h"
#include "ui/lidar_camera/intents.h"

namespace calibench::ui {

class SolveTask {
 public:
  // What the controller does around a solve (mutex held).
  struct Controls {
    std::function<CalibrationJob*()> job;  // the open dataset's job; null before one
    std::function<void()> publish;         // the job's records into the view (Publish)
    std::function<void()> edited;          // the record changed: undo buttons, autosave
    std::function<void(int)> reproject;    // pair `index`'s reprojection, on the worker
  };
  SolveTask(TaskHost<Snapshot> host, GuidanceTask& guidance, Controls controls)
      : host_(host), guidance_(guidance), controls_(std::move(controls)) {}

  // RunSolver: the user's solve, an undo step of its own (mutex held).
  void Run();
  // Auto-solve's after an edit, on the edit's undo step; once while one is queued (mutex held).
  void Request();
  // ResetSolver: no calibration, as an edit (mutex held).
  void Reset();
  // SetSettings: checked, into the job's record (mutex held).
  void Set(const SetSettings& intent);
  // ExportResult: what `calibench calibrate` writes, or another tool's format (mutex held).
  void Export(const ExportResult& intent);

 private:
  // `asked`: the user's Run; otherwise auto-solve's. Worker, mutex not held.
  void Solve(bool asked);

  TaskHost<Snapshot> host_;
  GuidanceTask& guidance_;
  Controls controls_;
  bool queued_ = false;  // an auto-solve is queued (mutex)
};

}  // namespace calibench::ui
