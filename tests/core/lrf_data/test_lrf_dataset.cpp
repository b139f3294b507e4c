// The calibench.lrf-dataset.v1 manifest and its files: LaserScan JSON, 2D PCD (real ACFR-RPG
// scans), 16-bit depth PNGs and depth-frame PCDs, round trips and the errors on bad inputs.
#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "core/io/cloud_io.h"
#include "core/lidar/cloud.h"
#include "core/lrf_data/dataset.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

namespace fs = std::filesystem;
using test::MatrixNear;
using test::TempDir;

void WriteText(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

// Expects an IoError whose message names `file`.
template <typename F>
void ExpectIoErrorNaming(F&& call, const fs::path& file) {
  try {
    call();
    ADD_FAILURE() << "no IoError for " << file;
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(file.filename().string()), std::string::npos) << e.what();
  }
}

DepthIntrinsics SmallIntrinsics() { return DepthIntrinsics{64, 48, 50.0, 52.0, 31.5, 23.5, 0.001}; }

Pose SomePose(double a, double b, double c) {
  Pose pose = Pose::Identity();
  pose.linear() = (Eigen::AngleAxisd(a, Vec3::UnitZ()) * Eigen::AngleAxisd(b, Vec3::UnitY()))
                      .toRotationMatrix();
  pose.translation() = Vec3(c, -2 * c, 0.5);
  return pose;
}

TEST(LrfDataset, ScanJsonRoundTripKeepsRangesAndNoReturns) {
  const fs::path dir = TempDir("lrf_scan_json");
  LaserScan scan;
  scan.angle_min = -2.0;
  scan.angle_increment = 0.0123456789;
  scan.range_min = 0.1;
  scan.range_max = 30.0;
  scan.ranges = {1.0,
                 std::numeric_limits<double>::quiet_NaN(),
                 2.718281828459045,
                 std::numeric_limits<double>::infinity(),
                 0.05,
                 12.3456789012345};
  SaveLaserScanJson(dir / "scan.json", scan);
  const LaserScan back = LoadLaserScan(dir / "scan.json");
  EXPECT_EQ(back.angle_min, scan.angle_min);
  EXPECT_EQ(back.angle_increment, scan.angle_increment);
  EXPECT_EQ(back.range_min, scan.range_min);
  EXPECT_EQ(back.range_max, scan.range_max);
  ASSERT_EQ(back.ranges.size(), scan.ranges.size());
  for (size_t i = 0; i < scan.ranges.size(); ++i) {
    EXPECT_EQ(back.Valid(i), scan.Valid(i)) << i;
    if (std::isfinite(scan.ranges[i])) {
      EXPECT_EQ(back.ranges[i], scan.ranges[i]) << i;
    }
  }
}

TEST(LrfDataset, ScanJsonAcceptsNullInfAndNanStrings) {
  const fs::path dir = TempDir("lrf_scan_strings");
  WriteText(dir / "s.json",
            R"({"angle_min": 0, "angle_increment": 0.5, "range_min": 0, "range_max": 5,
                "ranges": [1.5, null, "inf", "NaN", "-inf", 2]})");
  const LaserScan scan = LoadLaserScan(dir / "s.json");
  ASSERT_EQ(scan.ranges.size(), 6u);
  EXPECT_TRUE(scan.Valid(0) && scan.Valid(5));
  for (size_t i = 1; i < 5; ++i) EXPECT_FALSE(scan.Valid(i)) << i;
  EXPECT_NEAR(scan.Point(5).y(), 2 * std::sin(2.5), 1e-12);
}

