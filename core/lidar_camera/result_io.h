// The 3D LiDAR ↔ camera result: calibench.result.v1 (core/results) with the plane solver's figures,
// and its summary for the terminal.
#pragma once

#include <filesystem>
#include <string>

#include "core/lidar_camera/pipeline.h"
#include "core/results/result_file.h"

namespace calibench {

// Writes the result atomically; throws IoError naming the file. Requires outcome.solution.
void WriteResult(const std::filesystem::path& path, const CalibrationOutcome& outcome,
                 const SolverOptions& options, const ResultNames& names = {});

// Which residuals a solve had: every solved pair's planes, and the board edges where the LiDAR saw
// where the sheet ends. Requires outcome.solution.
struct ResidualCounts {
  int plane_pairs = 0;          // pairs solved with (each gives its plane residual)
  int edge_pairs = 0;           // of those, pairs with at least one board-edge point used
  int edge_points = 0;          // board-edge points used, all pairs
  bool edges_in_model = false;  // the method and options use board edges
  // In words, "" when every pair gave edge points: which pairs gave none and what their rings
  // showed (observed, per pair), and what that means for the result.
  std::string note;
};
ResidualCounts CountResiduals(const CalibrationOutcome& outcome);

// The LiDAR noise model the pairs' planes were fitted with (LidarPlaneFit::lidar_model), in words:
// per model the pairs and why it was chosen, and what it means for the fit. "" without LiDAR fits.
std::string DescribeLidarModel(const CalibrationOutcome& outcome);

// The LiDAR's noise learned from the accepted pairs' boards (core/target/lidar_noise.h), in
// words: the summary's line and the workbench's note. "" without boards fitted along their rays.
std::string DescribeLearnedLidarNoise(const CalibrationOutcome& outcome);
// "LiDAR times: ...": whether the boards' returns carry their own times, and their span; said once
// per result ("" without LiDAR fits).
std::string DescribeLidarTimes(const CalibrationOutcome& outcome);

// Human-readable summary: both directions in words, standard deviations, observability, pairs.
std::string FormatSummary(const CalibrationOutcome& outcome, const ResultNames& names = {});

}  // namespace calibench
