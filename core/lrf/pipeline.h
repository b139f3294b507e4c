// The LRF methods end to end: load an observation's files, extract its features, solve, and
// write the result (calibench.result.v1 with cam_from_lrf / lrf_from_cam).
//
// Three-face target + depth camera (papers/lrf-depth-camera-vboard.txt): scan corners and face
// lines, depth faces and their intersection lines, then paper-linear / refined / adaptive.
// Checkerboard + RGB camera (Zhang & Pless 2004): scan points on the board, the board plane from
// PnP (core pipeline), then the same refinement.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/base/parallel.h"
#include "core/lrf/board_in_scan.h"
#include "core/lrf/depth_planes.h"
#include "core/lrf/scan_lines.h"
#include "core/lrf/solver.h"
#include "core/lrf_data/dataset.h"
#include "core/results/pair_status.h"
#include "core/target/board_camera.h"

namespace calibench {

struct LrfPipelineOptions {
  ScanFeatureOptions scan;
  DepthFeatureOptions depth;
  BoardScanOptions board_scan;
  BoardDetectionOptions detection;  // checkerboard case
  PnpOptions pnp;                   // checkerboard case
  LrfSolverOptions solver;
  // Algorithm 1: > 0 = add observations in order until the newest one's Eq. (12) error falls
  // below this (metres); 0 = use every accepted observation.
  double adaptive_error_threshold_m = 0.0;
  std::vector<std::string> pair_ids;  // empty = every pair
  int threads = DefaultThreads();     // feature extraction workers
  bool Check(std::string* why) const;
};

struct LrfPairFeatures : PairStanding {
  bool input_error = false;
  LaserScan scan;                                // as loaded (empty on input error)
  std::optional<LrfObservation> three_face;      // features (ok or not) for the three-face target
  std::optional<DepthImage> depth;               // three-face: the depth frame (for display)
  std::optional<BoardScanPoints> board_scan;     // checkerboard: scan points on the board
  std::optional<CameraBoardObservation> camera;  // checkerboard: PnP
};

// Never throws for bad data: the pair comes back kFailed with the reason (files named).
LrfPairFeatures ExtractLrfPairFeatures(const LrfDataset& dataset, const LrfPairEntry& pair,
                                       const LrfPipelineOptions& options);

struct LrfCalibrationOutcome {
  std::vector<LrfPairFeatures> pairs;
  std::optional<LrfSolution> solution;        // absent when no calibration could be computed
  std::string failure;                        // why `solution` is absent
  std::optional<AdaptiveLrfResult> adaptive;  // when options.adaptive_error_threshold_m > 0
};

// Every selected pair extracted on options.threads workers, then solved: an LrfPairExtraction
// (core/lrf/pair_extraction.h) run at once.
LrfCalibrationOutcome CalibrateLrfDataset(const LrfDataset& dataset,
                                          const LrfPipelineOptions& options,
                                          const ProgressCallback& progress = {});
// Solves from already extracted pairs (accepted ones only; pending ones with features count as
// accepted), with the dataset's initial guess when the linear seed fails.
LrfCalibrationOutcome SolveLrfFromFeatures(std::vector<LrfPairFeatures> pairs,
                                           const LrfDataset& dataset,
                                           const LrfPipelineOptions& options);

}  // namespace calibench
