#include "core/session/feature_cache.h"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <system_error>

namespace calibench {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// v2: the LiDAR fits carry their ring-bias covariance, what their rings' ends showed and their
// noise model. v4: their range residuals' sums (the LiDAR's noise is learned from them).
// v5: a ring-less cloud's fit under the other candidate model (LidarPlaneFit::alternative).
// v6: each inlier's time (LidarPlaneFit::inlier_times_s).
constexpr const char* kFeatureCacheFormat = "calibench.features.v6";

// A matrix as its rows, flattened row by row.
template <typename Matrix>
json MatrixToJson(const Matrix& m) {
  json values = json::array();
  for (int r = 0; r < m.rows(); ++r)
    for (int c = 0; c < m.cols(); ++c) values.push_back(m(r, c));
  return values;
}
template <typename Matrix>
void MatrixFromJson(const json& values, Matrix* m) {
  if (!values.is_array() || values.size() != static_cast<size_t>(m->rows() * m->cols()))
    throw std::invalid_argument("matrix of the wrong size");
  for (int r = 0; r < m->rows(); ++r)
    for (int c = 0; c < m->cols(); ++c)
      (*m)(r, c) = values.at(r * m->cols() + c).template get<double>();
}

json PlaneToJson(const Plane& plane) { return MatrixToJson(plane.Coefficients()); }
Plane PlaneFromJson(const json& values) {
  Vec4 c;
  MatrixFromJson(values, &c);
  return Plane::FromCoefficients(c);
}

// The file's identity: size and modification time (nanoseconds); nullopt when unreadable.
std::optional<std::pair<std::uintmax_t, std::int64_t>> FileStamp(const fs::path& path) {
  std::error_code error;
  const std::uintmax_t size = fs::file_size(path, error);
  if (error) return std::nullopt;
  const auto time = fs::last_write_time(path, error);
  if (error) return std::nullopt;
  return std::make_pair(
      size,
      static_cast<std::int64_t>(
          std::chrono::duration_cast<std::chrono::nanoseconds>(time.time_since_epoch()).count()));
}

json StampJson(const fs::path& path) {
  const auto stamp = FileStamp(path);
  if (!stamp) return nullptr;
  return {{"path", path.string()}, {"size", stamp->first}, {"mtime_ns", stamp->second}};
}

// The fit's range-residual sums (core/target/lidar_noise.h); null when it was not fitted along
// its rays (count 0: no finite smallest z to write).
json MomentsToJson(const RangeResidualMoments& m) {
  if (m.count == 0) return nullptr;
  return {m.count, m.sum_z, m.sum_zz, m.sum_e2, m.sum_z_e2, m.min_z, m.max_z};
}

RangeResidualMoments MomentsFromJson(const json& j) {
  RangeResidualMoments m;
  if (j.is_null()) return m;
  m.count = j.at(0).get<int>();
  m.sum_z = j.at(1).get<double>();
  m.sum_zz = j.at(2).get<double>();
  m.sum_e2 = j.at(3).get<double>();
  m.sum_z_e2 = j.at(4).get<double>();
  m.min_z = j.at(5).get<double>();
  m.max_z = j.at(6).get<double>();
  return m;
}

json LidarToJson(const LidarPlaneFit& fit) {
  json edges = json::array();
  for (const LidarEdgePoint& e : fit.edge_points)
    edges.push_back({MatrixToJson(e.point), MatrixToJson(e.along_ring), e.sigma_along_m});
  return {
      {"alternative", fit.alternative ? LidarToJson(*fit.alternative) : json(nullptr)},
      {"range_moments", MomentsToJson(fit.range_moments)},
      {"plane", PlaneToJson(fit.plane)},
      {"covariance", MatrixToJson(fit.covariance)},
      {"inliers", fit.inliers},
      {"inlier_times_s", fit.inlier_times_s},
      {"inlier_centroid", MatrixToJson(fit.inlier_centroid)},
      {"num_candidates", fit.num_candidates},
      {"grown", fit.grown},
      {"range_offset_jacobian", MatrixToJson(fit.range_offset_jacobian)},
      {"edge_points", edges},
      {"sheet_size_m", MatrixToJson(fit.sheet_size_m)},
      {"rms_m", fit.rms_m},
      {"num_rings", fit.num_rings},
      {"ring_bias_covariance", MatrixToJson(fit.ring_bias_covariance)},
      {"edge_ends",
       {fit.edge_ends.ends, fit.edge_ends.edge_points, fit.edge_ends.no_return,
        fit.edge_ends.not_behind}},
      {"no_edge_search", fit.no_edge_search},
      {"lidar_model",
       {LidarGeometryName(fit.lidar_model.geometry), fit.lidar_model.why, fit.lidar_model.forced}}};
}

LidarPlaneFit LidarFromJson(const json& j) {
  LidarPlaneFit fit;
  fit.plane = PlaneFromJson(j.at("plane"));
  MatrixFromJson(j.at("covariance"), &fit.covariance);
  fit.inliers = j.at("inliers").get<std::vector<int>>();
  fit.inlier_times_s = j.at("inlier_times_s").get<std::vector<float>>();
  if (!fit.inlier_times_s.empty() && fit.inlier_times_s.size() != fit.inliers.size())
    throw std::invalid_argument("inlier times do not match the inliers");
  MatrixFromJson(j.at("inlier_centroid"), &fit.inlier_centroid);
  fit.num_candidates = j.at("num_candidates").get<int>();
  fit.grown = j.at("grown").get<bool>();
  MatrixFromJson(j.at("range_offset_jacobian"), &fit.range_offset_jacobian);
  fit.range_moments = MomentsFromJson(j.at("range_moments"));
  for (const json& e : j.at("edge_points")) {
    LidarEdgePoint point;
    MatrixFromJson(e.at(0), &point.point);
    MatrixFromJson(e.at(1), &point.along_ring);
    point.sigma_along_m = e.at(2).get<double>();
    fit.edge_points.push_back(point);
  }
  MatrixFromJson(j.at("sheet_size_m"), &fit.sheet_size_m);
  fit.rms_m = j.at("rms_m").get<double>();
  fit.num_rings = j.at("num_rings").get<int>();
  MatrixFromJson(j.at("ring_bias_covariance"), &fit.ring_bias_covariance);
  const json& ends = j.at("edge_ends");
  fit.edge_ends = {ends.at(0).get<int>(), ends.at(1).get<int>(), ends.at(2).get<int>(),
                   ends.at(3).get<int>()};
  fit.no_edge_search = j.at("no_edge_search").get<std::string>();
  const json& model = j.at("lidar_model");
  const auto geometry = ParseLidarGeometry(model.at(0).get<std::string>());
  if (!geometry) throw std::invalid_argument("unknown LiDAR model");
  fit.lidar_model = {*geometry, model.at(1).get<std::string>(), model.at(2).get<bool>()};
  if (const json& other = j.at("alternative"); !other.is_null())
    fit.alternative = std::make_shared<const LidarPlaneFit>(LidarFromJson(other));
  return fit;
}

// Per corner [id, u, v, x, y, z]: the pixel and the board point.
json CornersToJson(const BoardDetection& corners) {
  json all = json::array();
  for (size_t k = 0; k < corners.pixels.size(); ++k) {
    const Vec2& u = corners.pixels[k];
    const Vec3& p = corners.board_points[k];
    all.push_back(
        {k < corners.ids.size() ? corners.ids[k] : -1, u.x(), u.y(), p.x(), p.y(), p.z()});
  }
  return all;
}

BoardDetection CornersFromJson(const json& j) {
  BoardDetection corners;
  for (const json& c : j) {
    corners.ids.push_back(c.at(0).get<int>());
    corners.pixels.emplace_back(c.at(1).get<double>(), c.at(2).get<double>());
    corners.board_points.emplace_back(c.at(3).get<double>(), c.at(4).get<double>(),
                                      c.at(5).get<double>());
  }
  return corners;
}

json CameraToJson(const CameraBoardObservation& camera) {
  return {{"cam_from_board", MatrixToJson(camera.cam_from_board.matrix())},
          {"pose_covariance", MatrixToJson(camera.pose_covariance)},
          {"plane", PlaneToJson(camera.plane)},
          {"plane_covariance", MatrixToJson(camera.plane_covariance)},
          {"reprojection_rms_px", camera.reprojection_rms_px},
          {"corner_sigma_px", camera.corner_sigma_px},
          {"num_corners", camera.num_corners},
          {"corners", CornersToJson(camera.corners)}};
}

CameraBoardObservation CameraFromJson(const json& j) {
  CameraBoardObservation camera;
  Mat4 pose;
  MatrixFromJson(j.at("cam_from_board"), &pose);
  camera.cam_from_board = Pose(pose);
  MatrixFromJson(j.at("pose_covariance"), &camera.pose_covariance);
  camera.plane = PlaneFromJson(j.at("plane"));
  MatrixFromJson(j.at("plane_covariance"), &camera.plane_covariance);
  camera.reprojection_rms_px = j.at("reprojection_rms_px").get<double>();
  camera.corner_sigma_px = j.at("corner_sigma_px").get<double>();
  camera.num_corners = j.at("num_corners").get<int>();
  camera.corners = CornersFromJson(j.at("corners"));
  return camera;
}

// The pair's line; throws on anything missing or malformed.
CachedPair PairFromJson(const json& j) {
  if (j.at("format").get<std::string>() != kFeatureCacheFormat)
    throw std::invalid_argument("format");
  CachedPair cached;
  PairFeatures& f = cached.features;
  f.id = j.at("id").get<std::string>();
  const auto status = ParsePairStatus(j.at("status").get<std::string>());
  if (!status) throw std::invalid_argument("status");
  f.status = *status;
  f.reason = j.at("reason").get<std::string>();
  f.input_error = j.at("input_error").get<bool>();
  if (!j.at("lidar").is_null()) f.lidar = LidarFromJson(j.at("lidar"));
  if (!j.at("camera").is_null()) f.camera = CameraFromJson(j.at("camera"));
  const int source = j.at("board_source").get<int>();
  if (source < 0 || source > static_cast<int>(BoardSource::kCameraGuided))
    throw std::invalid_argument("board_source");
  f.board_origin.source = static_cast<BoardSource>(source);
  f.board_origin.confidence = j.at("board_confidence").get<double>();
  f.board_origin.detail = j.at("board_detail").get<std::string>();
  if (!j.at("edge_width_px").is_null()) f.edge_width_px = j.at("edge_width_px").get<double>();
  cached.entry.id = f.id;
  // The files must be the ones the features came from, unchanged.
  for (const char* which : {"cloud", "image"}) {
    const json& stamp = j.at(which);
    const fs::path path = stamp.at("path").get<std::string>();
    const auto now = FileStamp(path);
    if (!now || now->first != stamp.at("size").get<std::uintmax_t>() ||
        now->second != stamp.at("mtime_ns").get<std::int64_t>())
      throw std::invalid_argument("file changed");
    (std::string(which) == "cloud" ? cached.entry.cloud : cached.entry.image) = path;
  }
  return cached;
}

}  // namespace

