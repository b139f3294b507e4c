// The one interface every method's calibration job offers its front ends (docs/architecture.md,
// "The calibration job"). A job holds a dataset's pairs and its session's one record (the user's
// word, with undo and autosave); a front end extracts the pairs, gives the user's word, solves
// and writes the result through it without knowing the method. Two methods implement it: the
// LiDAR-camera job (calibration_job.h, Ca²Lib's planes) and the 2D LRF job
// (lrf_calibration_job.h, the three-face target). Each keeps its own typed steps beside these (a
// workbench's step-by-step detection, guidance), which the interface does not need.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/base/parallel.h"
#include "core/base/types.h"
#include "core/results/pair_status.h"
#include "core/session/session_record.h"

namespace calibench {

enum class JobKind { kLidarCamera, kLrf };
// "LiDAR-camera", "2D LRF": as messages name them.
std::string JobKindName(JobKind kind);

// Which method's job a dataset and a session are for (either may be empty). A session says so
// itself (an LRF session carries options.lrf_method); otherwise the dataset does (an LRF manifest).
// A session that does not read as one is the LiDAR-camera job's, whose reader then names the
// problem.
JobKind JobKindOf(const std::filesystem::path& dataset, const std::filesystem::path& session);

// One pair as the last solve left it, in any method's words.
struct JobPair : PairStanding {
  bool input_error = false;  // its files could not be read (the reason names them)
};

// What a solve gave: enough for a front end to say it, write it and choose its exit code.
struct JobVerdict {
  bool solved = false;  // a calibration the data supports (a refused one is not)
  std::string failure;  // why not, when !solved
  // The camera from the range sensor: cam_from_lidar, or cam_from_lrf for a 2D LRF.
  Pose cam_from_source = Pose::Identity();
  Mat6 covariance = Mat6::Zero();  // right perturbation of cam_from_source, [rho (m); phi (rad)]
  bool well_constrained = false;
  std::vector<JobPair> pairs;        // every pair, as this solve left it
  std::string summary;               // the method's summary, as its command prints it
  std::optional<Pose> ground_truth;  // the dataset's cam_from_source, when it has one (simulated)

  bool input_error() const;  // some pair's files could not be read
  // "pair ID: reason" per unreadable pair, one per line, each line starting with "\n  " and
  // `camera` (a rig's camera: "camera NAME ").
  std::string Unreadable(const std::string& camera = "") const;
};

// A method's outcome in the interface's words: its solution's pose (`pose_of` reads it), covariance
// and observability, its pairs' statuses, its summary and the dataset's ground truth.
template <typename Outcome, typename PoseOf>
JobVerdict VerdictOf(const Outcome& outcome, PoseOf pose_of, std::string summary,
                     std::optional<Pose> ground_truth) {
  JobVerdict verdict;
  verdict.solved = outcome.solution.has_value();
  verdict.failure = outcome.failure;
  if (outcome.solution) {
    verdict.cam_from_source = pose_of(*outcome.solution);
    verdict.covariance = outcome.solution->covariance;
    verdict.well_constrained = outcome.solution->observability.well_constrained;
  }
  for (const auto& pair : outcome.pairs)
    verdict.pairs.push_back({{pair}, pair.input_error});  // its standing, sliced
  verdict.summary = std::move(summary);
  verdict.ground_truth = std::move(ground_truth);
  return verdict;
}

struct RigFolder;   // core/io/rig_folder.h
struct RigOutcome;  // core/lidar_camera/rig.h

// Each camera of a rig's calibration in the interface's words (one camera's dataset is a rig of
// one, RigOfOne), so that a rig is said as one camera's solve is: solved when the rig solve gave
// a pose (joint), that pose and its covariance (the joint's block), well constrained as the
// camera's own solve's observability says, its pairs, its ground truth; `failure` the rig's when
// unsolved, `summary` empty. In the rig's camera order.
std::vector<JobVerdict> CameraVerdicts(const RigFolder& rig, const RigOutcome& outcome);

class Job {
 public:
  virtual ~Job() = default;

  virtual JobKind kind() const = 0;
  // The dataset's manifest (or folder), as messages name it.
  virtual std::filesystem::path manifest() const = 0;
  // Pairs known so far (the selected ones).
  virtual int size() const = 0;

  // Every pair's features at once, on the job's workers; `progress` after each pair.
  virtual void ExtractAll(const ProgressCallback& progress = {}) = 0;
  // The user's word on pair `pair_id`: rejected (with the reason shown for it; empty: "rejected
  // by the user") or taken back. One undo step in the record; it applies at the next solve.
  virtual void SetRejected(const std::string& pair_id, bool rejected,
                           const std::string& reason = "") = 0;
  // Solves from the extracted pairs with the record's word: the method's own Solve, told in the
  // interface's words.
  virtual JobVerdict Calibrate() = 0;
  // The last solve's result file (calibench.result.v1), written atomically. Requires a solve that
  // gave a calibration; IoError naming the file when it cannot be written.
  virtual void WriteResultFile(const std::filesystem::path& path) const = 0;

  // The session's one record: the user's word, the settings, undo and autosave (any thread).
  virtual SessionRecord& record() = 0;
  virtual const SessionRecord& record() const = 0;
};

}  // namespace calibench
