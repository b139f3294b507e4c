// The writers of core/results/export.h. Numbers are printed with 17 significant digits, so a
// file read back gives the same doubles; rotations go out as quaternions where the format allows
// (TF launch files) and as roll-pitch-yaw where it does not (URDF, Autoware).
#include "core/results/export.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "core/results/export_text.h"

namespace calibench {

using namespace export_text;

namespace {

ExportedCalibration Urdf(const Pose& pose, const ExportFrames& frames, const std::string& source) {
  const TransformText t = TextOf(pose);
  std::string text = "<?xml version=\"1.0\"?>\n<!--\n" +
                     Commented(HeaderLines(frames, source), "  ") +
                     "  The joint's origin is that pose (xyz in metres, rpy in radians: "
                     "R = Rz(yaw) Ry(pitch) Rx(roll)).\n-->\n";
  text += "<robot name=\"calibench_calibration\">\n";
  text += "  <link name=\"" + frames.parent() + "\"/>\n  <link name=\"" + frames.child() + "\"/>\n";
  text += "  <joint name=\"" + JointName(frames) + "\" type=\"fixed\">\n";
  text += "    <parent link=\"" + frames.parent() + "\"/>\n";
  text += "    <child link=\"" + frames.child() + "\"/>\n";
  text += "    <origin xyz=\"" + t.x + " " + t.y + " " + t.z + "\" rpy=\"" + t.roll + " " +
          t.pitch + " " + t.yaw + "\"/>\n";
  text += "  </joint>\n</robot>\n";
  return {text, ""};
}

ExportedCalibration Ros1Tf(const Pose& pose, const ExportFrames& frames,
                           const std::string& source) {
  const TransformText t = TextOf(pose);
  const std::string args = t.x + " " + t.y + " " + t.z + " " + t.qx + " " + t.qy + " " + t.qz +
                           " " + t.qw + " " + frames.parent() + " " + frames.child();
  const std::string command = "rosrun tf2_ros static_transform_publisher " + args;
  std::string text = "<launch>\n  <!--\n" + Commented(HeaderLines(frames, source), "    ") +
                     "    Arguments: x y z (m) qx qy qz qw frame_id child_frame_id.\n"
                     "    The same from a shell:\n    " +
                     command + "\n  -->\n";
  text += "  <node pkg=\"tf2_ros\" type=\"static_transform_publisher\" name=\"" +
          JointName(frames) + "\" args=\"" + args + "\"/>\n</launch>\n";
  return {text, command};
}

ExportedCalibration Ros2Tf(const Pose& pose, const ExportFrames& frames,
                           const std::string& source) {
  const TransformText t = TextOf(pose);
  const std::vector<std::pair<std::string, std::string>> arguments = {
      {"--x", t.x},
      {"--y", t.y},
      {"--z", t.z},
      {"--qx", t.qx},
      {"--qy", t.qy},
      {"--qz", t.qz},
      {"--qw", t.qw},
      {"--frame-id", frames.parent()},
      {"--child-frame-id", frames.child()}};
  std::string command = "ros2 run tf2_ros static_transform_publisher";
  std::string list;
  for (const auto& [flag, value] : arguments) {
    command += " " + flag + " " + value;
    list += "                \"" + flag + "\", \"" + value + "\",\n";
  }
  std::string text = Commented(HeaderLines(frames, source), "# ") +
                     "# The same from a shell:\n#   " + command + "\n\n";
  text += "from launch import LaunchDescription\nfrom launch_ros.actions import Node\n\n\n";
  text += "def generate_launch_description():\n    return LaunchDescription([\n";
  text += "        Node(\n            package=\"tf2_ros\",\n";
  text += "            executable=\"static_transform_publisher\",\n";
  text += "            name=\"" + JointName(frames) + "\",\n";
  text += "            arguments=[\n" + list + "            ],\n        ),\n    ])\n";
  return {text, command};
}

ExportedCalibration OpenCvYaml(const Pose& pose, const ExportFrames& frames,
                               const std::string& source) {
  const Mat4 m = pose.matrix();
  std::string text = "%YAML:1.0\n---\n" + Commented(HeaderLines(frames, source), "# ");
  text +=
      "# parent_from_child is that 4x4 matrix (rotation | translation in metres), as\n"
      "# cv::FileStorage reads it: fs[\"parent_from_child\"] >> mat.\n";
  text += "parent_frame: \"" + frames.parent() + "\"\nchild_frame: \"" + frames.child() + "\"\n";
  text += "camera_frame: \"" + CameraFrameName(frames.camera_frame) + "\"\n";
  text += "parent_from_child: !!opencv-matrix\n   rows: 4\n   cols: 4\n   dt: d\n   data: [ ";
  std::string data;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) data += (data.empty() ? "" : ", ") + Number(m(r, c));
  text += data + " ]\n";
  return {text, ""};
}

ExportedCalibration Autoware(const Pose& pose, const ExportFrames& frames,
                             const std::string& source) {
  const TransformText t = TextOf(pose);
  std::string text =
      Commented(HeaderLines(frames, source), "# ") +
      "# Autoware's sensor_kit_calibration.yaml form: <parent>: <child>: x y z (m),\n"
      "# roll pitch yaw (rad, R = Rz(yaw) Ry(pitch) Rx(roll)).\n";
  text += frames.parent() + ":\n  " + frames.child() + ":\n";
  text += "    x: " + t.x + "\n    y: " + t.y + "\n    z: " + t.z + "\n";
  text += "    roll: " + t.roll + "\n    pitch: " + t.pitch + "\n    yaw: " + t.yaw + "\n";
  return {text, ""};
}

ExportedCalibration Kalibr(const Pose& pose, const ExportFrames& frames,
                           const std::string& source) {
  // Kalibr names T_a_b the transform from b to a (its camchains hold T_cam_imu = cam_from_imu).
  const bool camera_child = !frames.camera_is_parent;
  const std::string key = camera_child ? "T_cam_lidar" : "T_lidar_cam";
  std::string text = Commented(HeaderLines(frames, source), "# ") + "# Kalibr's naming: " + key +
                     " is " + frames.child() + "_from_" + frames.parent() +
                     ", the inverse of the pose above (x_in_" + frames.child() + " = " + key +
                     " * x_in_" + frames.parent() + ").\n";
  text += "cam0:\n  " + key + ":\n" + MatrixRows(pose.inverse().matrix(), "  ");
  text += "  parent_frame: " + frames.parent() + "\n  child_frame: " + frames.child() + "\n";
  text += "  camera_frame: " + CameraFrameName(frames.camera_frame) + "\n";
  // Kalibr's sign: t_lidar = t_cam + timeshift_cam_lidar (as its timeshift_cam_imu).
  if (frames.camera_minus_lidar_s) {
    char shift[48];
    std::snprintf(shift, sizeof(shift), "%.9g", -*frames.camera_minus_lidar_s);
    text += "  timeshift_cam_lidar: " + std::string(shift) + "\n";
  }
  return {text, ""};
}

ExportedCalibration Txt(const Pose& pose, const ExportFrames& frames, const std::string& source) {
  const Mat4 m = pose.matrix();
  std::string text = Commented(HeaderLines(frames, source), "# ");
  text += "# parent: " + frames.parent() + "  child: " + frames.child() + "\n";
  for (int r = 0; r < 4; ++r) text += Numbers({m(r, 0), m(r, 1), m(r, 2), m(r, 3)}, " ") + "\n";
  return {text, ""};
}

}  // namespace

