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
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/guidance/advise.h"
#include "core/session/job.h"
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
  // The user's word changed while the last Solve ran (a front end undid or edited from its own
  // thread: the record locks itself, the solve reads it once at its start): that outcome answers
  // edits or settings that no longer stand. It is then dropped, with its guidance, and true
  // returned; the caller shows the record as it stands (an undo's restored solve) or solves
  // again. False, keeping the outcome, when the record's edits and settings are still those the
  // solve ran with (an edit undone and redone meanwhile is the same word).
  bool DiscardStaleOutcome();
  // Pre-flight, the meter and the next pose (AdviseCapture) after the last solve; with `at`, at
  // that solution instead (a reopened session's).
  const CaptureAdvice& Advise(const std::optional<SolverResult>& at = std::nullopt);

  const Dataset& dataset() const { return dataset_; }
  // The pairs as detection found them (status from their planes and the user's rejections).
  std::vector<PairFeatures> DetectedPairs() const;
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
    std::string lidar_failure = "not detected yet";
    std::string camera_failure = "not detected yet";
  };
  void Restatus(JobPair* pair) const;  // status and reason from the planes and the rejection
  PairEdit EditOf(const std::string& pair_id) const;
  // `edit` into pair `pair_id`'s state (added when the session has no such pair yet); that state.
  static PairState& SetEdit(Session* session, const std::string& pair_id, const PairEdit& edit);
  PipelineOptions Pipeline() const;  // options_'s with the record's settings
  // The pairs as detection found them, with `record`'s rejections.
  std::vector<PairFeatures> DetectedPairs(const Session& record) const;
  const SceneBackground* Background() const { return background_ ? &*background_ : nullptr; }

  Dataset dataset_;
  CalibrationJobOptions options_;
  SessionRecord record_;  // a copied job's record has no autosave file (SessionRecord's copy)
  JobEvents events_;
  std::vector<JobPair> pairs_;
  SceneBackground background_accumulator_;
  std::set<int> in_background_;
  std::optional<SceneBackground> background_;  // finished, when usable
  std::string background_note_ = "fewer than 3 clouds so far";
  std::optional<CalibrationOutcome> outcome_;
  std::optional<SolverResult> last_solution_;
  SolverOptions solved_with_;  // the solver settings of outcome_'s solve (the record's)
  // The record's edits and settings outcome_'s solve read (DiscardStaleOutcome).
  PairEdits solved_edits_;
  JobSettings solved_settings_;
  std::optional<CaptureAdvice> advice_;
};

}  // namespace calibench
