#include "core/targetless/checked_calibration.h"

#include "core/results/result_file.h"
#include "core/session/session.h"
#include "core/targetless/check.h"

namespace calibench {

CheckedCalibration LoadCheckedCalibration(const std::filesystem::path& path) {
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
    return checked;
  }
  const LoadedResult loaded = LoadResult(path);
  checked.cam_from_lidar = loaded.cam_from_source;
  checked.camera_axes_covariance = CameraAxesCovariance(loaded.covariance, loaded.cam_from_source);
  return checked;
}

}  // namespace calibench
