// calibench export: a result (or a session's result) as a file a robot loads.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "app/commands.h"
#include "core/base/atomic_file.h"
#include "core/lidar_camera/rig.h"
#include "core/results/export.h"
#include "core/results/result_file.h"
#include "core/session/lrf_calibration_job.h"
#include "core/session/session.h"

namespace calibench::app {

namespace {

std::string FormatNames() {
  std::string names;
  for (const ExportFormat format : AllExportFormats())
    names += (names.empty() ? "" : " | ") + ExportFormatName(format);
  return names;
}

// A rig result (calibench.rig.v1): its tree, each camera's frame named after the camera.
int ExportRigResult(const std::string& result, ExportFormat format, const ExportFrames& frames,
                    const std::string& out) {
  std::vector<RigExportCamera> cameras;
  for (const auto& [name, cam_from_lidar] : LoadRigResult(result))
    cameras.push_back({name, cam_from_lidar});
  ExportedCalibration exported;
  try {
    exported = ExportRig(format, cameras, frames, std::filesystem::path(result).filename());
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "calibench export: %s\n", e.what());
    return kUsage;
  }
  const std::filesystem::path path =
      out.empty() ? std::filesystem::absolute(result).parent_path() / DefaultExportFileName(format)
                  : std::filesystem::path(out);
  WriteFileAtomically(path, exported.text);
  std::printf("wrote %s (%s): %zu cameras in '%s', camera frames %s\n", path.c_str(),
              ExportFormatName(format).c_str(), cameras.size(), frames.lidar.c_str(),
              CameraFrameName(frames.camera_frame).c_str());
  if (!exported.command.empty()) std::printf("%s\n", exported.command.c_str());
  return kOk;
}

}  // namespace

Pose CalibrationOf(const std::filesystem::path& path) {
  if (!IsSessionFile(path)) return LoadResult(path).cam_from_source;
  const Session session = LoadSession(path);
  if (!session.result)
    throw IoError(path.string() +
                  ": the session has no result yet (press Run in the workbench, "
                  "or `calibench calibrate --session`)");
  return session.result->cam_from_lidar;
}

int RunExport(int argc, char** argv) {
  CLI::App app{
      "Write a calibration in a form a robot loads: a URDF joint, a ROS 1 or ROS 2 static "
      "transform (launch file and command line), OpenCV YAML, Autoware's "
      "sensor_kit_calibration.yaml, a Kalibr-style chain, or a plain 4x4 matrix. Each "
      "file holds the child's pose in the parent frame and says so in words.",
      "calibench export"};
  std::string result, format_name, out, camera_frame = "optical";
  ExportFrames frames;
  app.add_option("--result,-r", result, "calibench.result.v1 file, or a session with a result")
      ->required();
  app.add_option("--format,-f", format_name, FormatNames())->required();
  std::string parent_frame, child_frame;
  app.add_option("--parent-frame", parent_frame,
                 "the parent frame's name (the LiDAR's: default lidar, or lrf for an LRF result; "
                 "with --swap the camera's: default camera)");
  app.add_option("--child-frame", child_frame,
                 "the child frame's name (the camera's: default camera; with --swap the "
                 "sensor's)");
  app.add_flag("--swap", frames.camera_is_parent,
               "the camera is the parent and the LiDAR the child (--parent-frame then names the "
               "camera's frame and --child-frame the LiDAR's)");
  app.add_option("--camera-frame", camera_frame,
                 "optical (z forward, x right, y down: what the calibration computes) or link "
                 "(REP 103: x forward, y left, z up)")
      ->capture_default_str();
  app.add_option("--out,-o", out,
                 "file to write (default: the format's usual name next to the result)");
  if (const auto code = ParseFlags(app, argc, argv)) return *code;
  // The names given go to the roles --swap assigns; those not given keep their frame's name (an
  // LRF result's sensor frame is the LRF's).
  if (IsLrfResultFile(result) || IsLrfSession(result)) frames.lidar = "lrf";
  std::string& parent = frames.camera_is_parent ? frames.camera : frames.lidar;
  std::string& child = frames.camera_is_parent ? frames.lidar : frames.camera;
  if (app.count("--parent-frame")) parent = parent_frame;
  if (app.count("--child-frame")) child = child_frame;
  const auto format = ParseExportFormat(format_name);
  const auto camera = ParseCameraFrame(camera_frame);
  std::string why;
  if (!format || !camera || !frames.Check(&why)) {
    std::fprintf(
        stderr, "calibench export: %s\n",
        !format   ? ("--format must be " + FormatNames() + ", got '" + format_name + "'").c_str()
        : !camera ? ("--camera-frame must be optical or link, got '" + camera_frame + "'").c_str()
                  : why.c_str());
    return kUsage;
  }
  frames.camera_frame = *camera;
  if (IsRigResultFile(result)) return ExportRigResult(result, *format, frames, out);
  const Pose cam_from_lidar = CalibrationOf(result);
  if (!IsSessionFile(result)) frames.camera_minus_lidar_s = LoadResult(result).camera_minus_lidar_s;
  const ExportedCalibration exported =
      ExportCalibration(*format, cam_from_lidar, frames, std::filesystem::path(result).filename());
  const std::filesystem::path path =
      out.empty() ? std::filesystem::absolute(result).parent_path() / DefaultExportFileName(*format)
                  : std::filesystem::path(out);
  WriteFileAtomically(path, exported.text);
  std::printf("wrote %s (%s): the pose of '%s' in '%s', camera frame %s\n", path.c_str(),
              ExportFormatName(*format).c_str(), frames.child().c_str(), frames.parent().c_str(),
              CameraFrameName(frames.camera_frame).c_str());
  if (!exported.command.empty()) std::printf("%s\n", exported.command.c_str());
  return kOk;
}

}  // namespace calibench::app
