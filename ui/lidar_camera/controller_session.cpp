// The controller's session lifecycle: opening a dataset or a session (its file, lock, backup and
// resume are EditedSession's, ui/state/session_opening.h), the session shown in the view state,
// the view recorded, save-as, and what undo and redo restored shown.
#include <algorithm>
#include <cmath>

#include "core/base/allocator.h"
#include "core/base/atomic_file.h"
#include "core/io/cloud_io.h"
#include "core/io/image_io.h"
#include "core/io/rig_folder.h"
#include "core/lidar_camera/result_io.h"
#include "ui/lidar_camera/controller.h"

namespace calibench::ui {

void Controller::OpenDataset(const std::filesystem::path& dataset_path,
                             std::filesystem::path session_path, ExistingSession existing,
                             const std::string& camera) {
  if (IsRig(dataset_path)) {
    const RigFolder rig = LoadRig(dataset_path);
    const size_t index = camera.empty() ? 0 : RigCameraIndex(rig, camera);
    OpenLoadedDataset(rig.cameras[index], std::move(session_path), existing);
    return;
  }
  if (!camera.empty())
    throw IoError(dataset_path.string() +
                  ": not a rig (a folder with cameras/, or a manifest "
                  "with \"cameras\"), so it has no camera '" +
                  camera + "'");
  // A folder without target.json opens too (a drive to check without a board); Open says so.
  OpenLoadedDataset(LoadDataset(dataset_path, CameraFile::kRequired, TargetFile::kOptional),
                    std::move(session_path), existing);
}

namespace {

// What Open reads beyond the session and its dataset, before anything changes: the view (the
// workbench's to read, core keeps it as text: a malformed one is `source`'s error) and, for a
// rig's camera, the rig and the camera's index in it. Throws IoError naming the file.
std::pair<RigFolder, size_t> ReadViewAndRig(const Session& session, const Dataset& dataset,
                                            const std::filesystem::path& source) {
  std::vector<std::string> ids;
  for (const PairState& pair : session.pairs) ids.push_back(pair.id);
  ViewFromJson(session.view_json, source, ids);
  if (dataset.camera_name.empty()) return {RigOfOne(dataset), 0};
  RigFolder rig = LoadRig(dataset.manifest);
  const size_t camera = RigCameraIndex(rig, dataset.camera_name);
  return {std::move(rig), camera};
}

}  // namespace

void Controller::OpenLoadedDataset(const Dataset& dataset, std::filesystem::path session_path,
                                   ExistingSession existing) {
  Session session = NewSession(dataset);
  session.dataset = dataset.manifest;
  // A new session starts with the settings the workbench was started with (a resumed one keeps
  // its own).
  session.settings = JobSettings::Of(pipeline_);
  if (session_path.empty())
    session_path = DefaultSessionPath(dataset.manifest, dataset.camera_name);
  std::optional<SessionWithDataset> resumed;
  OpenedSessionFile file =
      session_.OpenBeside(session_path, existing, [&](const std::filesystem::path& candidate) {
        resumed = LoadSessionWithDataset(candidate);
        // As Open will read them: it opens.
        ReadViewAndRig(resumed->session, resumed->dataset, candidate);
      });
  if (file.resumed) {
    Open(resumed->dataset, std::move(resumed->session), file.path, file.note, std::move(file.lock));
    return;
  }
  Open(dataset, std::move(session), file.path, file.note, std::move(file.lock));
}

void Controller::OpenSession(const std::filesystem::path& session_path, bool save) {
  if (!save) {
    auto [session, dataset] = LoadSessionWithDataset(session_path);
    Open(dataset, std::move(session), {}, "", std::nullopt);
    return;
  }
  std::string note;
  std::optional<FileLock> lock = session_.Lock(session_path, &note);
  auto [session, dataset] = LoadSessionWithDataset(session_path);
  Open(dataset, std::move(session), session_path, note, std::move(lock));
}

void Controller::Open(const Dataset& dataset, Session session, std::filesystem::path session_path,
                      const std::string& note, std::optional<FileLock> session_lock) {
  const auto [rig, rig_camera] =
      ReadViewAndRig(session, dataset, session_path.empty() ? dataset.manifest : session_path);
  // The last dataset's work first: a rig solve of it is dropped (a new one starts below), its
  // queued jobs run out. From a followed capture's look (on the worker) nothing else is queued.
  rig_.Cancel();
  WaitIdle();
  {
    std::lock_guard lock(mutex_);
    // What the window set up outlives the dataset: auto-solve, the capture followed.
    Snapshot opened;
    opened.auto_solve = state_.auto_solve;
    opened.watching = state_.watching;
    state_ = std::move(opened);
    state_.dataset = dataset;
    state_.dataset_path = dataset.manifest;
    std::vector<PairView> pairs(dataset.pairs.size());
    for (size_t i = 0; i < dataset.pairs.size(); ++i) pairs[i].id = dataset.pairs[i].id;
    state_.pairs = SharedPairs<PairView>(std::move(pairs));
    // The pipeline job over the dataset's pairs as they load (LoadPair appends them), with the
    // session's options and the session as its record; every solver iteration shows as it
    // happens.
    CalibrationJobOptions job_options;
    job_options.advise.pipeline = session.settings.Over(pipeline_);
    job_options.advise.pipeline.pair_ids.clear();  // the workbench shows every pair
    Dataset setup = dataset;  // followed captures' pairs join as they load (LoadPair)
    JobEvents events;
    events.iteration = [this](const IterationReport& it) {
      std::lock_guard lock(mutex_);
      if (!state_.solver.running) return;  // an undo restored another solve meanwhile
      state_.solver.iterations.push_back(it);
      ++state_.generation;
    };
    job_.emplace(std::move(setup), job_options, PairEdits{}, std::move(events));
    job_->Resume(session);
    session_.Attach(&job_->record(), session_path, std::move(session_lock));
    ShowSession(session);
    if (!rig_.SetUp(rig, rig_camera)) StartRigSolve();
    loading_.Start(note);
  }
}

void Controller::ShowSession(const Session& session) {
  mutex_.AssertHeld(__func__);
  std::vector<std::string> ids;
  for (const PairState& pair : session.pairs) ids.push_back(pair.id);
  try {
    state_.view = ViewFromJson(session.view_json, state_.session_path, ids);
  } catch (const IoError&) {  // Open checked it; undo restores views this controller wrote
    state_.view = ViewState{};
  }
  state_.settings = session.settings;
  state_.selected = -1;
  for (size_t i = 0; i < state_.pairs.size(); ++i)
    if (state_.pairs.at(i).id == state_.view.selected_pair) state_.selected = static_cast<int>(i);
  if (state_.selected < 0 && !state_.pairs.empty()) state_.selected = 0;
  view_.Restored();
  state_.solver = SolverView{};
  if (session.result) {
    state_.solver.result = SolverResultFromSession(*session.result, session.settings.method);
    state_.solver.notes = session.result->notes;
    state_.solver.targetless_provenance = session.result->targetless_provenance;
    // The recorded convergence, so that the solver panel and the replay look as they did.
    const auto& costs = session.result->cost_history;
    const auto& steps = session.result->step_history;
    const auto& estimates = session.result->estimate_history;
    if (steps.size() == costs.size() && estimates.size() == costs.size())
      for (size_t i = 0; i < costs.size(); ++i)
        state_.solver.iterations.push_back({static_cast<int>(i), costs[i], steps[i], estimates[i]});
    for (int k : session.result->reweighted_iterations)
      if (k >= 0 && k < static_cast<int>(state_.solver.iterations.size()))
        state_.solver.iterations[k].reweighted = true;
  }
  Publish();  // the pairs as the job holds them, with residuals at that solve
}

// The record has restored it already, with the pairs that joined since that step as they are.
void Controller::Restore(const Session& restored, const std::string& what) {
  std::vector<std::vector<int>> before;
  for (const PairView& p : state_.pairs) before.push_back(p.brush_pixels);
  ShowSession(restored);
  // The meter and the next pose belong to the solve restored (or to none): judged again, asked
  // again (not while following a capture, where Advise's pre-flight would edit the record).
  guidance_.Judge(/*record=*/false);
  // The line no longer speaks of the solve undone ("solved with 39 pairs" over 40 accepted).
  int accepted = 0;
  for (const PairView& pair : state_.pairs) accepted += pair.SolvesWith();
  SetStatus(what + " the last change: " + std::to_string(accepted) + " pairs usable, " +
                (state_.solver.result ? "the calibration of that step shown"
                                      : "no calibration at that step"),
            false);
  state_.next_pose.reset();
  if (state_.solver.result && state_.watching.empty())
    worker_.Enqueue([this] { guidance_.AdviseFromState(); });
  session_.Autosave();
  for (int i = 0; i < static_cast<int>(state_.pairs.size()); ++i)
    if (state_.pairs.at(i).brush_pixels != before[i])
      worker_.Enqueue([this, i] { loading_.Refit(i); });
}

}  // namespace calibench::ui
