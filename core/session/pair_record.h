// One LiDAR-camera pair as the calibration job holds it (core/session/calibration_job.h): its
// status and reason, the brush and where it came from, both sides' fits, and what the last solve
// and pre-flight said of it. The job composes it from its record (the user's word, the statuses
// the steps left) and its detections; the workbench's snapshot shows it whole
// (docs/architecture.md, "One state").
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/guidance/preflight.h"
#include "core/lidar_camera/pipeline.h"
#include "core/results/pair_status.h"
#include "core/target/board_camera.h"
#include "core/target/lidar_plane.h"

namespace calibench {

// Where a pair's LiDAR region comes from: the board detection found (or the camera's prediction,
// completion's), the manifest's lidar_seed, or the user's brush (painted or erased).
enum class BrushOrigin { kDetected, kSeeded, kPainted };

struct PairRecord : PairStanding {
  BrushOrigin brush_origin = BrushOrigin::kDetected;
  // Sorted LiDAR-image pixel indices (ProjectById) of the region: painted, the seed's, or the
  // detected board's inliers; empty where no image pictures the pair (the CLI's job).
  std::vector<int> brush_pixels;
  std::optional<LidarPlaneFit> lidar;
  BoardOrigin board_origin;
  std::string lidar_failure;
  std::optional<BoardDetection> detection;  // the board's corners in the image
  std::optional<CameraBoardObservation> camera;
  std::string camera_failure;
  std::optional<Vec4> residual;  // at the solution shown, for a pair it solves with
  double robust_weight = 1.0;
  // Pre-flight's findings after the last solve, as `advise` lists them.
  std::vector<PreflightFinding> findings;

  // Accepted, with both planes: what the solver uses.
  bool SolvesWith() const { return status == PairStatus::kAccepted && lidar && camera; }
};

}  // namespace calibench
