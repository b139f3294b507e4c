#include "core/targetless/checked_calibration.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "core/results/reference.h"
#include "core/results/result_file.h"
#include "core/session/session.h"
#include "core/targetless/check.h"

namespace calibench {

CheckedCalibration LoadCheckedCalibration(const std::filesystem::path& path,
                                          const ExportFrames& frames) {
  CheckedCalibration checked;
  if (IsSessionFile(path)) {
    const Session session = LoadSession(path);
    if (!session.result)
      throw IoError(path.string() +
                    ": the session has no result yet (press Run in the workbench, or `calibench "
                    "calibrate --session`)");
    checked.cam_from_lidar = session.result->cam_from_lidar;
    checked.camera_axes_covariance =
        CameraAxesCovariance(session.result->covariance, checked.cam_from_lidar);
    checked.how = "a workbench session's result";
    return checked;
  }
  // Any export format, a calibench result among them (its covariance read below).
  const ImportedTransform imported = ReadExportedTransform(path);
  checked.cam_from_lidar = ReferenceCamFromLidar(imported, frames, &checked.how);
  if (!imported.format) {
    const LoadedResult loaded = LoadResult(path);
    checked.cam_from_lidar = loaded.cam_from_source;
    checked.camera_axes_covariance =
        CameraAxesCovariance(loaded.covariance, loaded.cam_from_source);
  }
  return checked;
}

CheckedCalibration GuessFromJointOrigin(const std::string& text, CameraFrame camera_frame) {
  std::istringstream in(text);
  double v[6];
  for (double& x : v)
    if (!(in >> x) || !std::isfinite(x))
      throw std::invalid_argument("'" + text +
                                  "' is not six numbers 'x y z roll pitch yaw' (metres, degrees)");
  std::string rest;
  if (in >> rest)
    throw std::invalid_argument("'" + text + "' has more than six numbers (x y z roll pitch yaw)");
  Pose lidar_from_camera = Pose::Identity();
  lidar_from_camera.linear() =
      RotationFromRollPitchYaw(v[3] * kDegToRad, v[4] * kDegToRad, v[5] * kDegToRad);
  lidar_from_camera.translation() = Vec3(v[0], v[1], v[2]);
  ExportFrames frames;
  frames.camera_frame = camera_frame;
  CheckedCalibration guess;
  guess.cam_from_lidar = CamFromLidarOf(lidar_from_camera, frames);
  guess.how = "a guess: the " + CameraFrameName(camera_frame) +
              " camera frame at x y z roll pitch yaw = " + text + " in the LiDAR's";
  return guess;
}

}  // namespace calibench
