// Recordings in: a simulated dataset recorded as a ROS 1 bag (bz2 and lz4 chunks), an MCAP (ros2
// profile, zstd) and a rosbag2 .db3, imported, then calibrated: the same transform as the folder
// (<= 1e-9). And the import's selection: moving boards, near-duplicates, missing images, the cap.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>

#include "core/capture/bag_import.h"
#include "core/io/camera_file.h"
#include "core/io/cloud_io.h"
#include "core/io/dataset.h"
#include "core/io/image_io.h"
#include "core/lidar_camera/pipeline.h"
#include "core/sim/sim.h"
#include "tests/bag_writers.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;
using test::RecordedMessage;

constexpr std::int64_t kBagSecond = 1'000'000'000;
constexpr std::int64_t kBagMs = 1'000'000;

class BagImport : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    SimOptions sim = SimPreset("default");
    sim.num_pairs = 8;
    sim.seed = 11;
    // One directory per process: ctest runs each test of the suite as its own process, in
    // parallel, and each sets the suite up (a shared directory was wiped under a running test).
    sim_dir_ = new fs::path(test::TempDir("bag_import_sim_" + std::to_string(getpid())));
    dataset_ = new Dataset(SimulateDataset(sim, *sim_dir_));
    // The import writes no brush seeds: the folder is calibrated the same way, by detection.
    for (PairEntry& pair : dataset_->pairs) pair.lidar_seed.reset();
  }
  static void TearDownTestSuite() {
    delete dataset_;
    if (!sim_dir_) return;  // the set-up threw before making it
    std::error_code ignored;
    fs::remove_all(*sim_dir_, ignored);
    delete sim_dir_;
    sim_dir_ = nullptr;
  }

  // Pair i's messages around t_i = 100 s + 2 s i: the cloud 5 ms after the image, and the same
  // image 40 ms before and after (the board held still), CameraInfo with every image.
  // image_of(i, k) chooses the pair whose image is shown at offset k = -1, 0, +1.
  static std::vector<RecordedMessage> Record(
      MessageEncoding encoding,
      const std::function<int(int, int)>& image_of = [](int i, int) { return i; }) {
    std::vector<RecordedMessage> messages;
    const auto& pairs = dataset_->pairs;
    std::vector<ImageU8> images;
    for (const PairEntry& pair : pairs) images.push_back(LoadImage(pair.image));
    for (int i = 0; i < static_cast<int>(pairs.size()); ++i) {
      const std::int64_t t = 100 * kBagSecond + 2 * kBagSecond * i;
      for (int k = -1; k <= 1; ++k) {
        const int shown = image_of(i, k);
        if (shown < 0) continue;
        const std::int64_t stamp = t + k * 40 * kBagMs;
        messages.push_back(
            {"/camera/image_raw", "sensor_msgs/Image", stamp + kBagMs,
             test::SerializeImage(images[shown], "bgr8", stamp, "camera", encoding)});
        messages.push_back(
            {"/camera/camera_info", "sensor_msgs/CameraInfo", stamp + kBagMs,
             test::SerializeCameraInfo(dataset_->camera, stamp, "camera", encoding)});
      }
      const LidarCloud cloud = LoadCloud(pairs[i].cloud);
      messages.push_back({"/velodyne_points", "sensor_msgs/PointCloud2", t + 20 * kBagMs,
                          test::SerializePointCloud2(cloud, t + 5 * kBagMs, "velodyne", encoding)});
    }
    std::stable_sort(messages.begin(), messages.end(),
                     [](const RecordedMessage& a, const RecordedMessage& b) {
                       return a.log_time_ns < b.log_time_ns;
                     });
    return messages;
  }

  static BagImportSummary Import(const fs::path& bag, const fs::path& out,
                                 BagImportOptions options = {}) {
    return ImportBag(bag, out, dataset_->target, options);
  }

  static Pose Calibrate(const Dataset& dataset) {
    PipelineOptions options;
    options.threads = 2;
    const CalibrationOutcome outcome = CalibrateDataset(dataset, options);
    EXPECT_TRUE(outcome.solution.has_value()) << outcome.failure;
    return outcome.solution ? outcome.solution->cam_from_lidar : Pose::Identity();
  }

  static Dataset* dataset_;
  static fs::path* sim_dir_;
};
Dataset* BagImport::dataset_ = nullptr;
fs::path* BagImport::sim_dir_ = nullptr;

