// One calibration session's pipeline job: what `calibrate`, `advise`, `watch` and the workbench
// all run (the model: COLMAP's controllers/, one job object the CLI and the GUI both drive).
// The job owns the pairs — each as detection found it and the user's word on it (a painted brush,
// a rejection) — the scene's background model, the solve and the guidance after it, and runs the
// pipeline's steps (core/lidar_camera/pipeline.h, core/guidance/advise.h) in the one order they
// need: detect (with the background), solve from what detection found (camera-guided completion
// within), then pre-flight, the meter and the next pose. Front ends differ only in how pairs
// arrive: all at once (DetectAll: `calibrate`, `advise`), one at a time as a capture grows
// (AddPair: `watch`), or step by step from files a window already decoded for its views
// (ReadPair / AddToBackground / DetectLidar: the workbench). Progress and each solver
// iteration are reported as events.
// The user's word lives in one place, the job's SessionRecord (session_record.h): the session as
// its file keeps it, with undo and autosave. The job reads it at every detection and solve; a
// front end may edit it from any thread (it locks). Everything else in the job is driven by one
// thread.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/guidance/advise.h"
#include "core/session/job.h"
#include "core/session/pair_record.h"
#include "core/session/session.h"
#include "core/session/session_record.h"
#include "core/target/scene_background.h"

namespace calibench {

struct CalibrationJobOptions {
  AdviseOptions advise;  // goal, stop rule, guidance, pre-flight and the pipeline's options
  // The background model holds one range per angular cell and cloud: the first this many clouds
  // make it (the static scene does not change after that), bounding memory on long captures.
  int max_background_clouds = 40;
  // Each solve starts from the last solution (a capture that grows: the same minimum, fewer
  // iterations) instead of the closed form `calibrate` starts from.
  bool warm_start = false;
  // The camera's intrinsics as estimated from the pairs' images before the calibration
  // (`calibrate --estimate-intrinsics`): each outcome carries them, for the result file to say so.
  std::optional<IntrinsicsResult> estimated_intrinsics;
  bool Check(std::string* why) const;
};

// What a job reports while it works; each is optional and called on the driving thread.
struct JobEvents {
  ProgressCallback detected;    // a pair's features are in (DetectAll, AddPair)
  IterationCallback iteration;  // every solver iteration, as it happens
};

class CalibrationJob final : public Job {
 public:
  // `dataset`: the camera, the target and the pairs known so far (options.advise.pipeline.pair_ids
  // selects among them), none detected yet. `edits`: the user's brushes and rejections by pair id
  // (a session's, EditsFromSession). The record starts as a new session over those pairs with
  // the options' solver settings and these edits.
  CalibrationJob(Dataset dataset, CalibrationJobOptions options, PairEdits edits = {},
                 JobEvents events = {});

  // Every pair known so far at once, as `calibrate` extracts them (ExtractDatasetPairs).
  void DetectAll();
  // One new pair (its id must be new), read and detected now with the background so far: a
  // growing capture. With `cached` (its features from an earlier run, core/session/feature_cache.h)
  // nothing is detected; only its cloud is read, for the background model. Never throws for bad
  // data: the pair fails with the reason.
  const PairFeatures& AddPair(const PairEntry& entry, const PairFeatures* cached = nullptr);

  // Step by step, for a front end that decodes the files itself (the workbench keeps them for its
  // views). AppendPair adds a pair not yet detected; its index is returned.
  int AppendPair(const PairEntry& entry);
  // Reads pair `index`'s files and finds the board in its image (the camera side, in *camera);
  // the decoded files come back for the caller's views. nullopt with *why (naming the file) when
  // they cannot be read: the pair then fails with that reason.
  std::optional<PairInputs> ReadPair(int index, CameraFeatures* camera, std::string* why);
  // Pair `index`'s cloud joins the background model (until max_background_clouds). True when the
  // model has just become usable: boards detected before it are worth detecting again.
  bool AddToBackground(int index, const LidarCloud& cloud);
  // Pair `index`'s LiDAR board from `cloud`: its brush (the edit), else the manifest's seed unless
  // `use_seed` is false (the workbench's "detect again"), else detection with the background
  // (BoardHintFor). `image` is the cloud's LiDAR image (ProjectById), needed for a brush.
  const PairFeatures& DetectLidar(int index, const LidarCloud& cloud, const LidarImage* image,
                                  bool use_seed = true);

