#include "core/results/reference.h"

#include <Eigen/Cholesky>

namespace calibench {

Pose ReadReferenceCamFromLidar(const std::filesystem::path& path, const ExportFrames& frames,
                               std::string* how) {
  return ReferenceCamFromLidar(ReadExportedTransform(path), frames, how);
}

Pose ReferenceCamFromLidar(const ImportedTransform& imported, const ExportFrames& frames,
                           std::string* how) {
  if (!imported.format) {
    *how = "a calibench result: cam_from_lidar";
    return imported.parent_from_child.inverse();
  }
  *how = ExportFormatName(*imported.format) + ": the pose of '" + imported.child + "' in '" +
         imported.parent + "', the camera (" + CameraFrameName(frames.camera_frame) +
         " frame) being the " + (frames.camera_is_parent ? "parent" : "child");
  return CamFromLidarOf(imported.parent_from_child, frames);
}

ReferenceDifference CompareWithReference(const Pose& cam_from_lidar, const Mat6& covariance,
                                         const Pose& reference_cam_from_lidar) {
  ReferenceDifference difference;
  difference.error = ComputePoseError(cam_from_lidar, reference_cam_from_lidar);
  // The result's covariance is of a right perturbation: result = reference * Exp(delta).
  const Vec6 delta = LogSE3(reference_cam_from_lidar.inverse() * cam_from_lidar);
  difference.translation_in_camera_m = reference_cam_from_lidar.rotation() * delta.head<3>();
  if (!covariance.isZero()) difference.chi_square = delta.dot(covariance.ldlt().solve(delta));
  return difference;
}

}  // namespace calibench
