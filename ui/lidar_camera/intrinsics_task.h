// The workbench's camera intrinsics (a task of the controller, ui/lidar_camera/controller.h):
// estimated from the loaded pairs' board corners by the step `calibench intrinsics` runs
// (CalibrateIntrinsics), on the worker, and written beside the dataset on request. The dataset's
// camera is never changed. No GL, GLFW or ImGui.
#pragma once

#include "ui/lidar_camera/controller_snapshot.h"
#include "ui/lidar_camera/intents.h"

namespace calibench::ui {

class IntrinsicsTask {
 public:
  explicit IntrinsicsTask(TaskHost<Snapshot> host) : host_(host) {}

  // Both with the controller's mutex held; the estimate's result lands in the snapshot
  // (Snapshot::intrinsics, intrinsics_failure) when the worker is done.
  void Estimate(const EstimateIntrinsics& request);
  void Save(const SaveIntrinsics& request);

 private:
  TaskHost<Snapshot> host_;
};

}  // namespace calibench::ui