  // Pair `index` is pictured on `image` (its cloud's ProjectById, kept for the views): its seed's
  // region and its detected board are drawn there (PairRecord::brush_pixels), the seed's into the
  // record as the session file keeps it. A brush the record holds that was painted on another
  // image layout would mark other returns: it is forgotten (no undo step) and the returned text
  // says why; empty otherwise.
  std::string PictureOn(int index, const LidarCloud& cloud,
                        std::shared_ptr<const LidarImage> image);

  // The user's word, each an undo step in the record. A brush applies at the pair's next
  // detection; a rejection (with the reason shown for it) at the next solve. A brush's pixels
  // (an empty list: erased, the pair then has no board until painted again) replace the seed and
  // any detection; nullopt forgets the brush (detection again). `amend`: the same undo step as
  // the last edit (a stroke's later dabs, "detect again" over every pair).
  void SetBrush(const std::string& pair_id, std::optional<PairEdit> brush, bool amend = false);
  void SetRejected(const std::string& pair_id, bool rejected,
                   const std::string& reason = "") override;
  // A saved session (the workbench's, an earlier watch's) becomes the record: its brushes,
  // rejections (with their reasons) and solver settings, by pair id (pairs that have not arrived
  // yet take theirs when they do), and what its views showed, carried into ToSession. Call before
  // detection.
  void Resume(const Session& session);
  // Whether the user painted pair `pair_id`'s board: its features must come from the brush, not
  // from a detection cached without it.
  bool HasBrush(const std::string& pair_id) const;
  // The settings the next steps run with, into the record as one undo step.
  void SetSettings(const JobSettings& settings);
  void SetGoal(const CaptureGoal& goal);
  // How precisely the person holds a suggested pose (GuidanceOptions::hand_tolerance_*).
  void SetHandTolerance(double translation_m, double rotation_deg);

  // Solves every detected pair from what detection found, with the user's decisions: the steps
  // `calibrate` runs after extraction (SolveExtractedPairs: solve, camera-guided completion, the
  // intrinsics). The outcome's pairs carry completion's boards and verdicts.
  const CalibrationOutcome& Solve();
  // What the last Solve found, into the record beside the edits it answers, as the session file
  // keeps them: each pair's status and reason (completion's boards, its verdicts) and the
  // solution with its convergence and the summary's notes; an undo step of its own with
  // `own_step` (a Run), else the same step as the edit it followed from (an auto-solve: one undo
  // takes back the edit and its solve). Unless the user's word changed while the solve ran (a
  // front end undid or edited from its own thread: the record locks itself, the solve reads it
  // once at its start): that outcome answers edits or settings that no longer stand. It is then
  // dropped, with its guidance, and false returned; the caller shows the record as it stands (an
  // undo's restored solve) or solves again. An edit undone and redone meanwhile is the same
  // word: that outcome stands.
  bool CommitOutcome(bool own_step);
  // `solution` (not a board solve: the targetless check's estimate) becomes the record's result
  // with `provenance` and `notes`, as one undo step.
  void AdoptSolution(const SolverResult& solution, const std::string& provenance,
                     const std::vector<std::string>& notes);
  // Following a capture, pre-flight's rejections after the last Advise apply (as `watch` applies
  // them), on the same undo step as the edit that led to them; true when a pair was rejected.
  bool ApplyPreflightRejections();
  // Pre-flight, the meter and the next pose (AdviseCapture) after the last solve; with `at`, at
  // that solution instead (a reopened session's).
  const CaptureAdvice& Advise(const std::optional<SolverResult>& at = std::nullopt);

  const Dataset& dataset() const { return dataset_; }
  // The pairs as detection found them (status from their planes and the user's rejections).
  std::vector<PairFeatures> DetectedPairs() const;
  // Every pair as the job holds it now (PairRecord: the record's status, reason and brush, the
  // fits with completion's boards, pre-flight's findings), with the residuals and robust weights
  // at `shown` (the solution a front end shows: the last solve, an undo step's, an adopted
  // estimate; `solved_ids` the pairs it was solved with, empty when unknown) for the pairs that
  // solve with it now. Any thread.
  std::vector<PairRecord> Records(const SolverResult* shown = nullptr,
                                  const std::vector<std::string>& solved_ids = {}) const;
  // The pairs as they stand with `shown` as the solution: its own residuals while its pairs are
  // still those accepted, else the solver's at its estimate over the pairs accepted now (what
  // export writes and guidance judges). Any thread.
  CalibrationOutcome OutcomeAt(const SolverResult& shown,
                               const std::vector<std::string>& solved_ids) const;
  const std::optional<CalibrationOutcome>& outcome() const { return outcome_; }
  const std::optional<CaptureAdvice>& advice() const { return advice_; }
  // The job's options with the record's solver and RANSAC settings: what the next step runs with.
  CalibrationJobOptions options() const;
  bool background_usable() const { return background_.has_value(); }
  int background_clouds() const { return background_accumulator_.clouds(); }
  // Why no background model is used (yet): fewer than 3 clouds, or the scene does not repeat.
  const std::string& background_note() const { return background_note_; }