TEST(LrfDataset, BadScansThrowNamingTheFile) {
  const fs::path dir = TempDir("lrf_scan_bad");
  WriteText(dir / "empty.json",
            R"({"angle_min": 0, "angle_increment": 0.5, "range_min": 0, "range_max": 5,
                "ranges": []})");
  ExpectIoErrorNaming([&] { LoadLaserScan(dir / "empty.json"); }, dir / "empty.json");
  WriteText(dir / "noinc.json", R"({"angle_min": 0, "range_min": 0, "range_max": 5,
                                    "ranges": [1]})");
  ExpectIoErrorNaming([&] { LoadLaserScan(dir / "noinc.json"); }, dir / "noinc.json");
  WriteText(dir / "word.json", R"({"angle_min": 0, "angle_increment": 0.5, "range_min": 0,
                                   "range_max": 5, "ranges": [1, "far"]})");
  ExpectIoErrorNaming([&] { LoadLaserScan(dir / "word.json"); }, dir / "word.json");
  ExpectIoErrorNaming([&] { LoadLaserScan(dir / "missing.json"); }, dir / "missing.json");
  WriteText(dir / "scan.txt", "1 2 3");
  ExpectIoErrorNaming([&] { LoadLaserScan(dir / "scan.txt"); }, dir / "scan.txt");
}

TEST(LrfDataset, RealAcfrPcdScansBinToAnEvenScanWithTheWallAhead) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const fs::path lasers = shared / "datasets/acfr-rpg-2dlidar-chessboard/lasers";
  int files = 0;
  for (const auto& entry : fs::directory_iterator(lasers)) {
    if (entry.path().extension() != ".pcd") continue;
    ++files;
    const LaserScan scan = LoadLaserScan(entry.path());
    int valid = 0;
    std::vector<double> ahead;  // ranges within ±3° of +x
    for (size_t i = 0; i < scan.ranges.size(); ++i) {
      if (!scan.Valid(i)) continue;
      ++valid;
      if (std::abs(scan.Angle(i)) < 3.0 * M_PI / 180.0) ahead.push_back(scan.ranges[i]);
    }
    // 361–375 non-origin points per file; a few collide in one bin after jitter.
    EXPECT_GE(valid, 355) << entry.path();
    EXPECT_LE(valid, 375) << entry.path();
    EXPECT_NEAR(scan.angle_increment, 2 * M_PI / 506, 2e-4) << entry.path();
    EXPECT_NEAR(scan.angle_min, -M_PI, 0.02) << entry.path();
    EXPECT_LE(scan.Angle(scan.ranges.size() - 1), M_PI + scan.angle_increment);
    ASSERT_GE(ahead.size(), 4u) << entry.path();
    std::sort(ahead.begin(), ahead.end());
    // The board's wall is 0.7–1.15 m ahead depending on the pose; about 1.1 m in the first pair
    // (README).
    EXPECT_GT(ahead.front(), 0.6) << entry.path();
    EXPECT_LT(ahead[ahead.size() / 2], 1.25) << entry.path();
    if (entry.path().stem() == "1773380642785313094") {
      EXPECT_NEAR(ahead[ahead.size() / 2], 1.1, 0.06) << entry.path();
    }
  }
  EXPECT_EQ(files, 5);
}

TEST(LrfDataset, PcdWithHeightIsNotA2dScan) {
  const fs::path dir = TempDir("lrf_pcd3d");
  LidarCloud cloud;
  cloud.points = {Eigen::Vector3f(1, 0, 0), Eigen::Vector3f(1, 0.1f, 0.5f),
                  Eigen::Vector3f(1, 0.2f, 0)};
  cloud.width = 3;
  SavePcd(dir / "cloud.pcd", cloud);
  ExpectIoErrorNaming([&] { LoadLaserScan(dir / "cloud.pcd"); }, dir / "cloud.pcd");
}

TEST(LrfDataset, DepthPngRoundTripWithinHalfAUnit) {
  const fs::path dir = TempDir("lrf_depth_png");
  DepthImage depth;
  depth.intrinsics = SmallIntrinsics();
  depth.depth_m.resize(64 * 48);
  for (size_t i = 0; i < depth.depth_m.size(); ++i)
    depth.depth_m[i] = static_cast<float>(0.2 + 0.0137 * static_cast<double>(i % 997));
  depth.depth_m[5] = 0.0f;
  depth.depth_m[6] = 70.0f;  // beyond 65535 units: no data
  SaveDepthPng(dir / "d.png", depth);
  const DepthImage back = LoadDepthPng(dir / "d.png", depth.intrinsics);
  ASSERT_EQ(back.depth_m.size(), depth.depth_m.size());
  EXPECT_EQ(back.depth_m[5], 0.0f);
  EXPECT_EQ(back.depth_m[6], 0.0f);
  double worst = 0;
  for (size_t i = 0; i < depth.depth_m.size(); ++i)
    if (i != 5 && i != 6)
      worst = std::max(worst, double(std::abs(back.depth_m[i] - depth.depth_m[i])));
  EXPECT_LE(worst, 0.5 * depth.intrinsics.depth_scale + 1e-6);
  EXPECT_GT(worst, 0.0);  // it is quantised, not copied
}

