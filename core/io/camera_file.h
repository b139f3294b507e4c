// Camera intrinsics files: OpenCV FileStorage (YAML/XML), ROS camera_info YAML, Kalibr camchain.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

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

// The camera a ROS CameraInfo describes: its distortion model by name (plumb_bob and
// rational_polynomial -> pinhole-radtan with 5 or 8 coefficients, equidistant -> kannala-brandt),
// K row-major, D. Throws std::invalid_argument naming what is wrong (an unknown model, a
// coefficient count the model does not have, intrinsics that fail CameraModel::Check).
CameraModel CameraFromCameraInfo(const std::string& distortion_model, int width, int height,
                                 const double (&k)[9], const std::vector<double>& d);

// Writes the camera as a ROS camera_info YAML (camera_calibration's layout, which
// LoadCameraFile and ROS's camera_info_manager read). Throws IoError naming the file.
void SaveCameraInfoYaml(const std::filesystem::path& path, const CameraModel& camera,
                        const std::string& camera_name);

// The forms a camera file is written in (each read back by LoadCameraFile).
enum class CameraFileFormat { kRosCameraInfo, kOpenCv, kKalibr };
std::optional<CameraFileFormat> ParseCameraFileFormat(
    const std::string& name);  // ros|opencv|kalibr

// Writes the camera (with its image size) atomically: a ROS camera_info YAML
// (SaveCameraInfoYaml), an OpenCV FileStorage YAML (%YAML:1.0, camera_matrix,
// distortion_coefficients, distortion_model) or a Kalibr camchain (cam0). Throws IoError naming
// the file, also when the format cannot hold the model (Kalibr's radtan has no k3).
void SaveCameraFile(const std::filesystem::path& path, const CameraModel& camera,
                    CameraFileFormat format, const std::string& camera_name = "camera");

}  // namespace calibench
