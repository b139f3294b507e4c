// The calibench.dataset.v1 manifest: round trip, the folder shorthand, and bad manifests.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "core/base/names.h"
#include "core/io/dataset.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

Dataset SmallDataset(const fs::path& dir) {
  Dataset d;
  d.camera.width = 640;
  d.camera.height = 480;
  d.camera.fx = d.camera.fy = 500;
  d.camera.cx = 319.5;
  d.camera.cy = 239.5;
  d.camera.distortion = {-0.1, 0.01, 0.0, 0.0, 0.0};
  d.target.cols = 7;
  d.target.rows = 5;
  d.target.square_size = 0.04;
  d.target.board_width = 0.42;
  d.target.board_height = 0.297;
  d.lidar_rings = 16;
  for (int i = 0; i < 3; ++i) {
    PairEntry p;
    p.id = "p" + std::to_string(i);
    p.cloud = dir / "clouds" / (p.id + ".pcd");
    p.image = dir / "images" / (p.id + ".png");
    if (i != 1) p.lidar_seed = LidarSeed{Vec3(2.0 + i, 0.1, -0.2), 0.25};
    // Past 2^53: a stamp a double would round (JSON readers that hold numbers as doubles).
    if (i != 0) p.lidar_stamp_ns = 1604515190231000001LL + i;
    d.pairs.push_back(p);
  }
  Pose gt = Pose::Identity();
  gt.linear() = Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  gt.translation() = Vec3(0.1, -0.2, 0.05);
  d.cam_from_lidar_ground_truth = gt;
  return d;
}

TEST(Dataset, ManifestRoundTripKeepsEverythingAndWritesRelativePaths) {
  const fs::path dir = test::TempDir("dataset_round_trip");
  const Dataset written = SmallDataset(dir);
  SaveDataset(dir / "dataset.json", written);
  std::ifstream in(dir / "dataset.json");
  const json j = json::parse(in);
  EXPECT_EQ(j["pairs"][0]["cloud"], "clouds/p0.pcd");  // relative to the manifest
  EXPECT_EQ(j["camera"]["model"], "pinhole-radtan");
  const Dataset read = LoadDataset(dir);  // the folder holding dataset.json works too
  ASSERT_EQ(read.pairs.size(), 3u);
  EXPECT_EQ(read.pairs[2].cloud, written.pairs[2].cloud);
  EXPECT_FALSE(read.pairs[1].lidar_seed);
  ASSERT_TRUE(read.pairs[2].lidar_seed);
  EXPECT_TRUE(test::MatrixNear(read.pairs[2].lidar_seed->point, Vec3(4.0, 0.1, -0.2), 0));
  EXPECT_FALSE(read.pairs[0].lidar_stamp_ns);
  EXPECT_EQ(j["pairs"][2]["lidar_stamp_ns"], "1604515190231000003");  // exact as a string
  ASSERT_TRUE(read.pairs[2].lidar_stamp_ns);
  EXPECT_EQ(*read.pairs[2].lidar_stamp_ns, 1604515190231000003LL);
  EXPECT_EQ(read.camera.distortion, written.camera.distortion);
  EXPECT_EQ(read.target.cols, 7);
  EXPECT_DOUBLE_EQ(read.target.board_height, 0.297);
  EXPECT_EQ(read.lidar_rings, 16);
  ASSERT_TRUE(read.cam_from_lidar_ground_truth);
  EXPECT_TRUE(test::MatrixNear(read.cam_from_lidar_ground_truth->matrix(),
                               written.cam_from_lidar_ground_truth->matrix(), 1e-12));
}

TEST(Dataset, FolderShorthandPairsCloudsAndImagesByStem) {
  const fs::path dir = test::TempDir("dataset_folder");
  fs::create_directories(dir / "clouds");
  fs::create_directories(dir / "images");
  for (const char* stem : {"a", "b", "c"})
    std::ofstream(dir / "clouds" / (std::string(stem) + ".pcd")) << "";
  for (const char* stem : {"a", "c", "d"})
    std::ofstream(dir / "images" / (std::string(stem) + ".png")) << "";
  std::ofstream(dir / "camera.yaml")
      << "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n"
         "camera_matrix: !!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n"
         "  data: [500, 0, 320, 0, 500, 240, 0, 0, 1]\n"
         "distortion_coefficients: !!opencv-matrix\n  rows: 1\n  cols: 5\n"
         "  dt: d\n  data: [0, 0, 0, 0, 0]\n";
  std::ofstream(dir / "target.json")
      << R"({"type": "charuco", "squares": [5, 7], "square_size": 0.04,
                                            "marker_size": 0.02, "dictionary": "DICT_6X6_250"})";
  const Dataset d = LoadDataset(dir);
  ASSERT_EQ(d.pairs.size(), 2u);  // a and c have both files
  EXPECT_EQ(d.pairs[0].id, "a");
  EXPECT_EQ(d.pairs[1].id, "c");
  EXPECT_EQ(d.target.type, BoardType::kCharuco);
  EXPECT_EQ(d.camera.width, 640);

  // A loop of symbolic links and a FIFO among the clouds: the folder still loads, with those
  // pairs in it; reading them fails that pair, naming the file (the pipeline's job).
  fs::create_symlink(dir / "clouds/e2.pcd", dir / "clouds/e.pcd");
  fs::create_symlink(dir / "clouds/e.pcd", dir / "clouds/e2.pcd");
  ASSERT_EQ(::mkfifo((dir / "clouds/f.pcd").c_str(), 0600), 0);
  for (const char* stem : {"e", "f"})
    std::ofstream(dir / "images" / (std::string(stem) + ".png")) << "";
  const Dataset with_bad_files = LoadDataset(dir);
  ASSERT_EQ(with_bad_files.pairs.size(), 4u);
  EXPECT_EQ(with_bad_files.pairs[2].id, "e");
  EXPECT_EQ(with_bad_files.pairs[3].id, "f");
}

