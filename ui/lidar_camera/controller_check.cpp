// The workbench's targetless check (docs/targetless.md "Workbench"): the step `calibench check`
// runs (LoadDatasetCheckInput, CheckCalibration) over the scenes of the open dataset's pairs,
// around the workbench's calibration or a result file; its estimate adopted on request as the
// workbench's calibration, with its provenance, as one undo step.
#include <cstdio>

#include "core/targetless/check_input.h"
#include "core/targetless/check_output.h"
#include "core/targetless/checked_calibration.h"
#include "ui/lidar_camera/controller.h"

namespace calibench::ui {
namespace {

// "0.42 deg / 13.0 mm (2.1 sigma)": a check's change in a status line.
std::string ChangeWords(const CheckReport& report) {
  char text[96];
  std::snprintf(text, sizeof(text), "%.2f deg / %.1f mm (%.1f sigma)", report.change_r_deg.norm(),
                1e3 * report.change_t_m.norm(), report.change_sigmas);
  return text;
}

}  // namespace

template <>
void Controller::Handle(const RunCheck& request) {
  if (state_.check.running) return;
  CheckedCalibration checked;
  std::string checked_words;
  if (request.result.empty()) {
    if (!state_.solver.result) {
      state_.check.failure = "nothing to check: solve first, or name a result file to check";
      SetStatus("check: " + state_.check.failure, true);
      return;
    }
    checked.cam_from_lidar = state_.solver.result->cam_from_lidar;
    checked.camera_axes_covariance =
        CameraAxesCovariance(state_.solver.result->covariance, checked.cam_from_lidar);
    checked_words = state_.solver.targetless_provenance.empty()
                        ? "the workbench's calibration"
                        : "the workbench's adopted targetless estimate";
  } else {
    const std::filesystem::path path = NextToSession(request.result);
    try {
      checked = LoadCheckedCalibration(path);
    } catch (const IoError& e) {
      state_.check.failure = e.what();
      SetStatus(std::string("check: ") + e.what(), true);
      return;
    }
    checked_words = path.string();
  }
  state_.check = CheckView{};
  state_.check.running = true;
  state_.check.checked = checked_words;
  SetStatus("checking " + checked_words + " without a target over " +
                std::to_string(state_.dataset->pairs.size()) + " scenes...",
            false);
  worker_.Enqueue([this, dataset = *state_.dataset, checked, checked_words] {
    const CheckOptions options;
    CheckView done;
    done.checked = checked_words;
    try {
      CheckInput input = LoadDatasetCheckInput(dataset, options, CheckInputOptions{});
      done.report = std::make_shared<const CheckReport>(
          CheckCalibration(input.frames, input.camera, checked.cam_from_lidar,
                           checked.camera_axes_covariance, options));
      auto edges = std::make_shared<std::map<std::string, std::vector<SceneEdgePoint>>>();
      for (EdgeFrame& frame : input.frames) (*edges)[frame.id] = std::move(frame.lidar_edges);
      done.lidar_edges = std::move(edges);
      done.unreadable = std::move(input.unreadable);
    } catch (const IoError& e) {
      done.failure = e.what();
    }
    std::lock_guard lock(mutex_);
    state_.check = std::move(done);
    if (!state_.check.report) {
      SetStatus("check: " + state_.check.failure, true);
      return;
    }
    const CheckReport& report = *state_.check.report;
    SetStatus("check of " + checked_words + ": " + CheckVerdictName(report.verdict) +
                  (report.has_estimate ? ", change " + ChangeWords(report) : std::string()),
              report.verdict == CheckVerdict::kMiscalibrated);
  });
}

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
      CheckVerdictName(report->verdict) + ", change " + ChangeWords(*report) + ")";
  state_.solver.notes = {"targetless estimate adopted: not a board solve; " +
                         state_.solver.targetless_provenance};
  RecomputeResiduals();
  // The meter judges board captures; an estimate from the scene is not one.
  state_.meter.reset();
  UpdateActiveRigCamera();
  RecordWhatFollowed(/*same_step=*/false);  // an undo step of its own
  SetStatus(
      "adopted the targetless estimate as the workbench's calibration (Undo restores the "
      "one before)",
      false);
  const int selected = state_.selected;
  if (selected >= 0) worker_.Enqueue([this, selected] { ComputeReprojection(selected); });
}

}  // namespace calibench::ui