  // The job as a workbench session over `dataset_path`: each pair's status and reason as the last
  // solve and guidance left them, the user's brushes, the solver settings, the last solution and
  // the views a resumed session showed. `calibrate --session`, `watch` and `gui --session` reopen
  // it: one state, whichever front end wrote it last.
  Session ToSession(const std::filesystem::path& dataset_path) const;

  // Job: what any front end asks of a job, whatever its method.
  JobKind kind() const override { return JobKind::kLidarCamera; }
  std::filesystem::path manifest() const override { return dataset_.manifest; }
  int size() const override { return static_cast<int>(dataset_.pairs.size()); }
  // DetectAll, with `progress` (when given) in place of the events' `detected` for this call.
  void ExtractAll(const ProgressCallback& progress = {}) override;
  JobVerdict Calibrate() override;  // Solve, in the interface's words
  // WriteResult of the last solve with the solver settings it ran with (cam_from_lidar).
  void WriteResultFile(const std::filesystem::path& path) const override;
  SessionRecord& record() override { return record_; }
  const SessionRecord& record() const override { return record_; }

 private:
  struct JobPair {
    PairFeatures detected;  // planes as detection found them, status from them
    // Completion's board and verdict where the last committed solve ran on this detection.
    std::optional<PairFeatures> completed;
    std::string lidar_failure = "not detected yet";
    std::string camera_failure = "not detected yet";
    bool lidar_tried = false;  // its LiDAR side was looked at (or its files failed to read)
    int detections = 0;        // counts its LiDAR detections: completion's applies to one
    std::optional<BoardDetection> detection;  // the board's corners in the image
    std::shared_ptr<const LidarImage> image;  // PictureOn's
    const PairFeatures& Now() const { return completed ? *completed : detected; }
  };
  void Restatus(JobPair* pair) const;  // status and reason from the planes and the rejection
  PairEdit EditOf(const std::string& pair_id) const;
  // `edit` into pair `pair_id`'s state (added when the session has no such pair yet); that state.
  static PairState& SetEdit(Session* session, const std::string& pair_id, const PairEdit& edit);
  PipelineOptions Pipeline() const;  // options_'s with the record's settings
  // The pairs as detection found them, with `record`'s rejections (pairs_mutex_ held).
  std::vector<PairFeatures> DetectedPairs(const Session& record) const;
  // The pairs as they stand, an accepted one without both planes failed (pairs_mutex_ held).
  std::vector<PairFeatures> PairsNow(const Session& record) const;
  CalibrationOutcome OutcomeAt(const Session& record, const SolverResult& shown,
                               const std::vector<std::string>& solved_ids) const;  // lock held
  // Every pair's status and reason as its steps left them into the record (a rejection stands),
  // on the current undo step.
  void RecordStatuses();
  const SceneBackground* Background() const { return background_ ? &*background_ : nullptr; }

  Dataset dataset_;
  CalibrationJobOptions options_;
  SessionRecord record_;  // a copied job's record has no autosave file (SessionRecord's copy)
  JobEvents events_;
  // A mutex a copied job has its own of (a job is copied on its driving thread, to try a step).
  struct OwnMutex : std::mutex {
    OwnMutex() = default;
    OwnMutex(const OwnMutex&) : std::mutex() {}
  };
  // The pairs, written on the driving thread and read from any (Records): under pairs_mutex_,
  // never held while the record is called.
  mutable OwnMutex pairs_mutex_;
  std::vector<JobPair> pairs_;
  SceneBackground background_accumulator_;
  std::set<int> in_background_;
  std::optional<SceneBackground> background_;  // finished, when usable
  // A moving capture's frames, each posed once for every pair that lists it (thread-safe).
  FrameBoards frames_;
  std::string background_note_ = "fewer than 3 clouds so far";
  std::optional<CalibrationOutcome> outcome_;
  std::optional<SolverResult> last_solution_;
  SolverOptions solved_with_;  // the solver settings of outcome_'s solve (the record's)
  // The record's edits and settings outcome_'s solve read (CommitOutcome).
  PairEdits solved_edits_;
  JobSettings solved_settings_;
  std::vector<int> solved_detections_;       // each pair's JobPair::detections at that solve
  std::vector<IterationReport> iterations_;  // that solve's, as its events reported them
  std::optional<CaptureAdvice> advice_;
};

}  // namespace calibench
