// The workbench's targetless check (a task of the controller, ui/lidar_camera/controller.h;
// docs/targetless.md "Workbench"): the step `calibench check` runs (LoadDatasetCheckInput,
// CheckCalibration) over the scenes of the open dataset's pairs, around the workbench's
// calibration or a result file, on the worker; what the check window shows lands in
// Snapshot::check. Adopting its estimate is an edit of the calibration, the controller's
// (AdoptCheckEstimate). No GL, GLFW or ImGui.
#pragma once

#include <string>

#include "core/targetless/check.h"
#include "ui/lidar_camera/controller_snapshot.h"
#include "ui/lidar_camera/intents.h"

namespace calibench::ui {

// "0.42 deg / 13.0 mm (2.1 sigma)": a check's change in a status line.
std::string CheckChangeWords(const CheckReport& report);

class CheckTask {
 public:
  explicit CheckTask(TaskHost<Snapshot> host) : host_(host) {}

  // With the controller's mutex held. Refused on the status line (and in Snapshot::check) when
  // there is nothing to check or the result file does not read; one check at a time.
  void Run(const RunCheck& request);

 private:
  TaskHost<Snapshot> host_;
};

}  // namespace calibench::ui