TEST(LrfDataset, DepthPngRejectsEightBitMultiChannelAndWrongSize) {
  const fs::path dir = TempDir("lrf_depth_bad");
  cv::imwrite((dir / "eight.png").string(), cv::Mat(48, 64, CV_8UC1, cv::Scalar(7)));
  cv::imwrite((dir / "rgb16.png").string(), cv::Mat(48, 64, CV_16UC3, cv::Scalar(7, 7, 7)));
  cv::imwrite((dir / "small.png").string(), cv::Mat(40, 64, CV_16UC1, cv::Scalar(7)));
  for (const char* name : {"eight.png", "rgb16.png", "small.png", "missing.png"})
    ExpectIoErrorNaming([&] { LoadDepthPng(dir / name, SmallIntrinsics()); }, dir / name);
}

TEST(LrfDataset, DepthCloudProjectsAndKeepsTheNearestPoint) {
  const fs::path dir = TempDir("lrf_depth_cloud");
  const DepthIntrinsics in = SmallIntrinsics();
  LidarCloud cloud;
  // Pixel (40, 10) at z = 2 and z = 1.5 (nearest wins), pixel (3, 44) at z = 0.8, one behind.
  auto at = [&](double u, double v, double z) {
    return Eigen::Vector3f(float((u - in.cx) / in.fx * z), float((v - in.cy) / in.fy * z),
                           float(z));
  };
  cloud.points = {at(40, 10, 2.0), at(40, 10, 1.5), at(3, 44, 0.8), Eigen::Vector3f(0, 0, -1)};
  cloud.width = 4;
  SavePcd(dir / "c.pcd", cloud);
  const DepthImage depth = LoadDepthCloud(dir / "c.pcd", in);
  EXPECT_NEAR(depth.At(40, 10), 1.5, 1e-6);
  EXPECT_NEAR(depth.At(3, 44), 0.8, 1e-6);
  int nonzero = 0;
  for (float z : depth.depth_m) nonzero += z > 0;
  EXPECT_EQ(nonzero, 2);
  ExpectIoErrorNaming([&] { LoadDepthCloud(dir / "none.pcd", in); }, dir / "none.pcd");
}

// A three-face dataset whose files exist under `dir`.
LrfDataset ThreeFaceDataset(const fs::path& dir) {
  fs::create_directories(dir / "scans");
  fs::create_directories(dir / "depth");
  LrfDataset d;
  d.target_type = LrfTargetType::kThreeFace;
  d.three_face.base_width = 1.0;
  d.three_face.ridge_height = 0.15;
  d.depth_camera = SmallIntrinsics();
  for (const char* id : {"0000", "0001"}) {
    LrfPairEntry pair;
    pair.id = id;
    pair.scan = dir / "scans" / (std::string(id) + ".json");
    WriteText(pair.scan, "{}");
    if (std::string(id) == "0000") {
      pair.depth = dir / "depth" / "0000.png";
      WriteText(pair.depth, "x");
      pair.scan_region = ScanRegion{-0.5, 0.25, 0.3, 4.0};
    } else {
      pair.depth_cloud = dir / "depth" / "0001.pcd";
      WriteText(pair.depth_cloud, "x");
    }
    d.pairs.push_back(pair);
  }
  d.cam_from_lrf_ground_truth = SomePose(0.1, -0.2, 0.3);
  d.initial_cam_from_lrf = SomePose(0.05, -0.1, 0.2);
  d.right_from_left = SomePose(0.0, 0.0, -0.12);
  return d;
}

