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

json ReadJson(const fs::path& path, std::uintmax_t max_bytes) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (status.type() == fs::file_type::not_found) Fail(path, "no such file");
  if (ec) Fail(path, "cannot read: " + ec.message());
  if (fs::is_directory(status)) Fail(path, "is a folder, not a JSON file");
  if (!fs::is_regular_file(status)) Fail(path, "is not a regular file (a FIFO or a device?)");
  const std::uintmax_t size = fs::file_size(path, ec);
  if (!ec && size > max_bytes)
    Fail(path, std::to_string(size) + " bytes is over the limit of " + std::to_string(max_bytes) +
                   " for this kind of JSON file");
  std::ifstream in(path, std::ios::binary);
  if (!in) Fail(path, "cannot open file");
  std::string text(static_cast<size_t>(size), '\0');
  in.read(text.data(), static_cast<std::streamsize>(size));
  text.resize(static_cast<size_t>(in.gcount()));
  CheckJsonNesting(path, text);
  try {
    return json::parse(text);
  } catch (const json::exception& e) {
    Fail(path, std::string("not valid JSON: ") + e.what());
  }
}

void CheckJsonNesting(const fs::path& path, std::string_view text) {
  int depth = 0;
  bool in_string = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\')
        ++i;  // an escaped character, a quote included
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonNesting)
        Fail(path,
             "nested deeper than " + std::to_string(kMaxJsonNesting) +
                 " levels; no Calibench file is (refused before parsing: the parser recurses)");
    } else if (c == ']' || c == '}') {
      depth = std::max(0, depth - 1);
    }
  }
}

void CheckFormat(const Fields& root, const std::string& expected) {
  const std::string format = root.Has("format") && root.At("format").is_string()
                                 ? root.String("format")
                                 : std::string("missing");
  if (format != expected)
    Fail(root.file(), "format is '" + format + "', expected '" + expected + "'");
}

const json& PairsArray(const Fields& root) { return root.Array("pairs"); }

void CheckUniquePairId(const std::string& id, std::set<std::string>* seen,
                       const fs::path& manifest) {
  if (!seen->insert(id).second) Fail(manifest, "pair id '" + id + "' appears twice");
}

std::optional<Pose> OptionalPose(const Fields& root, const char* group, const char* key) {
  if (!root.Has(group)) return std::nullopt;
  const Fields poses = root.Object(group);
  if (!poses.Has(key)) return std::nullopt;
  return PoseFromJson(poses.At(key), root.file(), poses.Path(key));
}

fs::path Resolve(const fs::path& base_dir, const std::string& p) {
  const fs::path path(p);
  return path.is_absolute() ? path : (base_dir / path).lexically_normal();
}

CameraModel ParseInlineCamera(const Fields& node) {
  CameraModel camera;
  const std::string model = node.String("model");
  const auto type = ParseCameraModelName(model);
  if (!type)
    node.Fail("model", "'" + model + "' is unknown (use pinhole-radtan or kannala-brandt)");
  camera.type = *type;
  GetPinhole(node, &camera);
  camera.distortion = node.Get<std::vector<double>>("distortion");
  if (node.Has("intrinsics_covariance"))
    camera.covariance = node.Get<std::vector<double>>("intrinsics_covariance");
  return camera;
}

BoardSpec ParseTarget(const Fields& node) {
  BoardSpec board;
  const std::string type = node.String("type");
  auto pair_of_ints = [&](const char* key) {
    const auto values = node.Get<std::vector<int>>(key);
    if (values.size() != 2) node.Fail(key, "must be [cols, rows]");
    return values;
  };
  if (type == "checkerboard") {
    board.type = BoardType::kCheckerboard;
    const auto corners = pair_of_ints("inner_corners");
    board.cols = corners[0];
    board.rows = corners[1];
  } else if (type == "charuco") {
    board.type = BoardType::kCharuco;
    const auto squares = pair_of_ints("squares");
    board.cols = squares[0];
    board.rows = squares[1];
    board.marker_size = node.Number("marker_size");
    board.dictionary = node.String("dictionary");
  } else {
    node.Fail("type", "'" + type + "' is unknown (use checkerboard or charuco)");
  }
  board.square_size = node.Number("square_size");
  if (node.Has("board_size")) {
    const auto size = node.Get<std::vector<double>>("board_size");
    if (size.size() != 2) node.Fail("board_size", "must be [width, height] in metres");
    board.board_width = size[0];
    board.board_height = size[1];
  }
  CheckOrFail(board, node.file(), "target");
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

Mat4 RigidMatrixFromJson(const json& node, const fs::path& file, const std::string& name) {
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
  return m;
}

Pose PoseFromJson(const json& node, const fs::path& file, const std::string& name) {
  const Mat4 m = RigidMatrixFromJson(node, file, name);
  Pose pose = Pose::Identity();
  pose.linear() = NearestRotation(m.topLeftCorner<3, 3>());
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

std::optional<LidarSeed> ParseLidarSeed(const Fields& p) {
  if (!p.Has("lidar_seed")) return std::nullopt;
  const Fields s = p.Object("lidar_seed");
  const auto point = s.Get<std::vector<double>>("point");
  if (point.size() != 3) s.Fail("point", "must be [x, y, z]");
  LidarSeed seed{Vec3(point[0], point[1], point[2]), s.Number("radius")};
  if (!(seed.radius > 0) || !seed.point.allFinite())
    p.Fail("lidar_seed", "needs a finite point and a radius > 0");
  return seed;
}

CameraModel ParseManifestCamera(const Fields& root) {
  const fs::path base = root.file().parent_path();
  CameraModel camera;
  if (root.Has("camera_file")) {
    camera = LoadCameraFile(Resolve(base, root.String("camera_file")));
  } else if (root.Has("camera")) {
    const Fields cam = root.Object("camera");
    camera = cam.Has("file") ? LoadCameraFile(Resolve(base, cam.String("file")))
                             : ParseInlineCamera(cam);
  } else {
    Fail(root.file(), "neither 'camera' nor 'camera_file' is given");
  }
  CheckOrFail(camera, root.file(), "camera");
  return camera;
}

json CameraToJson(const CameraModel& c) {
  json camera = PinholeToJson(c);
  camera["model"] = CameraModelName(c.type);
  camera["distortion"] = c.distortion;
  if (!c.covariance.empty()) camera["intrinsics_covariance"] = c.covariance;
  return camera;
}

std::string PathForManifest(const fs::path& path, const fs::path& manifest) {
  const fs::path base = fs::absolute(manifest).parent_path();
  const fs::path rel = fs::absolute(path).lexically_relative(base);
  return (rel.empty() || *rel.begin() == "..") ? fs::absolute(path).string() : rel.string();
}

}  // namespace calibench::json_io
