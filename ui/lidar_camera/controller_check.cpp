// The controller's edit from the targetless check: its estimate adopted as the workbench's
// calibration, with its provenance, as one undo step (the check itself is CheckTask's,
// ui/lidar_camera/check_task.h).
#include "core/targetless/check_output.h"
#include "ui/lidar_camera/check_task.h"
#include "ui/lidar_camera/controller.h"

namespace calibench::ui {

template <>
void Controller::Handle(const AdoptCheckEstimate&) {
  const std::shared_ptr<const CheckReport> report = state_.check.report;
  if (!report || !report->has_estimate) {
    SetStatus("no targetless estimate to adopt: run the check first", true);
    return;
  }
  SolverResult result;
  result.cam_from_lidar = report->estimate;
  result.covariance = RightPerturbationCovariance(report->covariance, report->estimate);
  result.observability.well_constrained = report->unconstrained_axes.empty();
  for (int axis : report->unconstrained_axes)
    result.observability.weak_directions.push_back(CameraAxisName(axis));
  state_.solver = SolverView{};
  state_.solver.result = result;
  state_.solver.targetless_provenance =
      TargetlessProvenanceText(state_.check.checked, "the workbench's check") + " (" +
      std::to_string(report->frames_used) + " frames; verdict " +
      CheckVerdictName(report->verdict) + ", change " + CheckChangeWords(*report) + ")";
  state_.solver.notes = {"targetless estimate adopted: not a board solve; " +
                         state_.solver.targetless_provenance};
  job_->AdoptSolution(result, state_.solver.targetless_provenance, state_.solver.notes);
  Publish();
  // The meter judges board captures; an estimate from the scene is not one.
  state_.meter.reset();
  rig_.UpdateActiveCamera();
  SetStatus(
      "adopted the targetless estimate as the workbench's calibration (Undo restores the "
      "one before)",
      false);
  AfterEdit();  // after the line: a failed autosave says so there
  const int selected = state_.selected;
  if (selected >= 0) worker_.Enqueue([this, selected] { ComputeReprojection(selected); });
}

}  // namespace calibench::ui
