// A rig of one LiDAR and its cameras calibrated together: each camera's pairs through the
// single-camera pipeline (CalibrateDataset: detection, its solve, completion), then the rig solve
// over every capture (core/lidar_camera/rig_solver.h), where a board two cameras saw at once ties
// them to each other. The result holds every camera's cam_from_lidar with its σ and the cameras'
// relative poses. One camera's dataset is a rig of one (RigOfOne, core/io/rig_folder.h): its rig
// solution is its own solve, so every front end reads one outcome whatever the rig's size.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/base/names.h"
#include "core/io/rig_folder.h"
#include "core/lidar_camera/dataset_calibration.h"
#include "core/lidar_camera/pipeline.h"
#include "core/lidar_camera/rig_solver.h"

namespace calibench {

struct RigOutcome {
  std::vector<std::string> camera_names;
  std::vector<CalibrationOutcome> single;  // each camera alone, as `calibrate` on its pairs
  // The rig solve, started from the single solutions; a rig of one's is its camera's solve (the
  // pose and its 6×6 covariance, no iterations).
  std::optional<RigSolution> joint;
  std::string failure;      // why `joint` is absent
  int shared_captures = 0;  // captures two or more cameras saw the board in

  // Two cameras or more: a rig solve, relative poses and a rig's result file (calibench.rig.v1).
  bool Several() const { return camera_names.size() > 1; }
};

// A rig of one's outcome (`rig` from RigOfOne) of its camera's calibration: `joint` is that
// solve, absent with its failure when it failed.
RigOutcome RigOutcomeOfOne(const RigFolder& rig, CalibrationOutcome single);

// The user's edits per camera (by camera name): each camera's session's brushes and rejections.
using RigEdits = std::map<std::string, PairEdits>;

// A pose with its σ in its own axes (mm, deg), named ("cam0", "cam1_from_cam0").
struct PoseWithSigmas {
  std::string name;
  Pose pose = Pose::Identity();
  Vec3 sigma_t_mm = Vec3::Zero(), sigma_r_deg = Vec3::Zero();
};
// The rig solve's cam_from_lidar of camera `c` with its σ (needs outcome.joint).
PoseWithSigmas RigJointPose(const RigOutcome& outcome, size_t c);
// Each camera after the first relative to the first, "<to>_from_<first>" (x_in_to = pose ·
// x_in_first), from the rig solve with σ (needs outcome.joint).
std::vector<PoseWithSigmas> RigRelativePoses(const RigOutcome& outcome);

// CalibrateRig one step at a time, for a front end that must not block on it for long (the
// workbench's worker runs each step between the user's edits): each camera's own calibration in
// its steps (DatasetCalibration, core/lidar_camera/dataset_calibration.h: the background, a few
// pairs at a time, its solve), the rig solve last. The results do not depend on the steps' size.
// Holds its copies of the arguments.
class RigCalibration {
 public:
  // pairs_per_thread: each camera's extraction steps (DatasetCalibration's); 0: one step.
  RigCalibration(RigFolder rig, PipelineOptions options, RigEdits edits = {},
                 ProgressCallback progress = {}, size_t pairs_per_thread = 0);
  ~RigCalibration();
  RigCalibration(const RigCalibration&) = delete;
  RigCalibration& operator=(const RigCalibration&) = delete;
  // Runs the next step; false when that was the last, or none was left (Outcome() is final).
  bool Step();
  // The camera the next step works on; camera_names.size() for the joint solve (or done).
  size_t NextCamera() const { return next_camera_; }
  const RigOutcome& Outcome() const { return outcome_; }

 private:
  void FinishCamera(size_t c, CalibrationOutcome single);

  RigFolder rig_;
  PipelineOptions options_;
  RigEdits edits_;
  ProgressCallback progress_;
  size_t pairs_per_thread_ = 0;
  RigOutcome outcome_;
  size_t next_camera_ = 0;
  std::unique_ptr<DatasetCalibration> camera_;  // the camera being calibrated
  bool solved_ = false;
  std::vector<RigCameraPrior> priors_;
  // Captures by stem: every camera's view of the board (NaturalOrder: the files' order).
  std::map<std::string, RigCapture, NaturalOrder> captures_;
};

// Calibrates every camera of the rig, then the rig (RigCalibration's steps, in a row). A camera
// whose own solve fails leaves the rig without a joint solution (failure says which and why). A
// rig of one is its camera's CalibrateDataset, bit for bit (RigOutcomeOfOne).
// `edits` apply to their camera's pairs, as `calibrate --session` applies one session's.
RigOutcome CalibrateRig(const RigFolder& rig, const PipelineOptions& options,
                        const ProgressCallback& progress = {}, const RigEdits& edits = {});

// The rig's result file (format calibench.rig.v1): "cameras": {"<camera>": {"cam_from_lidar":
// 4x4, "sigma_translation_mm", "sigma_rotation_deg" (camera axes), "covariance" (6x6, right
// perturbation [rho; phi]), "pairs", "single_camera": {"cam_from_lidar", σ}}}, and
// "camera_from_camera": {"<to>_from_<from>": {"matrix", σ}} for every ordered pair after the first
// camera. Throws IoError naming the file when it cannot be written.
void WriteRigResult(const std::filesystem::path& path, const RigOutcome& outcome);

// A rig result file's cameras (name, cam_from_lidar), in the file's order; throws IoError naming
// the file for anything else.
std::vector<std::pair<std::string, Pose>> LoadRigResult(const std::filesystem::path& path);
// Whether the file is a rig result (its first 4 KB name calibench.rig.v1).
bool IsRigResultFile(const std::filesystem::path& path);

// Per camera: the joint pose and σ next to the single-camera ones; the relative poses.
std::string FormatRigSummary(const RigOutcome& outcome);

}  // namespace calibench
