// The calibration a check judges (docs/targetless.md "Input"): read from a result file, from a
// session that holds a solve, or from any export format (export.h), with its covariance on the
// check's camera axes; or a rough guess (a CAD mount, a pose typed in), which the check refines
// and never judges.
#pragma once

#include <filesystem>
#include <string>

#include "core/base/types.h"
#include "core/results/export.h"

namespace calibench {

struct CheckedCalibration {
  Pose cam_from_lidar = Pose::Identity();
  // δ = [Δt (m); Δφ (rad)] on camera axes (check.h); zero when the file gives none.
  Mat6 camera_axes_covariance = Mat6::Zero();
  // Where it came from, in words ("a calibench result", "urdf: the pose of 'camera' in 'lidar'").
  std::string how;
};

// A calibench.result.v1 file, a session (calibench.session.v1) with a result, or an export
// (URDF, TF, Autoware, OpenCV YAML, Kalibr, txt) read with `frames` (which frame is the camera,
// in which convention; an export carries no covariance). Throws IoError naming the file when it
// is none of them, cannot be read, or is a session without a solve.
CheckedCalibration LoadCheckedCalibration(const std::filesystem::path& path,
                                          const ExportFrames& frames = {});

// A guess typed as a URDF joint's origin: "x y z roll pitch yaw", the camera's frame in the
// LiDAR's (metres, degrees; R = Rz(yaw) Ry(pitch) Rx(roll)), the camera frame in `camera_frame`'s
// convention (link: x forward, REP 103; optical: z forward). Throws std::invalid_argument saying
// what is wrong with the text.
CheckedCalibration GuessFromJointOrigin(const std::string& text, CameraFrame camera_frame);

}  // namespace calibench