namespace {

// One row per format: its name on the command line and the file name users give it.
struct FormatInfo {
  ExportFormat format;
  const char* name;
  const char* file;
};
constexpr FormatInfo kFormats[] = {
    {ExportFormat::kUrdf, "urdf", "calibration.urdf"},
    {ExportFormat::kRos1Tf, "ros1-tf", "static_tf.launch"},
    {ExportFormat::kRos2Tf, "ros2-tf", "static_tf.launch.py"},
    {ExportFormat::kOpenCvYaml, "opencv-yaml", "calibration.opencv.yaml"},
    {ExportFormat::kAutoware, "autoware", "sensor_kit_calibration.yaml"},
    {ExportFormat::kKalibr, "kalibr", "calibration.kalibr.yaml"},
    {ExportFormat::kTxt, "txt", "calibration.txt"},
};

const FormatInfo& InfoOf(ExportFormat format) {
  for (const FormatInfo& info : kFormats)
    if (info.format == format) return info;
  CALIBENCH_CHECK(false && "export format missing from kFormats");
  return kFormats[0];
}

}  // namespace

const std::vector<ExportFormat>& AllExportFormats() {
  static const std::vector<ExportFormat> formats = [] {
    std::vector<ExportFormat> all;
    for (const FormatInfo& info : kFormats) all.push_back(info.format);
    return all;
  }();
  return formats;
}

