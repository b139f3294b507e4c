// The headless pipeline over plain data: load -> extract features (planes) -> solve.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/board_camera.h"
#include "core/dataset.h"
#include "core/lidar_plane.h"
#include "core/solver.h"

namespace calibench {

struct PipelineOptions {
  LidarPlaneOptions lidar_plane;
  BoardDetectionOptions detection;
  PnpOptions pnp;
  SolverOptions solver;
  std::vector<std::string> pair_ids;           // empty = every pair of the dataset
  std::optional<Pose> initial_cam_from_lidar;  // user guess; else the closed form from planes
  int threads = 1;                             // feature extraction workers
  int min_pairs = 3;                           // planes fix all 6 dof from 3 pairs on
  // LiDAR: grow each brushed / seeded region to the whole board, limited by the target's sheet
  // size (LidarPlaneOptions::grow_radius_m = BoardGrowRadius(target)).
  bool grow_to_board = true;
  bool Check(std::string* why) const;
};

enum class PairStatus { kPending, kAccepted, kRejected, kFailed };
std::string PairStatusName(PairStatus status);  // "pending", "accepted", "rejected", "failed"

struct PairFeatures {
  std::string id;
  PairStatus status = PairStatus::kPending;
  std::string reason;        // why failed / rejected, human-readable
  bool input_error = false;  // the pair's files could not be read
  std::optional<LidarPlaneFit> lidar;
  std::optional<CameraBoardObservation> camera;
};

// options.lidar_plane for `target`: its grow radius (when options.grow_to_board) and its sheet size
// (for the board edges), where options.lidar_plane leaves them unset.
LidarPlaneOptions LidarPlaneOptionsFor(const PipelineOptions& options, const BoardSpec& target);

// The solver's input for one pair: both planes with their covariances.
PlanePair MakePlanePair(const std::string& id, const LidarPlaneFit& lidar,
                        const CameraBoardObservation& camera);

// Loads the pair's files and extracts both planes. Never throws for bad data: the pair comes
// back kFailed with the reason (unreadable files name the file).
PairFeatures ExtractPairFeatures(const Dataset& dataset, const PairEntry& pair,
                                 const PipelineOptions& options);

struct CalibrationOutcome {
  std::vector<PairFeatures> pairs;
  std::optional<SolverResult> solution;  // absent when no calibration could be computed
  std::string failure;                   // why `solution` is absent
  Pose initial_cam_from_lidar = Pose::Identity();
};

using ProgressCallback = std::function<void(int done, int total, const std::string& pair_id)>;

// Extracts every selected pair (in parallel with options.threads) and solves.
CalibrationOutcome CalibrateDataset(const Dataset& dataset, const PipelineOptions& options,
                                    const ProgressCallback& progress = {});

// Solves from already extracted features; pairs not kAccepted are ignored. Pairs with a
// (lidar, camera) plane and status kPending count as accepted.
CalibrationOutcome SolveFromFeatures(std::vector<PairFeatures> pairs,
                                     const PipelineOptions& options);

// Translation (metres) and rotation (radians) error of an estimate against a reference.
struct PoseError {
  double translation_m = 0.0;
  double rotation_rad = 0.0;
};
PoseError ComputePoseError(const Pose& estimate, const Pose& reference);

}  // namespace calibench
