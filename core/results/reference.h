// Another calibration of the same rig as the reference a result is compared with, for real data
// without ground truth (`calibench evaluate --reference`): read from a result file or from any
// export format (export.h), and the difference weighed by the result's own uncertainty.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "core/base/types.h"
#include "core/geometry/geometry.h"
#include "core/results/export.h"

namespace calibench {

// cam_from_lidar (optical camera frame) of the reference file: a calibench result's own, or an
// exported transform read with `frames` (which frame is the camera, in which convention). *how
// says in words how it was read. Throws IoError naming the file.
Pose ReadReferenceCamFromLidar(const std::filesystem::path& path, const ExportFrames& frames,
                               std::string* how);
// The same of a transform already read (ReadExportedTransform).
Pose ReferenceCamFromLidar(const ImportedTransform& imported, const ExportFrames& frames,
                           std::string* how);

struct ReferenceDifference {
  PoseError error;               // result against the reference
  Vec3 translation_in_camera_m;  // the difference's translation in the reference camera's axes
  // delta^T Sigma^-1 delta, 6 dof, with delta = Log(reference^-1 * result) and Sigma the result's
  // covariance (a right perturbation): about 6 when the reference lies where the result's
  // uncertainty puts the truth, above 16.8 in 1 % of cases. None when the result has no covariance.
  std::optional<double> chi_square;
};
ReferenceDifference CompareWithReference(const Pose& cam_from_lidar, const Mat6& covariance,
                                         const Pose& reference_cam_from_lidar);

}  // namespace calibench
