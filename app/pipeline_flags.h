// Flags shared by the subcommands that run the pipeline, bound to core::PipelineOptions.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "core/geometry/geometry.h"
#include "core/lidar_camera/pipeline.h"
#include "core/session/session.h"

namespace calibench {
struct AdviseOptions;
class Job;
struct JobVerdict;
}  // namespace calibench

namespace calibench::app {

struct PipelineFlags {
  // The pipeline's options; the settings' flags (JobSettingFields) are bound to `settings` and
  // applied over them by FinalizePipelineFlags.
  PipelineOptions options;
  JobSettings settings;
  std::string pairs;          // comma-separated pair ids
  std::string initial_guess;  // result.json, or 16 numbers (row-major 4x4)
  std::string method = "weighted-ml";
  double range_offset_prior_mm = 0.0;  // SolverOptions::range_offset_prior_sigma_m, in mm
  std::string lidar_model;             // PipelineOptions::lidar_model; "" = from the clouds
  std::string refine_intrinsics;       // --refine-intrinsics[=focal|pinhole|all]; "" = off
};

// with_selection adds --pairs and --initial-guess (not wanted where pairs are simulated).
void AddPipelineFlags(CLI::App& app, PipelineFlags& flags, bool with_selection = true);

// --goal-mm, --goal-deg, --hand-tolerance-m and --hand-tolerance-deg of `advise` and `watch`.
void AddGoalFlags(CLI::App& app, AdviseOptions* options);

// Applies the string flags; false with *why when they are malformed or the options fail Check.
bool FinalizePipelineFlags(PipelineFlags& flags, std::string* why);

// --session of `calibrate` and `report`: the workbench session's solver choices applied to
// *options, its dataset into *dataset_path (unless one was given), and its brushes and
// rejections as the pipeline's edits; nothing when session_path is empty. Throws IoError.
PairEdits ApplySessionFlag(const std::string& session_path, std::string* dataset_path,
                           PipelineOptions* options);

// Prints "[k/n] pair ID" progress to stderr (one line per pair when stderr is not a terminal).
ProgressCallback StderrProgress(const std::string& verb);

// "error against ground truth" and the σ the result reports beside it.
void PrintErrorAgainstTruth(const PoseError& error, const Mat6& covariance,
                            const Pose& cam_from_source);

// A job's extracted pairs solved (Job::Calibrate, any method), its summary printed, its result
// written to out_path (when not empty), the error against the dataset's ground truth printed when
// it has one; what went wrong said on stderr as "calibench <command>: ...". The exit code: kOk,
// kInputError when any pair file was unreadable, kNoCalibration, kNotConstrained.
int SolveAndSay(Job& job, const std::string& command, const std::string& out_path);
// SolveAndSay's saying, for a solve already told as verdicts (one per camera of a rig, named by
// `cameras`; CameraVerdicts, core/session/job.h) of the data `data`: the failure, or each camera's
// error against its ground truth; unreadable pair files (kInputError) and cameras not well
// constrained (kNotConstrained) on stderr; kNoCalibration when unsolved, else kOk.
int SayVerdicts(const std::vector<JobVerdict>& verdicts, const std::vector<std::string>& cameras,
                const std::string& command, const std::string& data);

// Calibrates and prints the summary; writes the result when out_path is not empty (with the
// intrinsics `estimated` from the images before, when given). Returns the exit code (kOk,
// kInputError when any pair file was unreadable, kNoCalibration, kNotConstrained).
int CalibrateAndReport(const Dataset& dataset, const PipelineOptions& options,
                       const std::string& out_path, CalibrationOutcome* outcome_out = nullptr,
                       const PairEdits& edits = {},
                       const std::optional<IntrinsicsResult>& estimated = std::nullopt);

}  // namespace calibench::app
