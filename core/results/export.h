// Calibrations in the forms robots load (issue "Recordings in, calibrations out"): a URDF joint,
// ROS 1 / ROS 2 static transform launch files, OpenCV YAML, Autoware's sensor kit calibration,
// a Kalibr-style chain and a plain 4x4 matrix; and the reader of all of them (for round trips
// and `evaluate --reference`).
//
// Every format holds the child frame's pose in the parent frame, parent_from_child
// (x_in_parent = parent_from_child * x_in_child) -- what ROS TF, URDF joints and Autoware mean --
// except Kalibr's T_<child>_<parent>, which is its inverse by Kalibr's naming. The parent is the
// LiDAR and the child the camera unless swapped. Each file says so in words.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/types.h"

namespace calibench {

enum class ExportFormat { kUrdf, kRos1Tf, kRos2Tf, kOpenCvYaml, kAutoware, kKalibr, kTxt };

const std::vector<ExportFormat>& AllExportFormats();
std::string ExportFormatName(ExportFormat format);  // "urdf", "ros1-tf", ...
std::optional<ExportFormat> ParseExportFormat(std::string_view name);
// What a user would name the file: "calibration.urdf", "static_tf.launch", ...
std::string DefaultExportFileName(ExportFormat format);

// The camera's frame in the exported transform. Optical: z forward, x right, y down (the
// frame the calibration is computed in; ROS's "<camera>_optical_frame"). Link: REP 103 body
// axes, x forward, y left, z up (ROS's "<camera>_link"). Confusing the two is where users'
// transforms usually go wrong.
enum class CameraFrame { kOptical, kLink };
std::string CameraFrameName(CameraFrame frame);  // "optical" / "link"
std::optional<CameraFrame> ParseCameraFrame(std::string_view name);
// The fixed rotation between them: x_in_link = LinkFromOptical() * x_in_optical.
Mat3 LinkFromOptical();

struct ExportFrames {
  std::string lidar = "lidar";    // the LiDAR's (or LRF's) frame name
  std::string camera = "camera";  // the camera's frame name
  bool camera_is_parent = false;  // the user swapped them: parent = camera, child = LiDAR
  CameraFrame camera_frame = CameraFrame::kOptical;
  // A waved capture's clocks (result.json "time_offset"): the camera's stamps minus the LiDAR's
  // clock, seconds. Kalibr's file holds it as its timeshift (t_lidar = t_cam + shift, so shift =
  // -camera_minus_lidar_s); the others say it in their header.
  std::optional<double> camera_minus_lidar_s;

  const std::string& parent() const { return camera_is_parent ? camera : lidar; }
  const std::string& child() const { return camera_is_parent ? lidar : camera; }
  // Frame names must be non-empty, distinct, and of ROS's characters (letters, digits, _ / -).
  bool Check(std::string* why) const;
};

// The calibration's transform as the file holds it: parent_from_child with the camera in the
// chosen camera frame.
Pose ParentFromChild(const Pose& cam_from_lidar, const ExportFrames& frames);
// The inverse: cam_from_lidar (optical camera frame) from a parent_from_child.
Pose CamFromLidarOf(const Pose& parent_from_child, const ExportFrames& frames);

struct ExportedCalibration {
  std::string text;     // the file
  std::string command;  // ros1-tf / ros2-tf: the command line that publishes it; else empty
};
// `source` names where the calibration came from (a result or session file), for the header.
ExportedCalibration ExportCalibration(ExportFormat format, const Pose& cam_from_lidar,
                                      const ExportFrames& frames, const std::string& source);

// A rig's transform tree: the LiDAR (frames.lidar) the parent of every camera, each camera's
// frame named by `frame` (frames.camera and camera_is_parent are not used). URDF (a joint per
// camera), ROS 1 and ROS 2 static transforms (a publisher per camera), Autoware's
// sensor_kit_calibration.yaml (a child per camera) and a Kalibr camchain (cam<n> with T_cam_lidar
// and T_cn_cnm1); OpenCV YAML and txt hold one transform and throw std::invalid_argument.
struct RigExportCamera {
  std::string frame;
  Pose cam_from_lidar;
};
ExportedCalibration ExportRig(ExportFormat format, const std::vector<RigExportCamera>& cameras,
                              const ExportFrames& frames, const std::string& source);

// What an exported file (any format above) holds.
struct ImportedTransform {
  std::optional<ExportFormat> format;  // nullopt: a calibench result (cam_from_lidar)
  std::string parent, child;           // empty when the format does not name them (txt)
  Pose parent_from_child = Pose::Identity();
};
// Reads any of the formats above (by extension and content). Throws IoError naming the file.
ImportedTransform ReadExportedTransform(const std::filesystem::path& path);

// Roll, pitch, yaw (rad) of R = Rz(yaw) * Ry(pitch) * Rx(roll), as URDF and ROS use them.
Vec3 RollPitchYaw(const Mat3& rotation);
Mat3 RotationFromRollPitchYaw(double roll, double pitch, double yaw);

}  // namespace calibench
