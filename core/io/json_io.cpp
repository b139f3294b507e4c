#include "core/io/json_io.h"

#include <algorithm>
#include <fstream>

#include "core/geometry/geometry.h"
#include "core/io/camera_file.h"

namespace calibench::json_io {
namespace fs = std::filesystem;

[[noreturn]] void Fail(const fs::path& file, const std::string& problem) {
  throw IoError(file.string() + ": " + problem);
}

json ReadJson(const fs::path& path) {
  if (!fs::exists(path)) Fail(path, "no such file");
  std::ifstream in(path);
  if (!in) Fail(path, "cannot open file");
  try {
    return json::parse(in);
  } catch (const json::exception& e) {
    Fail(path, std::string("not valid JSON: ") + e.what());
  }
}

const json& Field(const json& node, const char* key, const fs::path& file,
                  const std::string& where) {
  if (!node.is_object() || !node.contains(key)) Fail(file, "missing field '" + where + key + "'");
  return node.at(key);
}

void CheckFormat(const json& root, const std::string& expected, const fs::path& manifest) {
  const std::string format = root.value("format", "");
  if (format != expected) Fail(manifest, "format is '" + format + "', expected '" + expected + "'");
}

const json& PairsArray(const json& root, const fs::path& manifest) {
  if (!root.contains("pairs") || !root.at("pairs").is_array())
    Fail(manifest, "missing array 'pairs'");
  return root.at("pairs");
}

void CheckUniquePairId(const std::string& id, std::set<std::string>* seen,
                       const fs::path& manifest) {
  if (!seen->insert(id).second) Fail(manifest, "pair id '" + id + "' appears twice");
}

std::optional<Pose> OptionalPose(const json& root, const char* group, const char* key,
                                 const fs::path& manifest) {
  if (!root.contains(group) || !root.at(group).is_object() || !root.at(group).contains(key))
    return std::nullopt;
  return PoseFromJson(root.at(group).at(key), manifest, std::string(group) + "." + key);
}

fs::path Resolve(const fs::path& base_dir, const std::string& p) {
  const fs::path path(p);
  return path.is_absolute() ? path : (base_dir / path).lexically_normal();
}

CameraModel ParseInlineCamera(const json& node, const fs::path& file) {
  CameraModel camera;
  const std::string model = Get<std::string>(node, "model", file, "camera.");
  const auto type = ParseCameraModelName(model);
  if (!type)
    Fail(file, "camera.model '" + model + "' is unknown (use pinhole-radtan or kannala-brandt)");
  camera.type = *type;
  GetPinhole(node, file, "camera.", &camera);
  camera.distortion = Get<std::vector<double>>(node, "distortion", file, "camera.");
  return camera;
}

BoardSpec ParseTarget(const json& node, const fs::path& file) {
  BoardSpec board;
  const std::string type = Get<std::string>(node, "type", file, "target.");
  if (type == "checkerboard") {
    board.type = BoardType::kCheckerboard;
    const auto corners = Get<std::vector<int>>(node, "inner_corners", file, "target.");
    if (corners.size() != 2) Fail(file, "target.inner_corners must be [cols, rows]");
    board.cols = corners[0];
    board.rows = corners[1];
  } else if (type == "charuco") {
    board.type = BoardType::kCharuco;
    const auto squares = Get<std::vector<int>>(node, "squares", file, "target.");
    if (squares.size() != 2) Fail(file, "target.squares must be [cols, rows]");
    board.cols = squares[0];
    board.rows = squares[1];
    board.marker_size = Get<double>(node, "marker_size", file, "target.");
    board.dictionary = Get<std::string>(node, "dictionary", file, "target.");
  } else {
    Fail(file, "target.type '" + type + "' is unknown (use checkerboard or charuco)");
  }
  board.square_size = Get<double>(node, "square_size", file, "target.");
  if (node.contains("board_size")) {
    const auto size = Get<std::vector<double>>(node, "board_size", file, "target.");
    if (size.size() != 2) Fail(file, "target.board_size must be [width, height] in metres");
    board.board_width = size[0];
    board.board_height = size[1];
  }
  CheckOrFail(board, file, "target");
  return board;
}

json TargetToJson(const BoardSpec& board) {
  json t;
  if (board.type == BoardType::kCheckerboard) {
    t["type"] = "checkerboard";
    t["inner_corners"] = {board.cols, board.rows};
  } else {
    t["type"] = "charuco";
    t["squares"] = {board.cols, board.rows};
    t["marker_size"] = board.marker_size;
    t["dictionary"] = board.dictionary;
  }
  t["square_size"] = board.square_size;
  if (board.board_width > 0) t["board_size"] = {board.board_width, board.board_height};
  return t;
}

json MatrixToJson(const Mat4& m) {
  json rows = json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
  return rows;
}

Pose PoseFromJson(const json& node, const fs::path& file, const std::string& name) {
  std::vector<std::vector<double>> rows;
  try {
    rows = node.get<std::vector<std::vector<double>>>();
  } catch (const json::exception&) {
    Fail(file, name + " must be a 4x4 matrix of numbers");
  }
  if (rows.size() != 4 ||
      std::any_of(rows.begin(), rows.end(), [](auto& r) { return r.size() != 4; }))
    Fail(file, name + " must be a 4x4 matrix");
  Mat4 m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = rows[r][c];
  const Mat3 rotation = m.topLeftCorner<3, 3>();
  if (!m.allFinite() || (rotation * rotation.transpose() - Mat3::Identity()).norm() > 1e-4 ||
      rotation.determinant() < 0 || (m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9)
    Fail(file,
         name + " is not a rigid transform (rotation not orthonormal or last row not 0 0 0 1)");
  Pose pose = Pose::Identity();
  pose.linear() = NearestRotation(rotation);
  pose.translation() = m.topRightCorner<3, 1>();
  return pose;
}

json PoseToResultJson(const Pose& pose) {
  json m = json::array();
  for (int r = 0; r < 4; ++r)
    m.push_back(
        {pose.matrix()(r, 0), pose.matrix()(r, 1), pose.matrix()(r, 2), pose.matrix()(r, 3)});
  const Eigen::Quaterniond q(pose.linear());
  return {
      {"matrix", m},
      {"translation_m", {pose.translation().x(), pose.translation().y(), pose.translation().z()}},
      {"quaternion_xyzw", {q.x(), q.y(), q.z(), q.w()}}};
}

CameraModel ParseManifestCamera(const json& root, const fs::path& manifest) {
  const fs::path base = manifest.parent_path();
  CameraModel camera;
  if (root.contains("camera_file")) {
    camera = LoadCameraFile(Resolve(base, Get<std::string>(root, "camera_file", manifest, "")));
  } else if (root.contains("camera")) {
    const json& cam = root.at("camera");
    camera = cam.contains("file")
                 ? LoadCameraFile(Resolve(base, Get<std::string>(cam, "file", manifest, "camera.")))
                 : ParseInlineCamera(cam, manifest);
  } else {
    Fail(manifest, "neither 'camera' nor 'camera_file' is given");
  }
  CheckOrFail(camera, manifest, "camera");
  return camera;
}

json CameraToJson(const CameraModel& c) {
  json camera = PinholeToJson(c);
  camera["model"] = CameraModelName(c.type);
  camera["distortion"] = c.distortion;
  return camera;
}

std::string PathForManifest(const fs::path& path, const fs::path& manifest) {
  const fs::path base = fs::absolute(manifest).parent_path();
  const fs::path rel = fs::absolute(path).lexically_relative(base);
  return (rel.empty() || *rel.begin() == "..") ? fs::absolute(path).string() : rel.string();
}

}  // namespace calibench::json_io