TEST(Dataset, FolderPairsComeInNaturalOrder) {
  EXPECT_TRUE(NaturalLess("pose2", "pose10"));
  EXPECT_FALSE(NaturalLess("pose10", "pose2"));
  EXPECT_TRUE(NaturalLess("9.pcd", "10.pcd"));
  EXPECT_TRUE(NaturalLess("007", "7"));
  EXPECT_TRUE(NaturalLess("a", "b"));
  EXPECT_TRUE(NaturalLess("pose", "pose1"));
  EXPECT_FALSE(NaturalLess("x", "x"));
  const fs::path dir = test::TempDir("dataset_natural_order");
  fs::create_directories(dir / "clouds");
  fs::create_directories(dir / "images");
  for (const char* stem : {"pose10", "pose2", "pose1", "pose11", "pose3"}) {
    std::ofstream(dir / "clouds" / (std::string(stem) + ".pcd")) << "";
    std::ofstream(dir / "images" / (std::string(stem) + ".png")) << "";
  }
  std::ofstream(dir / "camera.yaml")
      << "image_width: 640\nimage_height: 480\ndistortion_model: plumb_bob\n"
         "d: [0, 0, 0, 0, 0]\nk: [500, 0, 320, 0, 500, 240, 0, 0, 1]\n";
  std::ofstream(dir / "target.json")
      << R"({"type": "checkerboard", "inner_corners": [5, 7], "square_size": 0.05})";
  std::vector<std::string> ids;
  for (const PairEntry& pair : LoadDataset(dir).pairs) ids.push_back(pair.id);
  EXPECT_EQ(ids, (std::vector<std::string>{"pose1", "pose2", "pose3", "pose10", "pose11"}));
}

// Writes `manifest` and expects LoadDataset to throw an IoError naming the file and `problem`.
void ExpectRejected(const json& manifest, const std::string& name, const std::string& problem) {
  const fs::path path = test::TempDir("dataset_bad") / (name + ".json");
  std::ofstream(path) << manifest.dump();
  try {
    LoadDataset(path);
    ADD_FAILURE() << name << ": accepted";
  } catch (const IoError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(name + ".json"), std::string::npos) << what;
    EXPECT_NE(what.find(problem), std::string::npos) << name << ": " << what;
  }
}

TEST(Dataset, BadManifestsNameTheFileAndTheProblem) {
  const fs::path dir = test::TempDir("dataset_good");
  SaveDataset(dir / "dataset.json", SmallDataset(dir));
  std::ifstream in(dir / "dataset.json");
  const json good = json::parse(in);

  json m = good;
  m["format"] = "calibench.dataset.v0";
  ExpectRejected(m, "wrong_format", "expected 'calibench.dataset.v1'");
  m = good;
  m["camera"]["model"] = "fisheye62";
  ExpectRejected(m, "unknown_model", "is unknown");
  m = good;
  m["camera"]["distortion"] = {0.1, 0.2, 0.3};
  ExpectRejected(m, "three_coefficients", "4, 5 or 8");
  m = good;
  m["camera"].erase("fx");
  ExpectRejected(m, "no_fx", "camera.fx: missing");
  m = good;
  m["pairs"][1]["id"] = "p0";
  ExpectRejected(m, "duplicate_id", "appears twice");
  m = good;
  m["pairs"][0]["lidar_seed"]["radius"] = -1;
  ExpectRejected(m, "negative_radius", "radius > 0");
  m = good;
  m["pairs"][1]["lidar_stamp_ns"] = "12.5 s";
  ExpectRejected(m, "stamp_words", "pairs[1].lidar_stamp_ns: must be nanoseconds");
  m = good;
  m["pairs"][1]["lidar_stamp_ns"] = 1604515190231000001LL;  // an integer reads as well
  {
    const fs::path integer = test::TempDir("dataset_stamp_integer") / "dataset.json";
    std::ofstream(integer) << m.dump();
    EXPECT_EQ(*LoadDataset(integer).pairs[1].lidar_stamp_ns, 1604515190231000001LL);
  }
  m = good;
  m["ground_truth"]["cam_from_lidar"] = {{2, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};
  ExpectRejected(m, "not_rigid", "not a rigid transform");
  m = good;
  m["target"]["inner_corners"] = {1, 5};
  ExpectRejected(m, "tiny_board", "inner_corners");
  m = good;
  m["target"]["board_size"] = {0.1, 0.1};
  ExpectRejected(m, "sheet_too_small", "smaller than the printed pattern");
}

TEST(Dataset, MissingPathsAndNonJson) {
  EXPECT_THROW(LoadDataset("/nonexistent/dataset.json"), IoError);
  const fs::path path = test::TempDir("dataset_not_json") / "dataset.json";
  std::ofstream(path) << "pairs: []";
  try {
    LoadDataset(path);
    FAIL();
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("not valid JSON"), std::string::npos);
  }
}

}  // namespace
}  // namespace calibench
