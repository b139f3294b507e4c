// The workbench's state and the only place that changes it. Panels read a Snapshot and return
// Intents; the controller applies them, runs the slow work (loading, plane fits, detection,
// solving, visibility; a rig's joint solve and a followed capture's looks as background steps) on
// its one worker thread, and autosaves the session after every edit.
// No GL, GLFW or ImGui here: the controller is driven by tests without a window.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/base/file_lock.h"
#include "core/capture/capture_feed.h"
#include "core/io/camera_file.h"
#include "core/io/rig_folder.h"
#include "core/lidar_camera/pipeline.h"
#include "core/lidar_camera/rig.h"
#include "core/results/export.h"
#include "core/session/calibration_job.h"  // the job, with the guidance and the session
#include "core/session/capture_follow.h"
#include "ui/lidar_camera/brush_task.h"
#include "ui/lidar_camera/check_task.h"
#include "ui/lidar_camera/controller_snapshot.h"  // Snapshot and the views it holds
#include "ui/lidar_camera/follow_task.h"
#include "ui/lidar_camera/guidance_task.h"
#include "ui/lidar_camera/intents.h"
#include "ui/lidar_camera/intrinsics_task.h"
#include "ui/lidar_camera/loading_task.h"
#include "ui/lidar_camera/rig_task.h"
#include "ui/lidar_camera/solve_task.h"
#include "ui/lidar_camera/view_task.h"
#include "ui/state/session_opening.h"
#include "ui/state/view_state.h"

namespace calibench::ui {

class Controller : public ControllerState<Snapshot> {
 public:
  // options: the pipeline's (as `calibench calibrate` takes them); a session's choices override
  // its solver settings.
  explicit Controller(PipelineOptions options = {});
  ~Controller();
  Controller(const Controller&) = delete;
  Controller& operator=(const Controller&) = delete;

  // Opens a dataset (new session saved next to it as <dataset folder>/calibench.session.json
  // unless session_path is given) or a saved session. The manifest / session is read here and
  // throws IoError; the pairs load on the worker thread (see loading_done / loading_total).
  // What to do when `session_path` already holds a session is `existing`'s (both workbenches'
  // ExistingSession, ui/state/session_opening.h): a session that does not load or belongs to
  // another dataset is backed up under kResume, after its newest autosave backup that does load
  // is resumed instead. A session file is locked (FileLock) while open: one that another
  // workbench has open throws IoError naming that process.
  // A rig (a rig folder or manifest) opens one camera: `camera`, else the first; its session is
  // calibench.session.<camera>.json beside the rig, and the rig's other cameras are solved in
  // background steps on the worker, below the edits' jobs (RigView), for the meter, the frustums
  // and the strip.
  void OpenDataset(const std::filesystem::path& dataset, std::filesystem::path session_path = {},
                   ExistingSession existing = ExistingSession::kReplace,
                   const std::string& camera = "");
  // Before opening another camera of the same rig: its cameras' solves as `rig` holds them (the
  // window's camera switch), so that they are not solved again.
  void CarryRig(const RigView& rig) { rig_.Carry(rig); }
  // The same for a dataset already read (a followed capture's, before it has pairs).
  void OpenLoadedDataset(const Dataset& dataset, std::filesystem::path session_path,
                         ExistingSession existing);
  // save = false: the session file is read, never locked or written (render).
  void OpenSession(const std::filesystem::path& session, bool save = true);

  void Apply(const Intent& intent);

  // Solves by itself once the pairs are detected and after every new or changed pair (the
  // window; tests and renders solve when asked). F5 / Run stays.
  void SetAutoSolve(bool on);
  // Follows a folder that a capture fills (the folder form: camera.yaml, target.json, clouds/,
  // images/; core/capture/folder_watch.h) in background steps on the worker, a look every 0.2 s:
  // waits for its camera and target, opens it (resuming the session beside it), then adds each pair
  // as it lands — loaded, detected and, with auto-solve, solved as the others. Pre-flight's
  // rejections apply to the pairs as `watch` applies them. Stops with StopWatching or the
  // controller.
  void WatchFolder(const std::filesystem::path& folder, FolderWatchOptions options = {});
  // The same for a recording being written (.bag, .mcap, .db3, a rosbag2 folder): its pairs
  // chosen as `import` and `watch` choose them (core/capture/recording_watch.h) and written to
  // `out` (the folder form), which opens once the first pair tells the camera and the board.
  void WatchRecording(const std::filesystem::path& recording, const std::filesystem::path& out,
                      std::optional<BoardSpec> board, BagImportOptions options);
  // Stops following; returns once no look runs. Not with mutex_ held (a look takes it).
  void StopWatching();
  // Waits for the rig solve's steps (tests, renders).
  void WaitRig() { rig_.Wait(); }

 private:
  // The session an earlier watch left, when its pairs are the first of `dataset`'s (a capture that
  // grew while the workbench was closed, a recording read again): opened over them, edits kept.
  bool ResumeGrownCapture(Dataset dataset);
  // The job's record of every pair into the view (PairRecord, whole), with the residuals at the
  // solution shown. Call with mutex_ held.
  void Publish();
  // The user's edits go to the job's record first (record-first, as the LRF workbench's): the job's
  // SetRejected, SetBrush and SetSettings, the record's Edit for the view and a reset solve;
  // what followed from them (statuses, completion, the solve) the job records beside them, and
  // the view shows the job's pairs (Publish); undo restores the view from the record
  // (ShowSession). Then session_.Edited(): the undo buttons, autosave, a new generation.
  // A session's view, settings and solve shown, its pairs as the job holds them (Open, undo,
  // redo); call with mutex_ held.
  void ShowSession(const Session& session);
  // The rig solve (RigTask::Start) over the open camera's edits and the settings. Mutex held.
  void StartRigSolve();
  // `note` (how the session came to be opened) joins the status line once the pairs have loaded.
  void Open(const Dataset& dataset, Session session, std::filesystem::path session_path,
            const std::string& note, std::optional<FileLock> lock);

  // SetPairStatus: the user's accept or reject into the job's record, then shown and solved again
  // (auto-solve); refused when the pair lacks a plane to accept. Mutex held.
  void Review(const SetPairStatus& status);
  // Undo / redo's session shown (`what`: "undid" / "redid", for the status line).
  void Restore(const Session& restored, const std::string& what);

  // The options the workbench was started with; the session's settings (state_.settings, the
  // record's) apply over them: JobSettings::Over.
  PipelineOptions pipeline_;
  // The pipeline job (core/session/calibration_job.h) over the opened dataset: detection with
  // the background, the solve, guidance, and the session's one record (the user's word, undo,
  // autosave), which state_ mirrors for the panels. Its steps run on the worker; its record is
  // edited under mutex_ (it locks itself too). Made anew by Open, after WaitIdle.
  std::optional<CalibrationJob> job_;
  // The open session's file, lock, autosave, undo and redo (both workbenches', session_opening.h).
  EditedSession<Snapshot> session_;
  ViewTask view_;  // what the views show of the selected pair
  // The tasks Apply routes intents to, each owning its own fields (TaskHost).
  BrushTask brush_;
  GuidanceTask guidance_;
  SolveTask solve_;
  LoadingTask loading_;
  RigTask rig_;
  CheckTask check_;
  IntrinsicsTask intrinsics_;
  FollowTask follow_;
};

}  // namespace calibench::ui
