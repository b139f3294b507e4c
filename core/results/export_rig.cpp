// ExportRig (core/results/export.h): a rig's transform tree, the LiDAR the parent of every camera,
// in the formats that hold a tree. Each camera's transform is the single-camera one
// (ParentFromChild with its frame named), so a rig of one camera writes what `export` writes.
#include <stdexcept>

#include "core/results/export.h"
#include "core/results/export_text.h"

namespace calibench {

using namespace export_text;

namespace {

// One camera of the tree: its frames (the LiDAR the parent) and its transform as text.
struct RigChild {
  ExportFrames frames;
  Pose parent_from_child;
  TransformText text;
};

std::string RigUrdf(const std::vector<RigChild>& children, const ExportFrames& frames,
                    const std::vector<std::string>& header) {
  std::string text = "<?xml version=\"1.0\"?>\n<!--\n" + Commented(header, "  ") +
                     "  Each joint's origin is that pose (xyz in metres, rpy in radians: "
                     "R = Rz(yaw) Ry(pitch) Rx(roll)).\n-->\n<robot name=\"calibench_rig\">\n" +
                     "  <link name=\"" + frames.lidar + "\"/>\n";
  for (const RigChild& child : children) {
    const TransformText& t = child.text;
    text += "  <link name=\"" + child.frames.camera + "\"/>\n";
    text += "  <joint name=\"" + JointName(child.frames) + "\" type=\"fixed\">\n";
    text += "    <parent link=\"" + frames.lidar + "\"/>\n";
    text += "    <child link=\"" + child.frames.camera + "\"/>\n";
    text += "    <origin xyz=\"" + t.x + " " + t.y + " " + t.z + "\" rpy=\"" + t.roll + " " +
            t.pitch + " " + t.yaw + "\"/>\n  </joint>\n";
  }
  return text + "</robot>\n";
}

// sensor_kit_calibration.yaml: the LiDAR's block with a child per camera.
std::string RigAutoware(const std::vector<RigChild>& children, const ExportFrames& frames,
                        const std::vector<std::string>& header) {
  std::string text = Commented(header, "# ") +
                     "# Autoware's sensor_kit_calibration.yaml form: <parent>: <child>: x y z "
                     "(m),\n# roll pitch yaw (rad, R = Rz(yaw) Ry(pitch) Rx(roll)).\n" +
                     frames.lidar + ":\n";
  for (const RigChild& child : children) {
    const TransformText& t = child.text;
    text += "  " + child.frames.camera + ":\n";
    for (const auto& [key, value] : {std::pair{"x", t.x},
                                     {"y", t.y},
                                     {"z", t.z},
                                     {"roll", t.roll},
                                     {"pitch", t.pitch},
                                     {"yaw", t.yaw}})
      text += std::string("    ") + key + ": " + value + "\n";
  }
  return text;
}

// A camchain: cam<n> with T_cam_lidar and, from cam1 on, T_cn_cnm1 (camera n from camera n-1),
// as Kalibr's multi-camera chains hold them.
std::string RigKalibr(const std::vector<RigChild>& children, const ExportFrames& frames,
                      const std::vector<std::string>& header) {
  std::string text = Commented(header, "# ") +
                     "# Kalibr's naming: T_a_b maps b into a (x_in_a = T_a_b * x_in_b): "
                     "T_cam_lidar is <camera>_from_" +
                     frames.lidar + ", T_cn_cnm1 the camera from the one before it.\n";
  for (size_t c = 0; c < children.size(); ++c) {
    const Pose cam_from_lidar = children[c].parent_from_child.inverse();
    text += "cam" + std::to_string(c) + ":\n  T_cam_lidar:\n" +
            MatrixRows(cam_from_lidar.matrix(), "  ");
    if (c > 0)
      text += "  T_cn_cnm1:\n" +
              MatrixRows((cam_from_lidar * children[c - 1].parent_from_child).matrix(), "  ");
    text += "  rostopic_frame: " + children[c].frames.camera + "\n  parent_frame: " + frames.lidar +
            "\n  camera_frame: " + CameraFrameName(frames.camera_frame) + "\n";
  }
  return text;
}

// The launch files: one publisher per camera, each the body of the single-camera file.
ExportedCalibration RigLaunch(ExportFormat format, const std::vector<RigChild>& children,
                              const std::vector<std::string>& header, const std::string& source) {
  const bool ros1 = format == ExportFormat::kRos1Tf;
  const std::string open = ros1 ? "<node " : "        Node(";
  const std::string close = ros1 ? "/>\n" : "        ),\n";
  ExportedCalibration tree;
  std::string body;
  for (const RigChild& child : children) {
    const ExportedCalibration part = ExportCalibration(
        format, CamFromLidarOf(child.parent_from_child, child.frames), child.frames, source);
    const size_t begin = part.text.find(open);
    const size_t end = part.text.find(close, begin);
    CALIBENCH_CHECK(begin != std::string::npos && end != std::string::npos);
    body += (ros1 ? "  " : "") + part.text.substr(begin, end + close.size() - begin);
    tree.command += (tree.command.empty() ? "" : "\n") + part.command;
  }
  tree.text =
      ros1 ? "<launch>\n  <!--\n" + Commented(header, "    ") + "  -->\n" + body + "</launch>\n"
           : Commented(header, "# ") +
                 "\nfrom launch import LaunchDescription\nfrom launch_ros.actions import "
                 "Node\n\n\ndef generate_launch_description():\n    return "
                 "LaunchDescription([\n" +
                 body + "    ])\n";
  return tree;
}

}  // namespace

ExportedCalibration ExportRig(ExportFormat format, const std::vector<RigExportCamera>& cameras,
                              const ExportFrames& frames, const std::string& source) {
  std::vector<RigChild> children;
  for (const RigExportCamera& camera : cameras) {
    RigChild child;
    child.frames = frames;
    child.frames.camera = camera.frame;
    child.frames.camera_is_parent = false;
    child.parent_from_child = ParentFromChild(camera.cam_from_lidar, child.frames);
    child.text = TextOf(child.parent_from_child);
    children.push_back(std::move(child));
  }
  const std::vector<std::string> header = {
      "Calibench rig calibration" + (source.empty() ? "" : " from " + source) + ": the pose of " +
          "each camera in '" + frames.lidar + "' (x_in_" + frames.lidar + " = " + frames.lidar +
          "_from_<camera> * x_in_<camera>)",
      "The camera frames are " + CameraFrameWords(frames.camera_frame)};
  switch (format) {
    case ExportFormat::kUrdf:
      return {RigUrdf(children, frames, header), ""};
    case ExportFormat::kAutoware:
      return {RigAutoware(children, frames, header), ""};
    case ExportFormat::kKalibr:
      return {RigKalibr(children, frames, header), ""};
    case ExportFormat::kRos1Tf:
    case ExportFormat::kRos2Tf:
      return RigLaunch(format, children, header, source);
    case ExportFormat::kOpenCvYaml:
    case ExportFormat::kTxt:
      break;
  }
  throw std::invalid_argument(
      "a rig's tree exports as urdf, ros1-tf, ros2-tf, autoware or kalibr; " +
      ExportFormatName(format) + " holds one transform");
}

}  // namespace calibench