std::string ExportFormatName(ExportFormat format) { return InfoOf(format).name; }

std::optional<ExportFormat> ParseExportFormat(std::string_view name) {
  for (const FormatInfo& info : kFormats)
    if (name == info.name) return info.format;
  return std::nullopt;
}

std::string DefaultExportFileName(ExportFormat format) { return InfoOf(format).file; }

std::string CameraFrameName(CameraFrame frame) {
  return frame == CameraFrame::kOptical ? "optical" : "link";
}

std::optional<CameraFrame> ParseCameraFrame(std::string_view name) {
  if (name == "optical") return CameraFrame::kOptical;
  if (name == "link") return CameraFrame::kLink;
  return std::nullopt;
}

Mat3 LinkFromOptical() {
  // Columns: the optical axes in link coordinates. Optical z (forward) = link x, optical x
  // (right) = link -y, optical y (down) = link -z.
  Mat3 link_from_optical;
  link_from_optical << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  return link_from_optical;
}

bool ExportFrames::Check(std::string* why) const {
  for (const std::string* name : {&lidar, &camera}) {
    const bool valid = !name->empty() && name->find_first_not_of(
                                             "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                             "0123456789_/-") == std::string::npos;
    if (!valid) {
      *why = "frame name '" + *name + "' must be letters, digits, '_', '/' or '-'";
      return false;
    }
  }
  if (lidar == camera) {
    *why = "the parent and child frames must differ, both are '" + lidar + "'";
    return false;
  }
  return true;
}

Pose ParentFromChild(const Pose& cam_from_lidar, const ExportFrames& frames) {
  Pose camera_from_optical = Pose::Identity();
  if (frames.camera_frame == CameraFrame::kLink) camera_from_optical.linear() = LinkFromOptical();
  const Pose camera_from_lidar = camera_from_optical * cam_from_lidar;
  return frames.camera_is_parent ? camera_from_lidar : camera_from_lidar.inverse();
}

Pose CamFromLidarOf(const Pose& parent_from_child, const ExportFrames& frames) {
  Pose optical_from_camera = Pose::Identity();
  if (frames.camera_frame == CameraFrame::kLink)
    optical_from_camera.linear() = LinkFromOptical().transpose();
  const Pose camera_from_lidar =
      frames.camera_is_parent ? parent_from_child : parent_from_child.inverse();
  return optical_from_camera * camera_from_lidar;
}

ExportedCalibration ExportCalibration(ExportFormat format, const Pose& cam_from_lidar,
                                      const ExportFrames& frames, const std::string& source) {
  const Pose pose = ParentFromChild(cam_from_lidar, frames);
  switch (format) {
    case ExportFormat::kUrdf:
      return Urdf(pose, frames, source);
    case ExportFormat::kRos1Tf:
      return Ros1Tf(pose, frames, source);
    case ExportFormat::kRos2Tf:
      return Ros2Tf(pose, frames, source);
    case ExportFormat::kOpenCvYaml:
      return OpenCvYaml(pose, frames, source);
    case ExportFormat::kAutoware:
      return Autoware(pose, frames, source);
    case ExportFormat::kKalibr:
      return Kalibr(pose, frames, source);
    case ExportFormat::kTxt:
      return Txt(pose, frames, source);
  }
  return Txt(pose, frames, source);
}

Vec3 RollPitchYaw(const Mat3& r) {
  // R = Rz(yaw) Ry(pitch) Rx(roll): R20 = -sin(pitch), R21 / R22 = tan(roll), R10 / R00 = tan(yaw).
  const double pitch = std::atan2(-r(2, 0), std::hypot(r(0, 0), r(1, 0)));
  if (std::hypot(r(0, 0), r(1, 0)) < 1e-12) {  // pitch = +-90 deg: only roll - yaw is defined
    return Vec3(std::atan2(-r(1, 2), r(1, 1)), pitch, 0.0);
  }
  return Vec3(std::atan2(r(2, 1), r(2, 2)), pitch, std::atan2(r(1, 0), r(0, 0)));
}

Mat3 RotationFromRollPitchYaw(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Vec3::UnitZ()) * Eigen::AngleAxisd(pitch, Vec3::UnitY()) *
          Eigen::AngleAxisd(roll, Vec3::UnitX()))
      .toRotationMatrix();
}

}  // namespace calibench
