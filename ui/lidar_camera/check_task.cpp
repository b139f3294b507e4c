// The workbench's targetless check and its estimate adopted, a task of the controller
// (ui/lidar_camera/check_task.h).
#include "ui/lidar_camera/check_task.h"

#include <cstdio>

#include "core/targetless/check_input.h"
#include "core/targetless/check_output.h"
#include "core/targetless/checked_calibration.h"

namespace calibench::ui {

std::string CheckChangeWords(const CheckReport& report) {
  char text[96];
  std::snprintf(text, sizeof(text), "%.2f deg / %.1f mm (%.1f sigma)", report.change_r_deg.norm(),
                1e3 * report.change_t_m.norm(), report.change_sigmas);
  return text;
}

void CheckTask::Run(const RunCheck& request) {
  Snapshot& state = host_.state;
  if (state.check.running) return;
  CheckedCalibration checked;
  std::string checked_words;
  if (request.result.empty()) {
    if (!state.solver.result) {
      state.check.failure = "nothing to check: solve first, or name a result file to check";
      host_.SetStatus("check: " + state.check.failure, true);
      return;
    }
    checked.cam_from_lidar = state.solver.result->cam_from_lidar;
    checked.camera_axes_covariance =
        CameraAxesCovariance(state.solver.result->covariance, checked.cam_from_lidar);
    checked_words = state.solver.targetless_provenance.empty()
                        ? "the workbench's calibration"
                        : "the workbench's adopted targetless estimate";
  } else {
    const std::filesystem::path path = NextToSession(state, request.result);
    try {
      checked = LoadCheckedCalibration(path);
    } catch (const IoError& e) {
      state.check.failure = e.what();
      host_.SetStatus(std::string("check: ") + e.what(), true);
      return;
    }
    checked_words = path.string();
  }
  state.check = CheckView{};
  state.check.running = true;
  state.check.checked = checked_words;
  host_.SetStatus("checking " + checked_words + " without a target over " +
                      std::to_string(state.dataset->pairs.size()) + " scenes...",
                  false);
  host_.worker.Enqueue([this, dataset = *state.dataset, checked, checked_words] {
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
    std::lock_guard lock(host_.mutex);
    Snapshot& shown = host_.state;
    shown.check = std::move(done);
    if (!shown.check.report) {
      host_.SetStatus("check: " + shown.check.failure, true);
      return;
    }
    const CheckReport& report = *shown.check.report;
    host_.SetStatus(
        "check of " + checked_words + ": " + CheckVerdictName(report.verdict) +
            (report.has_estimate ? ", change " + CheckChangeWords(report) : std::string()),
        report.verdict == CheckVerdict::kMiscalibrated);
  });
}

void CheckTask::Adopt() {
  Snapshot& state = host_.state;
  const std::shared_ptr<const CheckReport> report = state.check.report;
  if (!report || !report->has_estimate) {
    host_.SetStatus("no targetless estimate to adopt: run the check first", true);
    return;
  }
  SolverResult result;
  result.cam_from_lidar = report->estimate;
  result.covariance = RightPerturbationCovariance(report->covariance, report->estimate);
  result.observability.well_constrained = report->unconstrained_axes.empty();
  for (int axis : report->unconstrained_axes)
    result.observability.weak_directions.push_back(CameraAxisName(axis));
  state.solver = SolverView{};
  state.solver.result = result;
  state.solver.targetless_provenance =
      TargetlessProvenanceText(state.check.checked, "the workbench's check") + " (" +
      std::to_string(report->frames_used) + " frames; verdict " +
      CheckVerdictName(report->verdict) + ", change " + CheckChangeWords(*report) + ")";
  state.solver.notes = {"targetless estimate adopted: not a board solve; " +
                        state.solver.targetless_provenance};
  controls_.job()->AdoptSolution(result, state.solver.targetless_provenance, state.solver.notes);
  controls_.publish();
  // The meter judges board captures; an estimate from the scene is not one.
  state.meter.reset();
  host_.SetStatus(
      "adopted the targetless estimate as the workbench's calibration (Undo restores the "
      "one before)",
      false);
  controls_.edited();  // after the line: a failed autosave says so there
  controls_.adopted();
}

}  // namespace calibench::ui
