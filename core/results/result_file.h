// The calibench.result.v1 file (docs/architecture.md, "Conventions and file contracts") of both
// methods: what every result holds in the same form (both directions of the transform, covariance,
// standard deviations, observability, one entry per pair), and its reader. Each method adds its own
// solver figures (core/lidar_camera/result_io.h, core/lrf/result_io.h).
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "core/base/types.h"

namespace calibench {

// The transform's frames: <target>_from_<source>.
struct ResultNames {
  std::string target = "cam";    // cam_from_<source>
  std::string source = "lidar";  // "lidar" or "lrf"
};

struct LoadedResult {
  Pose cam_from_source = Pose::Identity();  // cam_from_lidar (or cam_from_lrf)
  Mat6 covariance = Mat6::Zero();
  bool well_constrained = false;
  // A waved capture's "time_offset" (camera_minus_lidar_s); absent when null or not written.
  std::optional<double> camera_minus_lidar_s;
};
// Reads cam_from_lidar (or cam_from_lrf) and the covariance. Throws IoError naming the file.
LoadedResult LoadResult(const std::filesystem::path& path);

// The solver method a result file records (its "solver"."method": a lidar-camera or a rig result
// alike), "" when the file cannot be read as JSON or names none. Never throws: a report falls
// back to its own default.
std::string ResultSolverMethod(const std::filesystem::path& path);

// Whether the file is an LRF method's result (it holds cam_from_lrf); false when it cannot be read
// as JSON. Never throws: the reader that follows names the file's own problem.
bool IsLrfResultFile(const std::filesystem::path& path);

// The transform for a terminal: <target>_from_<source> and its inverse as 3x4 matrices, each with
// its direction in words, and the standard deviations in camera axes (mm and degrees).
std::string FormatTransform(const ResultNames& names, const Pose& target_from_source,
                            const Mat6& covariance);

}  // namespace calibench
