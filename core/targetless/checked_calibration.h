// The calibration a check judges (docs/targetless.md "Input"): read from a result file or from a
// session that holds a solve, with its covariance on the check's camera axes.
#pragma once

#include <filesystem>

#include "core/base/types.h"

namespace calibench {

struct CheckedCalibration {
  Pose cam_from_lidar = Pose::Identity();
  // δ = [Δt (m); Δφ (rad)] on camera axes (check.h); zero when the file gives none.
  Mat6 camera_axes_covariance = Mat6::Zero();
};

// A calibench.result.v1 file, or a session (calibench.session.v1) with a result. Throws IoError
// naming the file when it is neither, cannot be read, or is a session without a solve.
CheckedCalibration LoadCheckedCalibration(const std::filesystem::path& path);

}  // namespace calibench
