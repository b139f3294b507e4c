// The solve, a task of the controller: the job's solve on the worker, auto-solve, the solver's
// settings and reset, export (ui/lidar_camera/solve_task.h).
#include "ui/lidar_camera/solve_task.h"

#include <algorithm>

#include "core/base/atomic_file.h"
#include "core/lidar_camera/result_io.h"
#include "core/results/export.h"
#include "core/targetless/check_output.h"

namespace calibench::ui {

void SolveTask::Solve(bool asked) {
  CalibrationJob* job = nullptr;
  {
    std::lock_guard lock(host_.mutex);
    job = controls_.job();
    if (!host_.state.dataset || !job) return;
    host_.state.solver = SolverView{};
    host_.state.solver.running = true;
    ++host_.state.generation;
  }
  // The job's solve from what detection found: the CLI's steps after extraction (solve,
  // camera-guided completion, the intrinsics' σ), watched iteration by iteration (its events).
  CalibrationOutcome outcome = job->Solve();
  const PipelineOptions options = job->options().advise.pipeline;
  std::lock_guard lock(host_.mutex);
  // An undo, redo or edit while it ran (the UI thread edits the record under mutex_, which the
  // solve does not hold): its outcome answers a word that no longer stands. Written into the
  // record it would undo the undo (the rejection back, its solve standing) or lose the edit.
  // After an undo or redo the restored state stands with its own solve (Restore showed it, so
  // the solver no longer shows this one running); after an edit the edits as they are now are
  // solved again (auto-solve's, once; the user's Run). Else what it found goes into the record
  // (an undo step of its own when asked; auto-solve's on the edit's).
  if (!job->CommitOutcome(/*own_step=*/asked)) {
    const bool restored = !host_.state.solver.running;
    host_.state.solver.running = false;
    ++host_.state.generation;
    if (restored) return;
    if (asked)
      host_.worker.Enqueue([this] { Solve(/*asked=*/true); });
    else
      Request();
    return;
  }
  host_.state.solver.running = false;
  if (!outcome.solution) {
    host_.state.solver.iterations.clear();
    host_.state.solver.failure = outcome.failure;
    controls_.publish();
    const int usable = static_cast<int>(
        std::count_if(outcome.pairs.begin(), outcome.pairs.end(), [](const PairFeatures& p) {
          return p.status == PairStatus::kAccepted && p.lidar && p.camera;
        }));
    // Too few pairs yet is no error while a capture is followed: it says how many are needed.
    if (!host_.state.watching.empty() && usable < options.min_pairs)
      host_.SetStatus("solving once " + std::to_string(options.min_pairs) + " pairs are usable (" +
                          std::to_string(usable) + " so far)",
                      false);
    else
      host_.SetStatus("no calibration: " + outcome.failure, true);
    controls_.edited();  // after the line: a failed autosave says so there
    return;
  }
  const SolverResult& result = *outcome.solution;
  host_.state.solver.result = result;
  host_.state.solver.solved_pair_ids.clear();
  for (const PairFeatures& p : outcome.pairs)
    if (p.status == PairStatus::kAccepted) host_.state.solver.solved_pair_ids.push_back(p.id);
  // The summary's notes, as the job recorded them beside the result.
  if (const Session record = job->record().Current(); record.result)
    host_.state.solver.notes = record.result->notes;
  controls_.publish();
  guidance_.Judge(/*record=*/true);
  host_.SetStatus("solved with " + std::to_string(host_.state.solver.solved_pair_ids.size()) +
                      " pairs in " + std::to_string(result.iterations) + " iterations" +
                      (result.observability.well_constrained ? "" : " (NOT well constrained)"),
                  !result.observability.well_constrained);
  controls_.edited();
  const int selected = host_.state.selected;
  if (selected >= 0) controls_.reproject(selected);
  // Pre-flight and the next pose (the ghost board) from this solve.
  host_.worker.Enqueue([this] { guidance_.Advise(); });
}

void SolveTask::Request() {
  host_.mutex.AssertHeld(__func__);
  if (!host_.state.auto_solve || queued_ || !host_.state.dataset) return;
  queued_ = true;
  host_.worker.Enqueue([this] {
    {
      std::lock_guard lock(host_.mutex);
      queued_ = false;
    }
    Solve(/*asked=*/false);
  });
}

void SolveTask::Run() {
  host_.worker.Enqueue([this] { Solve(/*asked=*/true); });
}

void SolveTask::Reset() {
  CalibrationJob* job = controls_.job();
  host_.state.solver = SolverView{};
  host_.state.reprojection.reset();
  job->record().Edit([](Session* session) { session->result.reset(); });
  controls_.publish();
  guidance_.Judge(/*record=*/false);
  controls_.edited();
}

void SolveTask::Set(const SetSettings& intent) {
  const JobSettings& settings = intent.settings;
  std::string why;
  if (!settings.Check(&why)) {
    host_.SetStatus("solver options: " + why, true);
    return;
  }
  const bool method_changed =
      host_.state.settings.method != settings.method ||
      host_.state.settings.estimate_range_offset != settings.estimate_range_offset;
  host_.state.settings = settings;
  CalibrationJob* job = controls_.job();
  // Into the job's record as the user set them (JobSettings::Apply reads them).
  job->SetSettings(settings);
  controls_.edited();
  // Residuals and weights shown for the current estimate depend on the method.
  if (method_changed) controls_.publish();
}

void SolveTask::Export(const ExportResult& export_result) {
  if (!host_.state.solver.result) {
    host_.SetStatus("nothing to export: run the solver first", true);
    return;
  }
  // What `calibench calibrate` writes: the pairs as they stand, the solution with the solver's
  // residuals at it for the accepted ones.
  CalibrationJob* job = controls_.job();
  const CalibrationOutcome outcome =
      job->OutcomeAt(*host_.state.solver.result, host_.state.solver.solved_pair_ids);
  const std::filesystem::path path = NextToSession(host_.state, export_result.path);
  try {
    if (export_result.format) {
      const ExportFrames& frames = export_result.frames;
      std::string why;
      if (!frames.Check(&why)) {
        host_.SetStatus("export: " + why, true);
        return;
      }
      const std::string source = host_.state.session_path.empty()
                                     ? "the workbench"
                                     : host_.state.session_path.filename().string();
      WriteFileAtomically(path, ExportCalibration(*export_result.format,
                                                  outcome.solution->cam_from_lidar, frames, source)
                                    .text);
      host_.SetStatus("exported " + path.string() + " (" + ExportFormatName(*export_result.format) +
                          "): the pose of '" + frames.child() + "' in '" + frames.parent() +
                          "', camera frame " + CameraFrameName(frames.camera_frame),
                      false);
      return;
    }
    if (!host_.state.solver.targetless_provenance.empty()) {
      // An adopted targetless estimate: no board solve stands behind it, and the file says so.
      WriteTargetlessResult(path, outcome.solution->cam_from_lidar, outcome.solution->covariance,
                            outcome.solution->observability.weak_directions,
                            host_.state.solver.targetless_provenance);
      host_.SetStatus("exported " + path.string() + " (the adopted targetless estimate)", false);
      return;
    }
    // The solver's options as the job's next step runs them (its record's settings).
    WriteResult(path, outcome, job->options().advise.pipeline.solver);
    host_.SetStatus("exported " + path.string(), false);
  } catch (const IoError& e) {
    host_.SetStatus(e.what(), true);
  }
}

}  // namespace calibench::ui
