// The calibench.result.v1 file (DESIGN.md "Result").
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "core/pipeline.h"

namespace calibench {

struct ResultNames {
  std::string target = "cam";    // cam_from_<source>
  std::string source = "lidar";  // "lidar" or "lrf"
};

// The result as JSON text. Requires outcome.solution.
std::string ResultToJson(const CalibrationOutcome& outcome, const SolverOptions& options,
                         const ResultNames& names = {});

// Writes atomically; throws IoError naming the file.
void WriteResult(const std::filesystem::path& path, const CalibrationOutcome& outcome,
                 const SolverOptions& options, const ResultNames& names = {});

struct LoadedResult {
  Pose cam_from_source = Pose::Identity();  // cam_from_lidar (or cam_from_lrf)
  Mat6 covariance = Mat6::Zero();
  bool well_constrained = false;
};
// Reads cam_from_lidar (or cam_from_lrf) and the covariance. Throws IoError naming the file.
LoadedResult LoadResult(const std::filesystem::path& path);

// Human-readable summary: both directions in words, standard deviations, observability, pairs.
std::string FormatSummary(const CalibrationOutcome& outcome, const ResultNames& names = {});

// Standard deviations of cam_from_lidar along the camera axes, from the covariance of its right
// perturbation: the translation of T·Exp([rho; phi]) moves by R·rho and its rotation by R·phi to
// first order, so both blocks are rotated into the camera frame. Metres and degrees.
Vec3 TranslationStd(const Mat6& covariance, const Pose& cam_from_lidar);
Vec3 RotationStdDeg(const Mat6& covariance, const Pose& cam_from_lidar);

}  // namespace calibench
