// Camera intrinsics files: OpenCV FileStorage (YAML/XML), ROS camera_info YAML, Kalibr camchain.
#pragma once

#include <filesystem>

#include "core/camera/camera.h"

namespace calibench {

// Reads intrinsics from an OpenCV FileStorage YAML/XML (camera_matrix, distortion_coefficients,
// optional distortion_model), a ROS camera_info YAML (camera_calibration output or the CameraInfo
// message fields K/D), or a Kalibr camchain (cam0). The model must be stated by the file
// (plumb_bob / rational_polynomial / radtan -> pinhole-radtan; equidistant / fisheye ->
// kannala-brandt); OpenCV FileStorage files without a model are pinhole-radtan by definition.
// Throws IoError naming the file and the problem (with its line where the YAML parser gives one):
// a missing or mistyped field, a key given twice, invalid YAML/XML, binary data, or text nested
// deeper than 64 levels (refused before any parser sees it).
CameraModel LoadCameraFile(const std::filesystem::path& path);

}  // namespace calibench
