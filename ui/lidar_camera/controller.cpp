// The controller's solve and the intents that are neither pairs' nor the session's: selection,
// accept/reject, solver runs and options, view, export; Apply dispatches every intent.
#include "ui/lidar_camera/controller.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <type_traits>

#include "core/base/allocator.h"
#include "core/base/atomic_file.h"
#include "core/io/cloud_io.h"
#include "core/io/image_io.h"
#include "core/lidar_camera/joint_intrinsics.h"
#include "core/lidar_camera/result_io.h"
#include "core/targetless/check_output.h"
#include "ui/lidar_camera/controller_outcome.h"

namespace calibench::ui {

Controller::Controller(PipelineOptions options)
    : pipeline_(std::move(options)),
      brush_(
          Host(),
          {.job = [this] { return job_ ? &*job_ : nullptr; },
           .edited =
               [this] {
                 Publish();
                 AfterEdit();
               },
           .refit = [this](int index) { worker_.Enqueue([this, index] { RefitLidar(index); }); }}),
      guidance_(Host(), {.job = [this] { return job_ ? &*job_ : nullptr; },
                         .judged = [this] { rig_.UpdateActiveCamera(); },
                         .publish = [this] { Publish(); },
                         .rejected =
                             [this] {
                               AfterEdit();
                               RequestSolve();
                             }}),
      rig_(Host(), [this] { guidance_.Judge(/*record=*/false); }),
      check_(Host()),
      intrinsics_(Host()),
      follow_(Host(), {.open =
                           [this](const Dataset& read) {
                             if (!ResumeGrownCapture(read))
                               OpenLoadedDataset(read, {}, ExistingSession::kResume);
                           },
                       .add = [this](const PairEntry& pair) { AddPair(pair); }}) {}

Controller::~Controller() {
  StopWatching();
  StopWorker();  // drops a rig solve's steps not yet run
}

void Controller::Publish() {
  mutex_.AssertHeld(__func__);
  if (!job_) return;
  const SolverResult* shown = state_.solver.result ? &*state_.solver.result : nullptr;
  std::vector<PairRecord> records = job_->Records(shown, state_.solver.solved_pair_ids);
  // The job's record of each pair, whole (pairs that joined the view before the job are shown as
  // they are until they load).
  std::vector<PairView>& pairs = state_.pairs.Edit();
  for (size_t i = 0; i < records.size() && i < pairs.size(); ++i) {
    PairView& pair = pairs[i];
    static_cast<PairRecord&>(pair) = std::move(records[i]);
    if (pair.awaiting_detection)
      pair.lidar_failure = PairsSettled() ? "finding the board ..."
                                          : "finding the board once every pair is loaded ...";
  }
  ++state_.generation;
}

void Controller::Solve(bool asked) {
  {
    std::lock_guard lock(mutex_);
    if (!state_.dataset || !job_) return;
    state_.solver = SolverView{};
    state_.solver.running = true;
    ++state_.generation;
  }
  // The job's solve from what detection found: the CLI's steps after extraction (solve,
  // camera-guided completion, the intrinsics' σ), watched iteration by iteration (its events).
  CalibrationOutcome outcome = job_->Solve();
  const PipelineOptions options = job_->options().advise.pipeline;
  std::lock_guard lock(mutex_);
  // An undo, redo or edit while it ran (the UI thread edits the record under mutex_, which the
  // solve does not hold): its outcome answers a word that no longer stands. Written into the
  // record it would undo the undo (the rejection back, its solve standing) or lose the edit.
  // After an undo or redo the restored state stands with its own solve (Restore showed it, so
  // the solver no longer shows this one running); after an edit the edits as they are now are
  // solved again (auto-solve's, once; the user's Run). Else what it found goes into the record
  // (an undo step of its own when asked; auto-solve's on the edit's).
  if (!job_->CommitOutcome(/*own_step=*/asked)) {
    const bool restored = !state_.solver.running;
    state_.solver.running = false;
    ++state_.generation;
    if (restored) return;
    if (asked)
      worker_.Enqueue([this] { Solve(); });
    else
      RequestSolve();
    return;
  }
  state_.solver.running = false;
  if (!outcome.solution) {
    state_.solver.iterations.clear();
    state_.solver.failure = outcome.failure;
    Publish();
    const int usable = static_cast<int>(
        std::count_if(outcome.pairs.begin(), outcome.pairs.end(), [](const PairFeatures& p) {
          return p.status == PairStatus::kAccepted && p.lidar && p.camera;
        }));
    // Too few pairs yet is no error while a capture is followed: it says how many are needed.
    if (!state_.watching.empty() && usable < options.min_pairs)
      SetStatus("solving once " + std::to_string(options.min_pairs) + " pairs are usable (" +
                    std::to_string(usable) + " so far)",
                false);
    else
      SetStatus("no calibration: " + outcome.failure, true);
    AfterEdit();  // after the line: a failed autosave says so there
    return;
  }
  const SolverResult& result = *outcome.solution;
  state_.solver.result = result;
  state_.solver.solved_pair_ids.clear();
  for (const PairFeatures& p : outcome.pairs)
    if (p.status == PairStatus::kAccepted) state_.solver.solved_pair_ids.push_back(p.id);
  // The summary's notes, as the job recorded them beside the result.
  if (const Session record = job_->record().Current(); record.result)
    state_.solver.notes = record.result->notes;
  Publish();
  guidance_.Judge(/*record=*/true);
  SetStatus("solved with " + std::to_string(state_.solver.solved_pair_ids.size()) + " pairs in " +
                std::to_string(result.iterations) + " iterations" +
                (result.observability.well_constrained ? "" : " (NOT well constrained)"),
            !result.observability.well_constrained);
  AfterEdit();
  const int selected = state_.selected;
  if (selected >= 0) worker_.Enqueue([this, selected] { ComputeReprojection(selected); });
  // Pre-flight and the next pose (the ghost board) from this solve.
  worker_.Enqueue([this] { guidance_.Advise(); });
}

void Controller::ComputeReprojection(int index) {
  std::shared_ptr<const LidarCloud> cloud;
  std::optional<Pose> cam_from_lidar;
  CameraModel camera;
  ViewState view;
  std::string id;
  {
    std::lock_guard lock(mutex_);
    if (index < 0 || index >= static_cast<int>(state_.pairs.size()) || !state_.solver.result)
      return;
    cloud = state_.pairs.at(index).cloud;
    cam_from_lidar = state_.solver.result->cam_from_lidar;
    camera = state_.dataset->camera;
    view = state_.view;
    id = state_.pairs.at(index).id;
  }
  if (!cloud) return;
  auto reprojection = ReprojectPair(camera, *cam_from_lidar, *cloud, view, id);
  std::lock_guard lock(mutex_);
  state_.reprojection = reprojection;
  ++state_.generation;
}

void Controller::EnsureSelectedImage() {
  std::filesystem::path path;
  const std::shared_ptr<const ImageU8> image = LoadSelectedImageFile(&path);
  if (!image) return;
  CameraModel camera;
  {
    std::lock_guard lock(mutex_);
    camera = state_.dataset->camera;
  }
  auto undistorted = std::make_shared<const UndistortedView>(Undistort(camera, *image));
  std::lock_guard lock(mutex_);
  if (!StillSelected(path)) return;
  state_.selected_image = image;
  state_.selected_image_pair = state_.pairs.at(state_.selected).id;
  state_.selected_undistorted = undistorted;
  ++state_.generation;
  if (state_.rig && state_.rig->Several()) worker_.Enqueue([this] { rig_.LoadFrames(); });
}

bool Controller::ValidPair(int index) const {
  return index >= 0 && index < static_cast<int>(state_.pairs.size());
}

template <>
void Controller::Handle(const SelectPair& select) {
  if (!ValidPair(select.index) || select.index == state_.selected) return;
  // Following a capture: looking at an older pair stops following; the newest resumes it.
  follow_newest_ = select.index + 1 == static_cast<int>(state_.pairs.size());
  state_.selected = select.index;
  state_.selected_image.reset();
  state_.selected_undistorted.reset();
  state_.reprojection.reset();
  RecordView();
  worker_.Enqueue([this] { EnsureSelectedImage(); });
  const int index = select.index;
  worker_.Enqueue([this, index] { ComputeReprojection(index); });
}

template <>
void Controller::Handle(const SetPairStatus& status) {
  if (!ValidPair(status.index)) return;
  const PairView& pair = state_.pairs.at(status.index);
  if (status.status == PairStatus::kAccepted && !(pair.lidar && pair.camera)) {
    SetStatus("pair " + pair.id + " cannot be accepted: " +
                  (!pair.camera ? "no camera plane (" + pair.camera_failure + ")"
                                : "no LiDAR plane (" + pair.lidar_failure + ")"),
              true);
    return;
  }
  const bool rejecting = status.status == PairStatus::kRejected;
  const std::string id = pair.id;
  // The user's word into the job's record (the next solve reads it there), then shown.
  if (rejecting != (pair.status == PairStatus::kRejected)) job_->SetRejected(id, rejecting);
  Publish();
  SetStatus("pair " + id + " " + PairStatusName(state_.pairs.at(status.index).status) +
                (state_.solver.result && !state_.auto_solve ? "; press Run to re-solve" : ""),
            false);
  AfterEdit();  // after the line: a failed autosave says so there
  RequestSolve();
}

template <>
void Controller::Handle(const RunSolver&) {
  worker_.Enqueue([this] { Solve(); });
}

template <>
void Controller::Handle(const ResetSolver&) {
  state_.solver = SolverView{};
  state_.reprojection.reset();
  job_->record().Edit([](Session* session) { session->result.reset(); });
  Publish();
  guidance_.Judge(/*record=*/false);
  AfterEdit();
}

template <>
void Controller::Handle(const SetSettings& intent) {
  const JobSettings& settings = intent.settings;
  std::string why;
  if (!settings.Check(&why)) {
    SetStatus("solver options: " + why, true);
    return;
  }
  const bool method_changed =
      state_.settings.method != settings.method ||
      state_.settings.estimate_range_offset != settings.estimate_range_offset;
  state_.settings = settings;
  // Into the job's record as the user set them (JobSettings::Apply reads them).
  job_->SetSettings(settings);
  AfterEdit();
  // Residuals and weights shown for the current estimate depend on the method.
  if (method_changed) Publish();
}

template <>
void Controller::Handle(const SetView& view) {
  const bool visibility_changed = view.view.visibility != state_.view.visibility ||
                                  view.view.hpr_radius_exponent != state_.view.hpr_radius_exponent;
  state_.view = view.view;
  RecordView();
  if (visibility_changed) {
    const int index = state_.selected;
    worker_.Enqueue([this, index] { ComputeReprojection(index); });
  }
}

template <>
void Controller::Handle(const ExportResult& export_result) {
  if (!state_.solver.result) {
    SetStatus("nothing to export: run the solver first", true);
    return;
  }
  // What `calibench calibrate` writes: the pairs as they stand, the solution with the solver's
  // residuals at it for the accepted ones.
  const CalibrationOutcome outcome =
      job_->OutcomeAt(*state_.solver.result, state_.solver.solved_pair_ids);
  const std::filesystem::path path = NextToSession(state_, export_result.path);
  try {
    if (export_result.format) {
      const ExportFrames& frames = export_result.frames;
      std::string why;
      if (!frames.Check(&why)) {
        SetStatus("export: " + why, true);
        return;
      }
      const std::string source =
          state_.session_path.empty() ? "the workbench" : state_.session_path.filename().string();
      WriteFileAtomically(path, ExportCalibration(*export_result.format,
                                                  outcome.solution->cam_from_lidar, frames, source)
                                    .text);
      SetStatus("exported " + path.string() + " (" + ExportFormatName(*export_result.format) +
                    "): the pose of '" + frames.child() + "' in '" + frames.parent() +
                    "', camera frame " + CameraFrameName(frames.camera_frame),
                false);
      return;
    }
    if (!state_.solver.targetless_provenance.empty()) {
      // An adopted targetless estimate: no board solve stands behind it, and the file says so.
      WriteTargetlessResult(path, outcome.solution->cam_from_lidar, outcome.solution->covariance,
                            outcome.solution->observability.weak_directions,
                            state_.solver.targetless_provenance);
      SetStatus("exported " + path.string() + " (the adopted targetless estimate)", false);
      return;
    }
    WriteResult(path, outcome, state_.settings.Over(pipeline_).solver);
    SetStatus("exported " + path.string(), false);
  } catch (const IoError& e) {
    SetStatus(e.what(), true);
  }
}

void Controller::Apply(const Intent& intent) {
  std::lock_guard lock(mutex_);
  // A followed recording's board is picked before anything opens: its first pair needs it.
  if (!state_.dataset && !std::holds_alternative<PickBoard>(intent)) return;
  // A stroke is its dabs; anything else in between ends it.
  if (!std::holds_alternative<BrushStroke>(intent) && !std::holds_alternative<PaintPoints>(intent))
    brush_.EndStroke();
  // The tasks' intents to their tasks, the rest to the controller's own handlers.
  std::visit(
      [this](const auto& what) {
        using What = std::decay_t<decltype(what)>;
        if constexpr (std::is_same_v<What, BrushStroke> || std::is_same_v<What, PaintPoints>)
          brush_.Paint(what);
        else if constexpr (std::is_same_v<What, ClearBrush>)
          brush_.Clear(what);
        else if constexpr (std::is_same_v<What, DetectBoardAgain>)
          brush_.DetectAgain(what);
        else if constexpr (std::is_same_v<What, EndStroke>)
          ;  // ended above, as by any intent but a dab
        else if constexpr (std::is_same_v<What, SetGoal>)
          guidance_.Apply(what);
        else if constexpr (std::is_same_v<What, EstimateIntrinsics>)
          intrinsics_.Estimate(what);
        else if constexpr (std::is_same_v<What, SaveIntrinsics>)
          intrinsics_.Save(what);
        else if constexpr (std::is_same_v<What, RunCheck>)
          check_.Run(what);
        else if constexpr (std::is_same_v<What, PickBoard>)
          follow_.Pick(what);
        else if constexpr (std::is_same_v<What, SelectCamera>)
          rig_.Select(what);
        else if constexpr (std::is_same_v<What, SolveRig>) {
          if (state_.rig && state_.rig->Several())
            StartRigSolve();
          else
            SetStatus("not a rig: there is one camera", true);
        } else
          Handle(what);
      },
      intent);
}

void Controller::StartRigSolve() {
  mutex_.AssertHeld(__func__);
  rig_.Start(job_ ? job_->record().Edits() : PairEdits{}, state_.settings.Over(pipeline_));
}

}  // namespace calibench::ui