FeatureCacheWriter::FeatureCacheWriter(fs::path path) : path_(std::move(path)) {}

void FeatureCacheWriter::Append(const PairEntry& entry, const PairFeatures& f) {
  const json line = {{"format", kFeatureCacheFormat},
                     {"id", f.id},
                     {"status", PairStatusName(f.status)},
                     {"reason", f.reason},
                     {"input_error", f.input_error},
                     {"cloud", StampJson(entry.cloud)},
                     {"image", StampJson(entry.image)},
                     {"lidar", f.lidar ? LidarToJson(*f.lidar) : json(nullptr)},
                     {"camera", f.camera ? CameraToJson(*f.camera) : json(nullptr)},
                     {"board_source", static_cast<int>(f.board_origin.source)},
                     {"board_confidence", f.board_origin.confidence},
                     {"board_detail", f.board_origin.detail},
                     {"edge_width_px", f.edge_width_px ? json(*f.edge_width_px) : json(nullptr)}};
  // One write of the whole line, flushed: a kill leaves at most this line cut short.
  const std::string text = line.dump(-1, ' ', false, json::error_handler_t::replace) + "\n";
  std::FILE* file = std::fopen(path_.c_str(), "ab");
  if (!file) throw IoError(path_.string() + ": cannot open the feature cache for appending");
  const bool ok =
      std::fwrite(text.data(), 1, text.size(), file) == text.size() && std::fflush(file) == 0;
  std::fclose(file);
  if (!ok) throw IoError(path_.string() + ": cannot append to the feature cache (disk full?)");
}

std::map<std::string, CachedPair> LoadFeatureCache(const fs::path& path, int* skipped) {
  std::map<std::string, CachedPair> pairs;
  int bad = 0;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    try {
      CachedPair cached = PairFromJson(json::parse(line));
      const std::string id = cached.features.id;
      pairs[id] = std::move(cached);
    } catch (const std::exception&) {
      ++bad;  // cut short by a kill, from another version, or its files changed
    }
  }
  if (skipped) *skipped = bad;
  return pairs;
}

fs::path FeatureCachePath(const fs::path& session_path) {
  return session_path.parent_path() / (session_path.stem().string() + ".features.jsonl");
}

}  // namespace calibench
