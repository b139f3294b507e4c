// The 2D LRF workbench's state and the only place that changes it (the LRF counterpart of
// ui/lidar_camera/controller.h). Panels read an LrfSnapshot and return LrfIntents; the controller
// applies them and runs the LRF job (core/session/lrf_calibration_job.h, what `lrf-calibrate`
// runs: extraction and the solve) on a worker thread. The job's record is the session: the user's
// rejections, the method, the selected pair and the last solve, with undo and an autosave beside
// the manifest (calibench.lrf-session.json), resumed when the manifest opens again.
// No GL, GLFW or ImGui here: the controller is driven by tests without a window.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "core/base/file_lock.h"
#include "core/base/image.h"
#include "core/lrf/pipeline.h"
#include "core/session/lrf_calibration_job.h"
#include "ui/state/controller_state.h"
#include "ui/state/session_opening.h"
#include "ui/state/shared_pairs.h"

namespace calibench::ui {

// Everything the panels show about one pair. The features are a shared, immutable buffer.
struct LrfPairView : PairHeader {
  bool extracted = false;
  std::shared_ptr<const LrfPairFeatures> features;
  // At the solver's estimate (after a solve): Eq. (12) mean corner-to-line distance (three-face
  // only) and the RMS point-to-plane distance of the pair's face / board scan points. Metres.
  std::optional<double> point_to_line_m;
  std::optional<double> point_to_plane_rms_m;
};

struct LrfSolverView {
  LrfMethod method = LrfMethod::kRefined;
  bool running = false;
  // Gauss-Newton iterations of the refined method (cost and cam_from_lrf in cam_from_lidar);
  // empty for paper-linear, which is closed form.
  std::vector<IterationReport> iterations;
  std::optional<LrfSolution> solution;  // ok solutions only; failures go to `failure`
  std::vector<std::string> solved_pair_ids;
  Vec3 std_translation_mm = Vec3::Zero();  // camera axes
  Vec3 std_rotation_deg = Vec3::Zero();    // camera axes
  std::string failure;
};

struct LrfSnapshot : SnapshotHeader {
  std::filesystem::path manifest;
  std::shared_ptr<const LrfDataset> dataset;  // null until a manifest opened
  SharedPairs<LrfPairView> pairs;  // one list the snapshots share (ui/state/shared_pairs.h)
  int selected = -1;
  std::shared_ptr<const ImageU8> selected_image;  // checkerboard case: the RGB image of `selected`
  LrfSolverView solver;
  int extracted_done = 0, extracted_total = 0;
  std::filesystem::path session_path;  // where the session autosaves; empty: nowhere
  bool can_undo = false, can_redo = false;
  std::string save_error;    // the last autosave's failure; empty when it saved
  std::string session_note;  // what opening did with the session there (resumed, moved aside)
};

struct LrfSelectPair {
  int index;
};
struct LrfSetPairStatus {
  int index;
  PairStatus status;  // kAccepted or kRejected
};
struct LrfRunSolver {};
struct LrfResetSolver {};
struct LrfSetMethod {
  LrfMethod method;
};
struct LrfExportResult {
  std::filesystem::path path;  // a relative path is taken from the manifest's folder
};
// Takes back the last rejection or method change (Ctrl+Z); Redo (Ctrl+Y) makes it again.
struct LrfUndo {};
struct LrfRedo {};
using LrfIntent = std::variant<LrfSelectPair, LrfSetPairStatus, LrfRunSolver, LrfResetSolver,
                               LrfSetMethod, LrfExportResult, LrfUndo, LrfRedo>;

// Appends an intent constructed in place (a moved temporary variant trips GCC 12's
// -Wmaybe-uninitialized).
template <typename T, typename... Args>
void EmitLrfIntent(std::vector<LrfIntent>* intents, Args&&... args) {
  intents->emplace_back(std::in_place_type<T>, T{std::forward<Args>(args)...});
}

class LrfController : public ControllerState<LrfSnapshot> {
 public:
  explicit LrfController(LrfPipelineOptions options = {});
  ~LrfController();
  LrfController(const LrfController&) = delete;
  LrfController& operator=(const LrfController&) = delete;

  // Loads the manifest, opens the session beside it (DefaultLrfSessionPath) as `existing` says
  // (both workbenches' ExistingSession, ui/state/session_opening.h), and queues feature
  // extraction of every pair. A session that does not open gives way to its newest backup that
  // opens, else is moved aside and a new one starts (ResumeSessionBeside; session_note says which).
  // A manifest that cannot be read, or a session open in another workbench, leaves the open dataset
  // as it was and shows the error in the status line (false).
  bool Open(const std::filesystem::path& manifest,
            ExistingSession existing = ExistingSession::kResume);
  // Opens a saved LRF session (calibench.session.v1 with options.lrf_method) with the manifest it
  // names, and autosaves to it from then on; false with the error shown, as Open.
  bool OpenSession(const std::filesystem::path& session_path);
  void Apply(const LrfIntent& intent);

 private:
  void OnJobError() override;
  // Starts on `dataset` with the record `saved` (nullopt: a new session), autosaving to
  // `session_path` under `lock`; `note` (what was done with the session) opens the status
  // line and is the snapshot's session_note.
  void Start(std::shared_ptr<const LrfDataset> dataset, std::optional<Session> saved,
             const std::filesystem::path& session_path, std::optional<FileLock> lock,
             const std::string& note);
  bool Fail(const std::string& message);  // the status line says it; false
  // Pair `index` extracted by `job` (worker; the job of the Open that queued it).
  void Extract(LrfCalibrationJob* job, std::uint64_t open_count, int index);
  void Solve();
  void LoadSelectedImage();
  void UpdatePairFigures();  // call with mutex_ held
  // Every row's status from the one rule: rejected (with its reason) where the job's record says
  // so, else accepted when extraction gave what the solver needs, failed with the reason when
  // not, pending before (mutex_ held). The rows never keep a status of
  // their own: an undo, an edit and an extraction all come here.
  void Restatus();
  bool ValidPair(int index) const;
  // One handler per intent type, as the lidar-camera controller has (Apply visits them with
  // mutex_ held and a dataset open).
  void Handle(const LrfSelectPair& intent);
  void Handle(const LrfSetPairStatus& intent);
  void Handle(const LrfRunSolver& intent);
  void Handle(const LrfResetSolver& intent);
  void Handle(const LrfSetMethod& intent);
  void Handle(const LrfExportResult& intent);
  void Handle(const LrfUndo& intent);
  void Handle(const LrfRedo& intent);
  // Undo / redo's session shown (`what`: "undid" / "redid").
  void Restore(const Session& restored, const char* what);

  LrfPipelineOptions options_;
  // The pipeline job over the open dataset (core/session/lrf_calibration_job.h), as
  // `lrf-calibrate` runs it: extraction and the solve, driven by the worker only; its record is
  // edited here too (it locks itself). Replaced by Open (mutex_ for the pointer).
  std::shared_ptr<LrfCalibrationJob> job_;
  // The open session's file, lock, autosave, undo and redo (both workbenches', session_opening.h).
  EditedSession<LrfSnapshot> session_;
  std::shared_ptr<const LrfCalibrationOutcome> outcome_;  // of the shown solution, for export
  std::uint64_t open_count_ = 0;  // a job of an earlier Open() discards its result
};

}  // namespace calibench::ui
