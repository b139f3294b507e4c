// JSON helpers shared by the manifest readers (dataset.cpp, lrf_dataset.cpp) and the result
// writers (result_io.cpp, lrf_pipeline.cpp). Internal: include it from .cpp files only (it pulls
// in nlohmann/json). Every reader throws IoError naming the file and the problem.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "core/base/types.h"
#include "core/camera/camera.h"
#include "core/io/dataset.h"

namespace calibench::json_io {

using nlohmann::json;

[[noreturn]] void Fail(const std::filesystem::path& file, const std::string& problem);

// Parses a JSON file; IoError when missing, unreadable or not JSON.
json ReadJson(const std::filesystem::path& path);

// node[key] as T; IoError "missing field '<where><key>'" or "has the wrong type".
template <typename T>
T Get(const json& node, const char* key, const std::filesystem::path& file,
      const std::string& where) {
  if (!node.is_object() || !node.contains(key)) Fail(file, "missing field '" + where + key + "'");
  try {
    return node.at(key).get<T>();
  } catch (const json::exception& e) {
    Fail(file, "field '" + where + key + "' has the wrong type: " + e.what());
  }
}

// An absolute path, or one relative to base_dir.
std::filesystem::path Resolve(const std::filesystem::path& base_dir, const std::string& path);

// The inline "camera" object of a manifest (model, size, focal lengths, centre, distortion).
CameraModel ParseInlineCamera(const json& node, const std::filesystem::path& file);

// The manifest's camera: "camera_file" (OpenCV / ROS / Kalibr file), "camera": {"file": ...}, or
// an inline "camera" object; validated with CameraModel::Check.
CameraModel ParseManifestCamera(const json& root, const std::filesystem::path& manifest);
// The inline form ParseInlineCamera reads.
json CameraToJson(const CameraModel& camera);

// A path as a manifest stores it: relative to the manifest's folder when it lies under it,
// absolute otherwise.
std::string PathForManifest(const std::filesystem::path& path,
                            const std::filesystem::path& manifest);

// A "target" object: checkerboard (inner_corners) or charuco (squares, marker_size,
// dictionary), square_size, optional board_size; validated with BoardSpec::Check.
BoardSpec ParseTarget(const json& node, const std::filesystem::path& file);
json TargetToJson(const BoardSpec& board);

// A 4x4 rigid transform as rows; PoseFromJson checks orthonormality and the last row.
json MatrixToJson(const Mat4& m);
Pose PoseFromJson(const json& node, const std::filesystem::path& file, const std::string& name);

// The result file's form of a transform: matrix, translation_m, quaternion_xyzw.
json PoseToResultJson(const Pose& pose);

}  // namespace calibench::json_io
