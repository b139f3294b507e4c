// The controller's own intents (selection, accept/reject, the view) and Apply, which routes every
// other intent to its task.
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
      session_(Host()),
      view_(Host(),
            {.job = [this] { return job_ ? &*job_ : nullptr; },
             .edited = [this] { session_.Edited(); },
             .follow_newest = [this](bool on) { loading_.FollowNewest(on); },
             .load_image =
                 [this](std::filesystem::path* path) { return LoadSelectedImageFile(path); },
             .image_shown =
                 [this] {
                   if (state_.rig && state_.rig->Several())
                     worker_.Enqueue([this] { rig_.LoadFrames(); });
                 }}),
      brush_(Host(), {.job = [this] { return job_ ? &*job_ : nullptr; },
                      .edited =
                          [this] {
                            Publish();
                            session_.Edited();
                          },
                      .refit =
                          [this](int index) {
                            worker_.Enqueue([this, index] { loading_.Refit(index); });
                          }}),
      guidance_(Host(), {.job = [this] { return job_ ? &*job_ : nullptr; },
                         .judged = [this] { rig_.UpdateActiveCamera(); },
                         .publish = [this] { Publish(); },
                         .rejected =
                             [this] {
                               session_.Edited();
                               solve_.Request();
                             }}),
      solve_(
          Host(), guidance_,
          {.job = [this] { return job_ ? &*job_ : nullptr; },
           .publish = [this] { Publish(); },
           .edited = [this] { session_.Edited(); },
           .reproject =
               [this](int index) { worker_.Enqueue([this, index] { view_.Reproject(index); }); }}),
      loading_(
          Host(), guidance_,
          {.job = [this] { return job_ ? &*job_ : nullptr; },
           .publish = [this] { Publish(); },
           .settled =
               [this] {
                 session_.Edited();
                 solve_.Request();
               },
           .show_image = [this] { worker_.Enqueue([this] { view_.ShowImage(); }); },
           .reproject =
               [this](int index) { worker_.Enqueue([this, index] { view_.Reproject(index); }); },
           .keep_image =
               [this](const std::filesystem::path& path, std::shared_ptr<const ImageU8> image) {
                 KeepDecodedImage(path, std::move(image));
               }}),
      rig_(Host(), [this] { guidance_.Judge(/*record=*/false); }),
      check_(Host(), {.job = [this] { return job_ ? &*job_ : nullptr; },
                      .publish = [this] { Publish(); },
                      .adopted =
                          [this] {
                            rig_.UpdateActiveCamera();
                            const int selected = state_.selected;
                            if (selected >= 0)
                              worker_.Enqueue([this, selected] { view_.Reproject(selected); });
                          },
                      .edited = [this] { session_.Edited(); }}),
      intrinsics_(Host()),
      follow_(Host(), {.open =
                           [this](const Dataset& read) {
                             if (!ResumeGrownCapture(read))
                               OpenLoadedDataset(read, {}, ExistingSession::kResume);
                           },
                       .add =
                           [this](const PairEntry& pair) {
                             std::lock_guard lock(mutex_);
                             loading_.Add(pair);
                           }}) {}

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
      pair.lidar_failure = loading_.Settled() ? "finding the board ..."
                                              : "finding the board once every pair is loaded ...";
  }
  view_.Frame(/*forced=*/false);  // the selected pair's cloud loaded or its board found
  ++state_.generation;
}

void Controller::Review(const SetPairStatus& status) {
  if (!state_.HasPair(status.index)) return;
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
  session_.Edited();  // after the line: a failed autosave says so there
  solve_.Request();
}

void Controller::Apply(const Intent& intent) {
  std::lock_guard lock(mutex_);
  // A followed recording's board is picked before anything opens: its first pair needs it.
  if (!state_.dataset && !std::holds_alternative<PickBoard>(intent)) return;
  // A stroke is its dabs; anything else in between ends it.
  if (!std::holds_alternative<BrushStroke>(intent) && !std::holds_alternative<PaintPoints>(intent))
    brush_.EndStroke();
  // Each intent to the task that owns what it changes; accept/reject is the controller's own.
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
        else if constexpr (std::is_same_v<What, Undo> || std::is_same_v<What, Redo>) {
          const bool undo = std::is_same_v<What, Undo>;
          if (std::optional<Session> restored = session_.Step(undo))
            Restore(*restored, undo ? "undid" : "redid");
        } else if constexpr (std::is_same_v<What, SaveSessionAs>)
          session_.SaveAs(NextToSession(state_, what.path));
        else if constexpr (std::is_same_v<What, SelectPair>)
          view_.Select(what);
        else if constexpr (std::is_same_v<What, SetView>)
          view_.Set(what);
        else if constexpr (std::is_same_v<What, FrameView>) {
          view_.Frame(/*forced=*/true);
          view_.Record();
        } else if constexpr (std::is_same_v<What, RunSolver>)
          solve_.Run();
        else if constexpr (std::is_same_v<What, ResetSolver>)
          solve_.Reset();
        else if constexpr (std::is_same_v<What, SetSettings>)
          solve_.Set(what);
        else if constexpr (std::is_same_v<What, ExportResult>)
          solve_.Export(what);
        else if constexpr (std::is_same_v<What, SetGoal>)
          guidance_.Apply(what);
        else if constexpr (std::is_same_v<What, EstimateIntrinsics>)
          intrinsics_.Estimate(what);
        else if constexpr (std::is_same_v<What, SaveIntrinsics>)
          intrinsics_.Save(what);
        else if constexpr (std::is_same_v<What, RunCheck>)
          check_.Run(what);
        else if constexpr (std::is_same_v<What, AdoptCheckEstimate>)
          check_.Adopt();
        else if constexpr (std::is_same_v<What, PickBoard>)
          follow_.Pick(what);
        else if constexpr (std::is_same_v<What, SelectCamera>)
          rig_.Select(what);
        else if constexpr (std::is_same_v<What, SolveRig>) {
          if (state_.rig && state_.rig->Several())
            StartRigSolve();
          else
            SetStatus("not a rig: there is one camera", true);
        } else {
          static_assert(std::is_same_v<What, SetPairStatus>, "an intent nobody handles");
          Review(what);
        }
      },
      intent);
}

void Controller::StartRigSolve() {
  mutex_.AssertHeld(__func__);
  rig_.Start(job_ ? job_->record().Edits() : PairEdits{}, state_.settings.Over(pipeline_));
}

}  // namespace calibench::ui
