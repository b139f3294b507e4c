#include "core/results/export_text.h"

#include <cstdio>

namespace calibench::export_text {

std::string Number(double value) {
  if (value == 0.0) value = 0.0;  // no "-0"
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  return buffer;
}

std::string Numbers(std::initializer_list<double> values, const char* separator) {
  std::string out;
  for (const double value : values) out += (out.empty() ? "" : separator) + Number(value);
  return out;
}

std::string CameraFrameWords(CameraFrame frame) {
  return frame == CameraFrame::kOptical
             ? "optical (z forward, x right, y down: the camera's image axes)"
             : "link (REP 103: x forward, y left, z up)";
}

std::vector<std::string> HeaderLines(const ExportFrames& frames, const std::string& source) {
  const std::string& parent = frames.parent();
  const std::string& child = frames.child();
  std::vector<std::string> lines = {
      "Calibench extrinsic calibration" + (source.empty() ? "" : " from " + source),
      "The pose of '" + child + "' in '" + parent + "': x_in_" + parent + " = " + parent +
          "_from_" + child + " * x_in_" + child + " (a point in " + child +
          " coordinates mapped into " + parent + " coordinates)",
      "The camera frame '" + frames.camera + "' is " + CameraFrameWords(frames.camera_frame)};
  if (frames.camera_minus_lidar_s) {
    char text[160];
    std::snprintf(text, sizeof(text),
                  "Time offset: the camera's stamps minus the LiDAR's clock %+.6f s (t_lidar = "
                  "t_camera %+.6f s)",
                  *frames.camera_minus_lidar_s, -*frames.camera_minus_lidar_s);
    lines.push_back(text);
  }
  return lines;
}

std::string Commented(const std::vector<std::string>& lines, const std::string& prefix) {
  std::string out;
  for (const std::string& line : lines) out += prefix + line + "\n";
  return out;
}

TransformText TextOf(const Pose& parent_from_child) {
  const Vec3 t = parent_from_child.translation();
  Eigen::Quaterniond q(parent_from_child.rotation());
  q.normalize();
  if (q.w() < 0) q.coeffs() *= -1.0;  // one of the two equal quaternions, always the same
  const Vec3 rpy = RollPitchYaw(parent_from_child.rotation());
  return {Number(t.x()), Number(t.y()), Number(t.z()),   Number(q.x()),   Number(q.y()),
          Number(q.z()), Number(q.w()), Number(rpy.x()), Number(rpy.y()), Number(rpy.z())};
}

std::string JointName(const ExportFrames& frames) {
  return frames.parent() + "_to_" + frames.child();
}

std::string MatrixRows(const Mat4& m, const char* indent) {
  std::string out;
  for (int r = 0; r < 4; ++r)
    out +=
        std::string(indent) + "- [" + Numbers({m(r, 0), m(r, 1), m(r, 2), m(r, 3)}, ", ") + "]\n";
  return out;
}

}  // namespace calibench::export_text
