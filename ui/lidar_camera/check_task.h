// The workbench's targetless check (a task of the controller, ui/lidar_camera/controller.h;
// docs/targetless.md "Workbench"): the step `calibench check` runs (LoadDatasetCheckInput,
// CheckCalibration) over the scenes of the open dataset's pairs, around the workbench's
// calibration or a result file, on the worker; what the check window shows lands in
// Snapshot::check. Its estimate adopted is an edit of the calibration in the job's record, one
// undo step (AdoptCheckEstimate). No GL, GLFW or ImGui.
#pragma once

#include <functional>
#include <string>
#include <utility>

#include "core/session/calibration_job.h"
#include "core/targetless/check.h"
#include "ui/lidar_camera/controller_snapshot.h"
#include "ui/lidar_camera/intents.h"

namespace calibench::ui {

// "0.42 deg / 13.0 mm (2.1 sigma)": a check's change in a status line.
std::string CheckChangeWords(const CheckReport& report);

class CheckTask {
 public:
  // What the controller does when an estimate is adopted (mutex held).
  struct Controls {
    std::function<CalibrationJob*()> job;  // the open dataset's job
    std::function<void()> publish;         // the job's records into the view (Publish)
    // The calibration changed: the rig's rows follow, the selected pair is reprojected.
    std::function<void()> adopted;
    std::function<void()> edited;  // the record changed: undo buttons, autosave
  };
  CheckTask(TaskHost<Snapshot> host, Controls controls)
      : host_(host), controls_(std::move(controls)) {}

  // With the controller's mutex held. Refused on the status line (and in Snapshot::check) when
  // there is nothing to check or the result file does not read; one check at a time.
  void Run(const RunCheck& request);
  // AdoptCheckEstimate: the check's estimate as the workbench's calibration, with its provenance,
  // one undo step; refused when the check gave none. Mutex held.
  void Adopt();

 private:
  TaskHost<Snapshot> host_;
  Controls controls_;
};

}  // namespace calibench::ui