TEST(LrfDataset, ThreeFaceManifestRoundTrip) {
  const fs::path dir = TempDir("lrf_manifest");
  const LrfDataset d = ThreeFaceDataset(dir);
  SaveLrfDataset(dir / "manifest.json", d);
  const LrfDataset back = LoadLrfDataset(dir / "manifest.json");
  EXPECT_EQ(back.target_type, LrfTargetType::kThreeFace);
  EXPECT_EQ(back.three_face.base_width, 1.0);
  EXPECT_EQ(back.three_face.ridge_height, 0.15);
  EXPECT_EQ(back.depth_camera.width, 64);
  EXPECT_EQ(back.depth_camera.fy, 52.0);
  EXPECT_EQ(back.depth_camera.cx, 31.5);
  ASSERT_EQ(back.pairs.size(), 2u);
  EXPECT_EQ(back.pairs[0].scan, d.pairs[0].scan);
  EXPECT_EQ(back.pairs[0].depth, d.pairs[0].depth);
  EXPECT_TRUE(back.pairs[0].depth_cloud.empty());
  EXPECT_EQ(back.pairs[1].depth_cloud, d.pairs[1].depth_cloud);
  ASSERT_TRUE(back.pairs[0].scan_region.has_value());
  EXPECT_NEAR(back.pairs[0].scan_region->angle_min, -0.5, 1e-12);
  EXPECT_NEAR(back.pairs[0].scan_region->angle_max, 0.25, 1e-12);
  EXPECT_EQ(back.pairs[0].scan_region->range_max, 4.0);
  EXPECT_FALSE(back.pairs[1].scan_region.has_value());
  ASSERT_TRUE(back.cam_from_lrf_ground_truth && back.initial_cam_from_lrf && back.right_from_left);
  EXPECT_TRUE(MatrixNear(back.cam_from_lrf_ground_truth->matrix(),
                         d.cam_from_lrf_ground_truth->matrix(), 1e-12));
  EXPECT_TRUE(
      MatrixNear(back.initial_cam_from_lrf->matrix(), d.initial_cam_from_lrf->matrix(), 1e-12));
  EXPECT_TRUE(MatrixNear(back.right_from_left->matrix(), d.right_from_left->matrix(), 1e-12));
  // Paths are stored relative to the manifest.
  std::ifstream in(dir / "manifest.json");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\"scans/0000.json\""), std::string::npos);
}

TEST(LrfDataset, CheckerboardManifestRoundTrip) {
  const fs::path dir = TempDir("lrf_manifest_board");
  WriteText(dir / "s.json", "{}");
  WriteText(dir / "i.png", "x");
  WriteText(dir / "manifest.json", R"({
    "format": "calibench.lrf-dataset.v1",
    "camera": {"model": "pinhole-radtan", "width": 640, "height": 480, "fx": 519.3,
               "fy": 518.9, "cx": 331.1, "cy": 229.4, "distortion": [0.1, 0.2, 0.0, 0.0, -1.0]},
    "target": {"type": "checkerboard", "inner_corners": [11, 8], "square_size": 0.019},
    "pairs": [{"id": "a", "scan": "s.json", "image": "i.png"}]})");
  const LrfDataset d = LoadLrfDataset(dir / "manifest.json");
  EXPECT_EQ(d.target_type, LrfTargetType::kCheckerboard);
  EXPECT_EQ(d.board.cols, 11);
  EXPECT_EQ(d.board.rows, 8);
  EXPECT_EQ(d.camera.fx, 519.3);
  EXPECT_EQ(d.camera.distortion.size(), 5u);
  ASSERT_EQ(d.pairs.size(), 1u);
  EXPECT_EQ(d.pairs[0].image, dir / "i.png");
  SaveLrfDataset(dir / "copy.json", d);
  const LrfDataset back = LoadLrfDataset(dir / "copy.json");
  EXPECT_EQ(back.target_type, LrfTargetType::kCheckerboard);
  EXPECT_EQ(back.board.square_size, 0.019);
  EXPECT_EQ(back.camera.cy, 229.4);
  EXPECT_EQ(back.pairs[0].image, dir / "i.png");
  EXPECT_EQ(back.pairs[0].scan, dir / "s.json");
}

