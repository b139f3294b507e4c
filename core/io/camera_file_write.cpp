// SaveCameraFile: the OpenCV FileStorage and Kalibr forms (the ROS form is SaveCameraInfoYaml).
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>

#include "core/base/atomic_file.h"
#include "core/io/camera_file.h"

namespace calibench {
namespace {

std::string Numbers(const std::vector<double>& values) {
  std::string text;
  char number[40];
  for (size_t i = 0; i < values.size(); ++i) {
    std::snprintf(number, sizeof(number), "%.17g", values[i]);
    text += (i ? ", " : "") + std::string(number);
  }
  return text;
}

std::string OpenCvMatrix(const char* name, int rows, int cols, const std::vector<double>& data) {
  return std::string(name) + ": !!opencv-matrix\n   rows: " + std::to_string(rows) +
         "\n   cols: " + std::to_string(cols) + "\n   dt: d\n   data: [ " + Numbers(data) + " ]\n";
}

// What cv::FileStorage writes, so OpenCV's own tools read it too.
std::string OpenCvYaml(const CameraModel& c) {
  const bool fisheye = c.type == CameraModelType::kKannalaBrandt;
  return "%YAML:1.0\n---\nimage_width: " + std::to_string(c.width) +
         "\nimage_height: " + std::to_string(c.height) +
         "\ndistortion_model: " + (fisheye ? "equidistant" : "plumb_bob") + "\n" +
         OpenCvMatrix("camera_matrix", 3, 3, {c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1}) +
         OpenCvMatrix("distortion_coefficients", 1, static_cast<int>(c.distortion.size()),
                      c.distortion) +
         (c.covariance.empty()
              ? ""
              : OpenCvMatrix("intrinsics_covariance", static_cast<int>(4 + c.distortion.size()),
                             static_cast<int>(4 + c.distortion.size()), c.covariance));
}

std::string KalibrYaml(const std::filesystem::path& path, const CameraModel& c,
                       const std::string& topic) {
  const bool fisheye = c.type == CameraModelType::kKannalaBrandt;
  std::vector<double> coefficients = c.distortion;
  if (!fisheye) {
    if (coefficients.size() > 5 || (coefficients.size() == 5 && coefficients[4] != 0.0))
      throw IoError(path.string() +
                    ": Kalibr's radtan model has k1 k2 p1 p2 only; this camera has k3 = " +
                    Numbers({coefficients.size() > 4 ? coefficients[4] : 0.0}) +
                    " (estimate with k3 fixed at 0, or write --format ros or opencv)");
    coefficients.resize(4);
  }
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap << YAML::Key << "cam0" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "camera_model" << YAML::Value << "pinhole";
  out << YAML::Key << "intrinsics" << YAML::Value << YAML::Flow
      << std::vector<double>{c.fx, c.fy, c.cx, c.cy};
  out << YAML::Key << "distortion_model" << YAML::Value << (fisheye ? "equidistant" : "radtan");
  out << YAML::Key << "distortion_coeffs" << YAML::Value << YAML::Flow << coefficients;
  out << YAML::Key << "resolution" << YAML::Value << YAML::Flow
      << std::vector<int>{c.width, c.height};
  out << YAML::Key << "rostopic" << YAML::Value << topic;
  if (!c.covariance.empty()) {
    // fx fy cx cy k1 k2 p1 p2 (k3, zero, left out as above).
    const size_t n = 4 + c.distortion.size(), kept = 4 + coefficients.size();
    std::vector<double> covariance;
    for (size_t i = 0; i < kept; ++i)
      for (size_t j = 0; j < kept; ++j) covariance.push_back(c.covariance[i * n + j]);
    out << YAML::Key << "intrinsics_covariance" << YAML::Value << YAML::Flow << covariance;
  }
  out << YAML::EndMap << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace

std::optional<CameraFileFormat> ParseCameraFileFormat(const std::string& name) {
  if (name == "ros") return CameraFileFormat::kRosCameraInfo;
  if (name == "opencv") return CameraFileFormat::kOpenCv;
  if (name == "kalibr") return CameraFileFormat::kKalibr;
  return std::nullopt;
}

void SaveCameraFile(const std::filesystem::path& path, const CameraModel& camera,
                    CameraFileFormat format, const std::string& camera_name) {
  std::string why;
  if (!camera.Check(&why)) throw IoError(path.string() + ": cannot write the camera: " + why);
  switch (format) {
    case CameraFileFormat::kRosCameraInfo:
      SaveCameraInfoYaml(path, camera, camera_name);
      return;
    case CameraFileFormat::kOpenCv:
      WriteFileAtomically(path, OpenCvYaml(camera));
      return;
    case CameraFileFormat::kKalibr:
      WriteFileAtomically(path, KalibrYaml(path, camera, "/" + camera_name + "/image_raw"));
      return;
  }
}

}  // namespace calibench
