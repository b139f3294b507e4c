#include "core/lrf_data/dataset.h"

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>

#include "core/base/atomic_file.h"
#include "core/geometry/geometry.h"
#include "core/io/cloud_io.h"
#include "core/io/dataset_source.h"
#include "core/io/image_io.h"
#include "core/io/json_io.h"
#include "core/lidar/cloud.h"

namespace calibench {
namespace fs = std::filesystem;
using nlohmann::json;

using json_io::Fail;
using json_io::Fields;

namespace {

constexpr char kFormat[] = "calibench.lrf-dataset.v1";

ThreeFaceTarget ParseThreeFace(const Fields& node) {
  ThreeFaceTarget t;
  t.base_width = node.GetOr("base_width", t.base_width);
  t.base_height = node.GetOr("base_height", t.base_height);
  t.tent_half_width = node.GetOr("tent_half_width", t.tent_half_width);
  t.apex_y = node.GetOr("apex_y", t.apex_y);
  t.foot_y = node.GetOr("foot_y", t.foot_y);
  t.ridge_height = node.GetOr("ridge_height", t.ridge_height);
  json_io::CheckOrFail(t, node.file(), "target");
  return t;
}

json ThreeFaceToJson(const ThreeFaceTarget& t) {
  return {{"type", "three-face"},
          {"base_width", t.base_width},
          {"base_height", t.base_height},
          {"tent_half_width", t.tent_half_width},
          {"apex_y", t.apex_y},
          {"foot_y", t.foot_y},
          {"ridge_height", t.ridge_height}};
}

DepthIntrinsics ParseDepthCamera(const Fields& node) {
  DepthIntrinsics in;
  json_io::GetPinhole(node, &in);
  in.depth_scale = node.GetOr("depth_scale", in.depth_scale);
  json_io::CheckOrFail(in, node.file(), "depth_camera");
  return in;
}

json DepthCameraToJson(const DepthIntrinsics& in) {
  json camera = json_io::PinholeToJson(in);
  camera["depth_scale"] = in.depth_scale;
  return camera;
}

ScanRegion ParseScanRegion(const Fields& node) {
  ScanRegion region;
  region.angle_min = node.GetOr("angle_min_deg", -180.0) * kDegToRad;
  region.angle_max = node.GetOr("angle_max_deg", 180.0) * kDegToRad;
  region.range_min = node.GetOr("range_min", region.range_min);
  region.range_max = node.GetOr("range_max", region.range_max);
  if (!(region.angle_min < region.angle_max && region.range_min >= 0 &&
        region.range_min < region.range_max))
    json_io::FailAt(node.file(), node.where(),
                    "needs angle_min_deg < angle_max_deg and 0 <= range_min < range_max");
  return region;
}

// A pair's file, resolved against the manifest's folder. Existence is checked when the pair is
// loaded, so that one missing file fails its pair (named) and keeps the others.
fs::path PairFile(const Fields& p, const char* key) {
  return json_io::Resolve(p.file().parent_path(), p.String(key));
}

LrfPairEntry ParsePair(const Fields& p, LrfTargetType type) {
  LrfPairEntry pair;
  pair.id = p.String("id");
  pair.scan = PairFile(p, "scan");
  if (type == LrfTargetType::kThreeFace) {
    if (p.Has("depth") == p.Has("cloud"))
      Fail(p.file(), "pair " + pair.id + " needs exactly one of 'depth' (PNG) or 'cloud' (PCD)");
    if (p.Has("depth")) pair.depth = PairFile(p, "depth");
    if (p.Has("cloud")) pair.depth_cloud = PairFile(p, "cloud");
  } else {
    pair.image = PairFile(p, "image");
  }
  if (p.Has("scan_region")) pair.scan_region = ParseScanRegion(p.Object("scan_region"));
  return pair;
}

json ScanRegionToJson(const ScanRegion& region) {
  return {{"angle_min_deg", region.angle_min / kDegToRad},
          {"angle_max_deg", region.angle_max / kDegToRad},
          {"range_min", region.range_min},
          {"range_max", region.range_max}};
}

// Scan files ------------------------------------------------------------------------------------

double RangeFromJson(const json& value, const fs::path& file, size_t index) {
  if (value.is_null()) return std::numeric_limits<double>::quiet_NaN();
  if (value.is_number()) return value.get<double>();
  if (value.is_string()) {
    std::string text = value.get<std::string>();
    std::transform(text.begin(), text.end(), text.begin(), ::tolower);
    if (text == "inf" || text == "+inf" || text == "infinity")
      return std::numeric_limits<double>::infinity();
    if (text == "-inf") return -std::numeric_limits<double>::infinity();
    if (text == "nan") return std::numeric_limits<double>::quiet_NaN();
  }
  Fail(file,
       "ranges[" + std::to_string(index) + "] is neither a number, null, \"inf\" nor \"nan\"");
}

LaserScan LoadScanJson(const fs::path& path, const LoadLimits& limits) {
  // The file's size bounds its rays before it is parsed: a range takes at least 2 bytes ("1,").
  const json document = json_io::ReadJson(
      path, static_cast<std::uintmax_t>(limits.max_scan_points) * 32 + (64 << 10));
  const Fields root(document, path);
  LaserScan scan;
  scan.angle_min = root.Number("angle_min");
  scan.angle_increment = root.Number("angle_increment");
  scan.range_min = root.Number("range_min");
  scan.range_max = root.Number("range_max");
  const json& ranges = root.Array("ranges");
  if (ranges.empty()) Fail(path, "'ranges' is empty");
  CheckLoadLimit(path, "the number of ranges", static_cast<std::int64_t>(ranges.size()),
                 limits.max_scan_points, "max_scan_points");
  for (size_t i = 0; i < ranges.size(); ++i)
    scan.ranges.push_back(RangeFromJson(ranges[i], path, i));
  if (!std::isfinite(scan.angle_min) || !std::isfinite(scan.angle_increment) ||
      scan.angle_increment == 0.0)
    Fail(path, "angle_min must be finite and angle_increment finite and non-zero (radians)");
  if (!(scan.range_min >= 0 && scan.range_min < scan.range_max))
    Fail(path, "range_min and range_max must satisfy 0 <= range_min < range_max (metres)");
  return scan;
}

// A 2D PCD: the points are binned by angle into an evenly spaced scan (lrf_dataset.h).
LaserScan LoadScanPcd(const fs::path& path, const LoadLimits& limits) {
  LoadLimits scan_limits = limits;
  scan_limits.max_cloud_points = limits.max_scan_points;
  const LidarCloud cloud = LoadCloud(path, scan_limits);
  struct Return {
    double angle, range;
  };
  std::vector<Return> returns;
  for (const Eigen::Vector3f& p : cloud.points) {
    const double range = std::hypot(double(p.x()), double(p.y()));
    if (range < 1e-6) continue;  // (0, 0, 0) marks no return
    if (std::abs(p.z()) > 0.01)
      Fail(path, "not a 2D scan: a point has z = " + std::to_string(p.z()) + " (expected 0)");
    returns.push_back({std::atan2(double(p.y()), double(p.x())), range});
  }
  if (returns.size() < 2) Fail(path, "fewer than 2 valid points (points at the origin are none)");
  std::sort(returns.begin(), returns.end(),
            [](const Return& a, const Return& b) { return a.angle < b.angle; });
  std::vector<double> steps;
  for (size_t i = 1; i < returns.size(); ++i) {
    const double step = returns[i].angle - returns[i - 1].angle;
    if (step > 1e-9) steps.push_back(step);
  }
  if (steps.empty()) Fail(path, "all points lie at one angle");
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  LaserScan scan;
  scan.angle_min = returns.front().angle;
  scan.angle_increment = steps[steps.size() / 2];
  const double span = (returns.back().angle - scan.angle_min) / scan.angle_increment;
  // Angles that spread unevenly (a few returns far apart, two very close) would make a scan of
  // billions of bins.
  CheckLoadLimit(path, "the number of bins at the median angle step",
                 static_cast<std::int64_t>(std::min(span, 1e18)) + 1, limits.max_scan_points,
                 "max_scan_points");
  scan.ranges.assign(static_cast<size_t>(std::llround(span)) + 1,
                     std::numeric_limits<double>::quiet_NaN());
  // Real drivers jitter in angle (ACFR-RPG: 0.60–0.66° around a 0.71° median), so two returns can
  // round to one bin; the second then takes the neighbour it leans towards when that one is free.
  for (const Return& r : returns) {
    const double position = (r.angle - scan.angle_min) / scan.angle_increment;
    const long nearest = std::llround(position);
    const long other = position > nearest ? nearest + 1 : nearest - 1;
    long bin = nearest;
    if (!std::isnan(scan.ranges[nearest]) && other >= 0 &&
        other < static_cast<long>(scan.ranges.size()) && std::isnan(scan.ranges[other]))
      bin = other;
    if (std::isnan(scan.ranges[bin]) || r.range < scan.ranges[bin]) scan.ranges[bin] = r.range;
  }
  scan.range_min = 0.0;
  scan.range_max = std::max_element(returns.begin(), returns.end(), [](auto& a, auto& b) {
                     return a.range < b.range;
                   })->range;
  return scan;
}

}  // namespace

LrfDataset LoadLrfDataset(const fs::path& path) {
  const fs::path manifest = fs::absolute(ResolveDataset(path, DatasetKind::kLrf).path);
  const json document = json_io::ReadJson(manifest);
  const Fields root(document, manifest);
  json_io::CheckFormat(root, kFormat);
  LrfDataset dataset;
  dataset.manifest = manifest;
  const Fields target = root.Object("target");
  const std::string type = target.String("type");
  if (type == "three-face") {
    dataset.target_type = LrfTargetType::kThreeFace;
    dataset.three_face = ParseThreeFace(target);
    dataset.depth_camera = ParseDepthCamera(root.Object("depth_camera"));
  } else if (type == "checkerboard" || type == "charuco") {
    dataset.target_type = LrfTargetType::kCheckerboard;
    dataset.board = json_io::ParseTarget(target);
    dataset.camera = json_io::ParseManifestCamera(root);
  } else {
    target.Fail("type", "'" + type + "' is unknown (use three-face or checkerboard)");
  }
  std::set<std::string> seen;
  const json& pairs = json_io::PairsArray(root);
  for (size_t i = 0; i < pairs.size(); ++i) {
    LrfPairEntry pair = ParsePair(Fields(pairs[i], manifest, "pairs[" + std::to_string(i) + "]"),
                                  dataset.target_type);
    json_io::CheckUniquePairId(pair.id, &seen, manifest);
    dataset.pairs.push_back(std::move(pair));
  }
  dataset.cam_from_lrf_ground_truth = json_io::OptionalPose(root, "ground_truth", "cam_from_lrf");
  dataset.initial_cam_from_lrf = json_io::OptionalPose(root, "initial_guess", "cam_from_lrf");
  dataset.right_from_left = json_io::OptionalPose(root, "stereo", "right_from_left");
  return dataset;
}

void SaveLrfDataset(const fs::path& manifest_path, const LrfDataset& dataset) {
  auto relative = [&](const fs::path& p) { return json_io::PathForManifest(p, manifest_path); };
  auto matrix = [](const Pose& pose) { return json_io::MatrixToJson(pose.matrix()); };
  json root;
  root["format"] = kFormat;
  if (dataset.target_type == LrfTargetType::kThreeFace) {
    root["depth_camera"] = DepthCameraToJson(dataset.depth_camera);
    root["target"] = ThreeFaceToJson(dataset.three_face);
  } else {
    root["camera"] = json_io::CameraToJson(dataset.camera);
    root["target"] = json_io::TargetToJson(dataset.board);
  }
  json pairs = json::array();
  for (const LrfPairEntry& p : dataset.pairs) {
    json entry = {{"id", p.id}, {"scan", relative(p.scan)}};
    if (!p.depth.empty()) entry["depth"] = relative(p.depth);
    if (!p.depth_cloud.empty()) entry["cloud"] = relative(p.depth_cloud);
    if (!p.image.empty()) entry["image"] = relative(p.image);
    if (p.scan_region) entry["scan_region"] = ScanRegionToJson(*p.scan_region);
    pairs.push_back(entry);
  }
  root["pairs"] = pairs;
  if (dataset.cam_from_lrf_ground_truth)
    root["ground_truth"] = {{"cam_from_lrf", matrix(*dataset.cam_from_lrf_ground_truth)},
                            {"direction", "x_in_cam = cam_from_lrf * x_in_lrf"}};
  if (dataset.initial_cam_from_lrf)
    root["initial_guess"] = {{"cam_from_lrf", matrix(*dataset.initial_cam_from_lrf)}};
  if (dataset.right_from_left)
    root["stereo"] = {{"right_from_left", matrix(*dataset.right_from_left)},
                      {"direction", "x_in_right = right_from_left * x_in_left"}};
  WriteFileAtomically(manifest_path, root.dump(2) + "\n");
}

LaserScan LoadLaserScan(const fs::path& path, const LoadLimits& limits) {
  if (!fs::exists(path)) Fail(path, "no such file");
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  if (ext == ".json") return LoadScanJson(path, limits);
  if (ext == ".pcd") return LoadScanPcd(path, limits);
  Fail(path, "unsupported scan file extension '" + ext + "' (use .json or .pcd)");
}

void SaveLaserScanJson(const fs::path& path, const LaserScan& scan) {
  json ranges = json::array();
  for (double r : scan.ranges) ranges.push_back(std::isfinite(r) ? json(r) : json(nullptr));
  const double angle_max =
      scan.angle_min +
      static_cast<double>(std::max<size_t>(scan.ranges.size(), 1) - 1) * scan.angle_increment;
  const json root = {{"angle_min", scan.angle_min},
                     {"angle_max", angle_max},
                     {"angle_increment", scan.angle_increment},
                     {"range_min", scan.range_min},
                     {"range_max", scan.range_max},
                     {"ranges", ranges}};
  WriteFileAtomically(path, root.dump() + "\n");
}

DepthImage LoadDepthPng(const fs::path& path, const DepthIntrinsics& intrinsics,
                        const LoadLimits& limits) {
  json_io::CheckOrFail(intrinsics, path, "depth intrinsics");
  const std::string bytes = ReadImageFile(path);
  // The size from the header, before anything is decoded: a 540 KB PNG can declare 16000^2.
  const ImageHeader header = ReadImageHeader(path, bytes);
  if (std::string_view(header.format) != "PNG")
    Fail(path, std::string("a depth image must be a 16-bit PNG, this is a ") + header.format);
  CheckLoadLimit(path, "depth pixels", header.Pixels(), limits.max_depth_pixels,
                 "max_depth_pixels");
  if (header.width != intrinsics.width || header.height != intrinsics.height)
    Fail(path, "depth PNG is " + std::to_string(header.width) + "x" +
                   std::to_string(header.height) + " but the depth camera is " +
                   std::to_string(intrinsics.width) + "x" + std::to_string(intrinsics.height));
  cv::Mat image;
  try {
    const cv::Mat encoded(1, static_cast<int>(bytes.size()), CV_8UC1,
                          const_cast<char*>(bytes.data()));
    image = cv::imdecode(encoded, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    Fail(path, std::string("cannot decode the image: ") + e.err);
  }
  if (image.empty()) Fail(path, "cannot decode the image (not a PNG?)");
  if (image.depth() != CV_16U || image.channels() != 1)
    Fail(path, "a depth PNG must be 16-bit single-channel, this one has " +
                   std::to_string(image.elemSize1() * 8) + "-bit samples and " +
                   std::to_string(image.channels()) + " channel(s)");
  if (image.cols != intrinsics.width || image.rows != intrinsics.height)
    Fail(path, "depth PNG is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                   " but the depth camera is " + std::to_string(intrinsics.width) + "x" +
                   std::to_string(intrinsics.height));
  DepthImage depth;
  depth.intrinsics = intrinsics;
  depth.depth_m.resize(static_cast<size_t>(image.cols) * image.rows);
  for (int v = 0; v < image.rows; ++v) {
    const uint16_t* row = image.ptr<uint16_t>(v);
    for (int u = 0; u < image.cols; ++u)
      depth.depth_m[static_cast<size_t>(v) * image.cols + u] =
          static_cast<float>(row[u] * intrinsics.depth_scale);
  }
  // A wrong depth_scale (metres per unit) shows in the median depth: a millimetre PNG read with
  // scale 1 puts the scene kilometres away, one read with 1e-6 within millimetres. Depth
  // cameras see between a few centimetres and a few tens of metres.
  std::vector<float> valid;
  for (float z : depth.depth_m)
    if (z > 0) valid.push_back(z);
  if (!valid.empty()) {
    std::nth_element(valid.begin(), valid.begin() + valid.size() / 2, valid.end());
    const double median = valid[valid.size() / 2];
    if (median > 50.0 || median < 0.05)
      Fail(path, "the median depth is " + std::to_string(median) + " m with depth_scale " +
                     std::to_string(intrinsics.depth_scale) +
                     " m per unit: the scale looks wrong (0.001 for millimetre PNGs)");
  }
  return depth;
}

void SaveDepthPng(const fs::path& path, const DepthImage& depth) {
  const DepthIntrinsics& in = depth.intrinsics;
  json_io::CheckOrFail(in, path, "depth intrinsics");
  if (depth.depth_m.size() != static_cast<size_t>(in.width) * in.height)
    Fail(path, "depth image has " + std::to_string(depth.depth_m.size()) +
                   " values, the intrinsics say " + std::to_string(in.width) + "x" +
                   std::to_string(in.height));
  cv::Mat image(in.height, in.width, CV_16UC1);
  for (int v = 0; v < in.height; ++v) {
    uint16_t* row = image.ptr<uint16_t>(v);
    for (int u = 0; u < in.width; ++u) {
      const double units = std::round(depth.At(u, v) / in.depth_scale);
      row[u] = (std::isfinite(units) && units > 0 && units <= 65535.0)
                   ? static_cast<uint16_t>(units)
                   : uint16_t{0};
    }
  }
  std::vector<uchar> bytes;
  if (!cv::imencode(".png", image, bytes)) Fail(path, "cannot encode the depth PNG");
  WriteFileAtomically(path, std::string(bytes.begin(), bytes.end()));
}

DepthImage LoadDepthCloud(const fs::path& path, const DepthIntrinsics& intrinsics,
                          const LoadLimits& limits) {
  json_io::CheckOrFail(intrinsics, path, "depth intrinsics");
  CheckLoadLimit(path, "the depth camera's pixels (width x height)",
                 static_cast<std::int64_t>(intrinsics.width) * intrinsics.height,
                 limits.max_depth_pixels, "max_depth_pixels");
  const LidarCloud cloud = LoadCloud(path);
  DepthImage depth;
  depth.intrinsics = intrinsics;
  depth.depth_m.assign(static_cast<size_t>(intrinsics.width) * intrinsics.height, 0.0f);
  for (const Eigen::Vector3f& p : cloud.points) {
    const auto pixel = intrinsics.Project(p.cast<double>());
    if (!pixel) continue;
    const long u = std::lround(pixel->x()), v = std::lround(pixel->y());
    if (u < 0 || v < 0 || u >= intrinsics.width || v >= intrinsics.height) continue;
    float& z = depth.depth_m[static_cast<size_t>(v) * intrinsics.width + u];
    if (z == 0.0f || p.z() < z) z = p.z();  // nearest wins: the surface the camera would see
  }
  return depth;
}

DepthImage LoadPairDepth(const LrfDataset& dataset, const LrfPairEntry& pair) {
  if (!pair.depth.empty()) return LoadDepthPng(pair.depth, dataset.depth_camera);
  if (!pair.depth_cloud.empty()) return LoadDepthCloud(pair.depth_cloud, dataset.depth_camera);
  Fail(dataset.manifest, "pair " + pair.id + " names neither a depth PNG nor a depth cloud");
}

}  // namespace calibench