TEST(LrfDataset, BadManifestsThrowNamingTheManifest) {
  const fs::path dir = TempDir("lrf_manifest_bad");
  const LrfDataset d = ThreeFaceDataset(dir);
  SaveLrfDataset(dir / "good.json", d);
  std::ifstream in(dir / "good.json");
  const std::string good((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto variant = [&](const std::string& name, const std::string& from, const std::string& to) {
    std::string text = good;
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    WriteText(dir / name, text);
    ExpectIoErrorNaming([&] { LoadLrfDataset(dir / name); }, dir / name);
  };
  variant("format.json", "calibench.lrf-dataset.v1", "calibench.dataset.v1");
  variant("type.json", "\"three-face\"", "\"four-face\"");
  variant("tent.json", "\"ridge_height\": 0.15", "\"ridge_height\": -0.15");
  variant("intrinsics.json", "\"fx\": 50.0", "\"fx\": 0.0");
  ExpectIoErrorNaming([&] { LoadLrfDataset(dir / "nothing.json"); }, dir / "nothing.json");
  // A pair's missing file is not the manifest's fault: the pair fails when it is loaded (naming
  // the file) and the other pairs are kept.
  std::string text = good;
  text.replace(text.find("scans/0001.json"), 15, "scans/0009.json");
  WriteText(dir / "missingfile.json", text);
  const LrfDataset loaded = LoadLrfDataset(dir / "missingfile.json");
  EXPECT_EQ(loaded.pairs.size(), d.pairs.size());
  ExpectIoErrorNaming([&] { LoadLaserScan(loaded.pairs[1].scan); }, dir / "scans/0009.json");
}

}  // namespace
}  // namespace calibench

namespace calibench {
namespace {

// The depth camera's one projection: Project and Unproject invert each other, their Jacobians
// are the derivatives, and a point behind the camera has no pixel.
TEST(DepthIntrinsicsProjection, ProjectAndUnprojectAreInversesWithTheirJacobians) {
  DepthIntrinsics k;
  k.width = 640, k.height = 480, k.fx = 525.5, k.fy = 524.0, k.cx = 319.2, k.cy = 241.7;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> lateral(-1.5, 1.5), depth(0.3, 6.0);
  for (int i = 0; i < 200; ++i) {
    const Vec3 point(lateral(rng), lateral(rng), depth(rng));
    Eigen::Matrix<double, 2, 3> project;
    const auto pixel = k.Project(point, &project);
    ASSERT_TRUE(pixel);
    Eigen::Matrix<double, 3, 2> unproject;
    EXPECT_TRUE(test::MatrixNear(k.Unproject(*pixel, point.z(), &unproject), point, 1e-12));
    Eigen::Matrix<double, 2, 3> numeric_project;
    Eigen::Matrix<double, 3, 2> numeric_unproject;
    for (int c = 0; c < 3; ++c) {
      Vec3 step = Vec3::Zero();
      step[c] = 1e-6;
      numeric_project.col(c) = (*k.Project(point + step) - *k.Project(point - step)) / 2e-6;
    }
    for (int c = 0; c < 2; ++c) {
      Vec2 step = Vec2::Zero();
      step[c] = 1e-3;
      numeric_unproject.col(c) =
          (k.Unproject(*pixel + step, point.z()) - k.Unproject(*pixel - step, point.z())) / 2e-3;
    }
    EXPECT_TRUE(test::MatrixNear(project, numeric_project, 1e-4));
    EXPECT_TRUE(test::MatrixNear(unproject, numeric_unproject, 1e-9));
  }
  EXPECT_FALSE(k.Project(Vec3(0.1, 0.2, -1.0)));
  EXPECT_FALSE(k.Project(Vec3(0.1, 0.2, 0.0)));
}

}  // namespace
}  // namespace calibench