TEST_F(BagImport, EveryFormatCalibratesLikeTheFolder) {
  const fs::path dir = test::TempDir("bag_import_round_trip");
  const Pose folder = Calibrate(*dataset_);
  const auto ros1 = Record(MessageEncoding::kRos1);
  const auto cdr = Record(MessageEncoding::kCdr);
  struct Case {
    const char* name;
    std::function<void(const fs::path&)> write;
  };
  const std::vector<Case> cases = {
      {"ros1_bz2.bag", [&](const fs::path& p) { test::WriteRos1Bag(p, ros1, "bz2"); }},
      {"ros1_lz4.bag", [&](const fs::path& p) { test::WriteRos1Bag(p, ros1, "lz4"); }},
      {"ros2_zstd.mcap", [&](const fs::path& p) { test::WriteMcap(p, cdr, "ros2", "zstd"); }},
      {"ros2.db3", [&](const fs::path& p) { test::WriteDb3(p, cdr); }},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path bag = dir / c.name;
    c.write(bag);
    const BagImportSummary summary = Import(bag, dir / (std::string(c.name) + ".dataset"));
    EXPECT_EQ(summary.cloud_topic, "/velodyne_points");
    EXPECT_EQ(summary.image_topic, "/camera/image_raw");
    EXPECT_EQ(summary.camera_source, "/camera/camera_info");
    EXPECT_EQ(summary.clouds, 8);
    EXPECT_EQ(summary.images, 24);
    // Each cloud is alone in its stillness window, so each is tried: one search per pair, the
    // images beside it followed by optical flow.
    EXPECT_EQ(summary.images_searched, 8);
    EXPECT_EQ(summary.boards_seen, 8);
    EXPECT_EQ(summary.pair_ids.size(), 8u);
    EXPECT_TRUE(summary.dropped.empty());
    EXPECT_EQ(summary.kept_without_stillness_check, 0);
    const Dataset imported = LoadDataset(summary.manifest);
    // The intrinsics travel through CameraInfo (float64) and camera.yaml unchanged.
    EXPECT_EQ(imported.camera.distortion, dataset_->camera.distortion);
    EXPECT_EQ(imported.camera.fx, dataset_->camera.fx);
    const CameraModel yaml = LoadCameraFile(summary.manifest.parent_path() / "camera.yaml");
    EXPECT_EQ(yaml.distortion, dataset_->camera.distortion);
    EXPECT_EQ(yaml.cx, dataset_->camera.cx);
    EXPECT_TRUE(test::MatrixNear(Calibrate(imported).matrix(), folder.matrix(), 1e-9));
  }
}

// A board that moves between the images around a cloud is dropped; so is a pair whose image is
// missing, and one that repeats a kept pose.
TEST_F(BagImport, SelectionDropsMovingBoardsMissingImagesAndDuplicates) {
  const fs::path dir = test::TempDir("bag_import_selection");
  // Pair 1: the image after it shows pair 2's board (moved). Pair 3: no image at all.
  // Pair 5: shows pair 4's board throughout (a duplicate pose).
  const auto messages = Record(MessageEncoding::kRos1, [](int i, int k) {
    if (i == 1 && k == 1) return 2;
    if (i == 3) return -1;
    if (i == 5) return 4;
    return i;
  });
  test::WriteRos1Bag(dir / "selection.bag", messages, "none");
  const BagImportSummary summary = Import(dir / "selection.bag", dir / "selection.dataset");
  const std::map<std::string, int> dropped = {{"board moving (within 200 ms)", 1},
                                              {"near-duplicate board pose", 1},
                                              {"no image within 50 ms", 1}};
  EXPECT_EQ(summary.dropped, dropped);
  const std::vector<std::string> ids = {"0000", "0001", "0002", "0003", "0004"};
  EXPECT_EQ(summary.pair_ids, ids);
  // Every cloud is accounted for: written or dropped for one reason.
  EXPECT_EQ(summary.clouds, 8);
}

TEST_F(BagImport, TheCapSpreadsThePairsOverTheRecording) {
  const fs::path dir = test::TempDir("bag_import_cap");
  test::WriteMcap(dir / "cap.mcap", Record(MessageEncoding::kRos1), "ros1", "lz4",
                  /*summary=*/false);
  BagImportOptions options;
  options.max_pairs = 3;
  const BagImportSummary summary = Import(dir / "cap.mcap", dir / "cap.dataset", options);
  EXPECT_EQ(summary.pair_ids.size(), 3u);
  EXPECT_EQ(summary.dropped.at("over the cap of 3 pairs"), 5);
  // The first, middle and last moments: pairs 0, 3 and 7 of the recording by their stamps.
  const std::string record = test::ReadFileBytes(dir / "cap.dataset/import.json");
  EXPECT_NE(record.find("\"cloud_stamp_ns\": 100005000000"), std::string::npos);
  EXPECT_NE(record.find("\"cloud_stamp_ns\": 106005000000"), std::string::npos);
  EXPECT_NE(record.find("\"cloud_stamp_ns\": 114005000000"), std::string::npos);
}

TEST_F(BagImport, AmbiguousTopicsAreNamedAndAskedFor) {
  const fs::path dir = test::TempDir("bag_import_topics");
  auto messages = Record(MessageEncoding::kCdr);
  const auto first_image = std::find_if(messages.begin(), messages.end(), [](const auto& m) {
    return m.topic == "/camera/image_raw";
  });
  RecordedMessage second = *first_image;
  second.topic = "/camera2/image_raw";
  messages.push_back(second);
  test::WriteDb3(dir / "two_cameras.db3", messages);
  try {
    Import(dir / "two_cameras.db3", dir / "out");
    ADD_FAILURE() << "two image topics were not refused";
  } catch (const IoError& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find("several image topics (/camera/image_raw, /camera2/image_raw)"),
              std::string::npos)
        << what;
    EXPECT_NE(what.find("--image-topic"), std::string::npos) << what;
  }
  BagImportOptions options;
  options.image_topic = "/camera/image_raw";
  EXPECT_EQ(Import(dir / "two_cameras.db3", dir / "out", options).pair_ids.size(), 8u);
}

}  // namespace
}  // namespace calibench
