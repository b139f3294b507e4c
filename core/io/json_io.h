// JSON helpers shared by the manifest readers (io/dataset.cpp, lrf/dataset.cpp) and the result
// writer (results/result_file.cpp); fields are read with json_fields.h. Internal: include it from
// .cpp files only (it pulls in nlohmann/json). Every reader throws IoError naming the file and the
// problem.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>

#include "core/base/types.h"
#include "core/camera/camera.h"
#include "core/io/dataset.h"
#include "core/io/json_fields.h"

namespace calibench::json_io {

using nlohmann::json;

[[noreturn]] void Fail(const std::filesystem::path& file, const std::string& problem);

// Calibench's JSON files nest a handful of levels; nlohmann's parser recurses, so text nested
// deeper than this is refused before it runs (100,000 levels would overflow the stack).
constexpr int kMaxJsonNesting = 64;
// Manifests, sessions, results and scans stay far below this (a 40-pair session with brushes is
// about 1 MB).
constexpr std::uintmax_t kMaxJsonBytes = 256ull << 20;

// Parses a JSON file; IoError when missing, unreadable, larger than max_bytes, nested deeper
// than kMaxJsonNesting, or not JSON.
json ReadJson(const std::filesystem::path& path, std::uintmax_t max_bytes = kMaxJsonBytes);
// IoError naming `path` when `text` nests arrays and objects deeper than kMaxJsonNesting.
void CheckJsonNesting(const std::filesystem::path& path, std::string_view text);

// IoError "<what>: <why>" naming the file unless spec.Check(&why) passes (targets, intrinsics).
template <typename Spec>
void CheckOrFail(const Spec& spec, const std::filesystem::path& file, const std::string& what) {
  std::string why;
  if (!spec.Check(&why)) Fail(file, what + ": " + why);
}

// The pinhole fields of an intrinsics object (CameraModel, DepthIntrinsics): width and height
// (pixels), fx, fy, cx, cy (pixels), read from `node` and written back.
template <typename Intrinsics>
void GetPinhole(const Fields& node, Intrinsics* in) {
  in->width = node.Int("width");
  in->height = node.Int("height");
  in->fx = node.Number("fx");
  in->fy = node.Number("fy");
  in->cx = node.Number("cx");
  in->cy = node.Number("cy");
}
template <typename Intrinsics>
json PinholeToJson(const Intrinsics& in) {
  return {{"width", in.width}, {"height", in.height}, {"fx", in.fx},
          {"fy", in.fy},       {"cx", in.cx},         {"cy", in.cy}};
}

// A manifest's "format"; IoError "format is '<found>', expected '<expected>'".
void CheckFormat(const Fields& root, const std::string& expected);
// A manifest's "pairs"; IoError "missing array 'pairs'".
const json& PairsArray(const Fields& root);
// Records a pair id; IoError "pair id '<id>' appears twice" when `seen` holds it already.
void CheckUniquePairId(const std::string& id, std::set<std::string>* seen,
                       const std::filesystem::path& manifest);
// root[group][key] as a rigid transform (PoseFromJson, named "<group>.<key>"); nullopt when
// either is absent.
std::optional<Pose> OptionalPose(const Fields& root, const char* group, const char* key);

// A manifest pair's optional "lidar_seed": {"point": [x, y, z], "radius" > 0} (metres).
std::optional<LidarSeed> ParseLidarSeed(const Fields& pair);

// An absolute path, or one relative to base_dir.
std::filesystem::path Resolve(const std::filesystem::path& base_dir, const std::string& path);

// The inline "camera" object of a manifest (model, size, focal lengths, centre, distortion).
CameraModel ParseInlineCamera(const Fields& camera);

// The manifest's camera: "camera_file" (OpenCV / ROS / Kalibr file), "camera": {"file": ...}, or
// an inline "camera" object; validated with CameraModel::Check.
CameraModel ParseManifestCamera(const Fields& root);
// The inline form ParseInlineCamera reads.
json CameraToJson(const CameraModel& camera);

// A path as a manifest stores it: relative to the manifest's folder when it lies under it,
// absolute otherwise.
std::string PathForManifest(const std::filesystem::path& path,
                            const std::filesystem::path& manifest);

// A "target" object: checkerboard (inner_corners) or charuco (squares, marker_size,
// dictionary), square_size, optional board_size; validated with BoardSpec::Check.
BoardSpec ParseTarget(const Fields& target);
json TargetToJson(const BoardSpec& board);

// A 4x4 rigid transform as rows. RigidMatrixFromJson checks orthonormality (1e-4) and the last
// row and returns the numbers as written; PoseFromJson also projects onto the nearest rotation.
json MatrixToJson(const Mat4& m);
Mat4 RigidMatrixFromJson(const json& node, const std::filesystem::path& file,
                         const std::string& name);
Pose PoseFromJson(const json& node, const std::filesystem::path& file, const std::string& name);

// The result file's form of a transform: matrix, translation_m, quaternion_xyzw.
json PoseToResultJson(const Pose& pose);

}  // namespace calibench::json_io
