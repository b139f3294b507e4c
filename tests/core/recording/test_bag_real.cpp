// Recordings no one here wrote (../shared/datasets/ros-bags, made by rosbag, ros2 bag and
// `mcap convert`): every one opens with the topics and counts an independent parser found
// (FACTS.txt), and every PointCloud2 / Image / CompressedImage / CameraInfo decodes to the sizes
// it declares (VALIDATE.txt).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>

#include "core/recording/bag.h"
#include "core/recording/ros_messages.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

// "topic type" -> message count.
std::map<std::string, std::int64_t> TopicCounts(const BagReader& bag) {
  std::map<std::string, std::int64_t> counts;
  for (const BagTopic& topic : bag.Topics())
    counts[topic.name + " " + topic.type] += topic.message_count;
  return counts;
}

// What each importable message decoded to, per topic: "WxH encoding" or "N points" counts.
std::map<std::string, std::map<std::string, int>> DecodeEveryImportable(BagReader& bag) {
  std::map<std::string, std::map<std::string, int>> seen;
  bag.ForEachMessage({}, [&](const BagMessage& message) {
    const BagTopic& topic = bag.Topics()[message.topic];
    std::string what;
    if (topic.type == kPointCloud2Type) {
      const PointCloud2Message cloud = DecodePointCloud2(message.data, topic.encoding);
      what = std::to_string(cloud.declared_points) + " points " + cloud.fields;
    } else if (topic.type == kImageType) {
      const ImageMessage image = DecodeImage(message.data, topic.encoding);
      what = std::to_string(image.image.width) + "x" + std::to_string(image.image.height) + " " +
             image.encoding;
    } else if (topic.type == kCompressedImageType) {
      const ImageMessage image = DecodeCompressedImage(message.data, topic.encoding);
      what = std::to_string(image.image.width) + "x" + std::to_string(image.image.height) + " " +
             image.encoding;
    } else if (topic.type == kCameraInfoType) {
      const CameraInfoMessage info = DecodeCameraInfo(message.data, topic.encoding);
      what = std::to_string(info.camera.width) + "x" + std::to_string(info.camera.height) + " " +
             info.distortion_model;
    } else {
      return true;
    }
    ++seen[topic.name][what];
    return true;
  });
  return seen;
}

using DecodedKinds = std::map<std::string, std::map<std::string, int>>;

TEST(RealBags, Ros1LidarLz4) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  auto bag = OpenBag(shared / "datasets/ros-bags/ros1_luminar_lidar_lz4.bag");
  EXPECT_EQ(bag->Format(), "ROS 1 bag v2.0, 6 chunks (lz4)");
  const std::map<std::string, std::int64_t> expected = {
      {"/luminar_pointcloud sensor_msgs/PointCloud2", 5},
      {"/base_scan sensor_msgs/LaserScan", 5},
      {"/base_pose_ground_truth nav_msgs/Odometry", 5}};
  EXPECT_EQ(TopicCounts(*bag), expected);
  const std::string fields =
      " points x:FLOAT32@0 y:FLOAT32@4 z:FLOAT32@8 intensity:FLOAT32@16 time_sec:UINT32@20 "
      "time_nsec:UINT32@24 laser_id:UINT16@28";
  const DecodedKinds want = {{"/luminar_pointcloud",
                              {{"35707" + fields, 1},
                               {"36055" + fields, 1},
                               {"36267" + fields, 1},
                               {"36336" + fields, 1},
                               {"36457" + fields, 1}}}};
  EXPECT_EQ(DecodeEveryImportable(*bag), want);
}

TEST(RealBags, Ros1CloudWithRgbAndSixTfConnections) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  auto bag = OpenBag(shared / "datasets/ros-bags/ros1_rgbd_cluster_cloud_tf.bag");
  const std::map<std::string, std::int64_t> expected = {
      {"/tf tf2_msgs/TFMessage", 3199},
      {"/tf tf/tfMessage", 333},
      {"/euclidean_cluster_indices_decomposer/output00 sensor_msgs/PointCloud2", 1}};
  EXPECT_EQ(TopicCounts(*bag), expected);
  const DecodedKinds want = {
      {"/euclidean_cluster_indices_decomposer/output00",
       {{"13966 points x:FLOAT32@0 y:FLOAT32@4 z:FLOAT32@8 rgb:FLOAT32@16", 1}}}};
  EXPECT_EQ(DecodeEveryImportable(*bag), want);
}

TEST(RealBags, Ros1CameraWithCameraInfo) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  auto bag = OpenBag(shared / "datasets/ros-bags/ros1_svo_camera_imu.bag");
  EXPECT_EQ(TopicCounts(*bag).at("/camera/image_raw sensor_msgs/Image"), 10);
  EXPECT_EQ(TopicCounts(*bag).at("/camera/camera_info sensor_msgs/CameraInfo"), 11);
  EXPECT_EQ(TopicCounts(*bag).at("/imu/data sensor_msgs/Imu"), 35);
  const DecodedKinds want = {{"/camera/image_raw", {{"752x480 mono8", 10}}},
                             {"/camera/camera_info", {{"752x480 plumb_bob", 11}}}};
  EXPECT_EQ(DecodeEveryImportable(*bag), want);
  // The first CameraInfo, as FACTS.txt decodes it.
  const int info = bag->FindTopic("/camera/camera_info");
  bag->ForEachMessage({}, [&](const BagMessage& message) {
    if (message.topic != info) return true;
    const CameraInfoMessage decoded = DecodeCameraInfo(message.data, MessageEncoding::kRos1);
    EXPECT_EQ(decoded.header.frame_id, "/camera");
    EXPECT_NEAR(decoded.camera.fx, 414.5, 0.05);
    EXPECT_NEAR(decoded.camera.fy, 414.3, 0.05);
    EXPECT_NEAR(decoded.camera.cx, 348.8, 0.05);
    EXPECT_NEAR(decoded.camera.cy, 240.1, 0.05);
    EXPECT_EQ(decoded.camera.distortion.size(), 5u);
    if (decoded.camera.distortion.size() == 5) {
      EXPECT_NEAR(decoded.camera.distortion[0], -0.2831, 5e-5);
      EXPECT_NEAR(decoded.camera.distortion[2], 0.0008959, 5e-8);
    }
    return false;
  });
}

// One recording stored three ways must give the same messages, byte for byte.
TEST(RealBags, Ros1CompressionsGiveTheSameMessages) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  std::vector<std::vector<std::string>> all;
  for (const char* name :
       {"ros1_turtlesim_none.bag", "ros1_turtlesim_bz2.bag", "ros1_turtlesim_lz4.bag"}) {
    auto bag = OpenBag(shared / "datasets/ros-bags" / name);
    std::int64_t total = 0;
    for (const BagTopic& topic : bag->Topics()) total += topic.message_count;
    EXPECT_EQ(total, 8647) << name;
    std::vector<std::string> messages;
    bag->ForEachMessage({}, [&](const BagMessage& message) {
      messages.push_back(bag->Topics()[message.topic].name + std::to_string(message.log_time_ns) +
                         std::string(message.data.begin(), message.data.end()));
      return true;
    });
    std::sort(messages.begin(), messages.end());
    all.push_back(std::move(messages));
  }
  ASSERT_EQ(all[0].size(), 8647u);
  EXPECT_TRUE(all[0] == all[1]);
  EXPECT_TRUE(all[0] == all[2]);
}

TEST(RealBags, Ros1Bz2WithoutLeadingSlashesAndEmptyDefinitions) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  auto cartographer = OpenBag(shared / "datasets/ros-bags/ros1_cartographer_bz2_6chunks.bag");
  const std::map<std::string, std::int64_t> expected = {
      {"horizontal_laser_2d sensor_msgs/MultiEchoLaserScan", 222}, {"imu sensor_msgs/Imu", 1243}};
  EXPECT_EQ(TopicCounts(*cartographer), expected);
  int visited = 0;
  cartographer->ForEachMessage({}, [&](const BagMessage&) { return ++visited, true; });
  EXPECT_EQ(visited, 1465);
  auto empty = OpenBag(shared / "datasets/ros-bags/ros1_empty_msgdef.bag");
  EXPECT_EQ(TopicCounts(*empty).at("/led_array_status led_array_msgs/Status"), 14);
}

TEST(RealBags, McapRos1ProfileEqualsTheBagItWasConvertedFrom) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  auto bag = OpenBag(shared / "datasets/ros-bags/ros1_dvs_images.bag");
  auto mcap = OpenBag(shared / "datasets/ros-bags/mcap_ros1_dvs_images_zstd.mcap");
  EXPECT_EQ(mcap->Format(), "MCAP (ros1 profile), 1 chunks (zstd)");
  EXPECT_EQ(TopicCounts(*bag), TopicCounts(*mcap));
  const DecodedKinds want = {{"/dvs/image_raw", {{"346x260 mono8", 4}}},
                             {"/dvs1/image_raw", {{"346x260 mono8", 3}}}};
  EXPECT_EQ(DecodeEveryImportable(*mcap), want);
  auto messages = [](BagReader& reader) {
    std::vector<std::string> all;
    reader.ForEachMessage({}, [&](const BagMessage& message) {
      all.push_back(std::string(message.data.begin(), message.data.end()));
      return true;
    });
    return all;
  };
  EXPECT_TRUE(messages(*bag) == messages(*mcap));
}

TEST(RealBags, McapOrganizedOusterCloud) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  auto mcap = OpenBag(shared / "datasets/ros-bags/mcap_ros1_ouster_os1_zstd.mcap");
  EXPECT_EQ(TopicCounts(*mcap).at("/os1_node/lidar_packets ouster_ros/PacketMsg"), 206);
  const std::string fields =
      "131072 points x:FLOAT32@0 y:FLOAT32@4 z:FLOAT32@8 intensity:FLOAT32@16 t:UINT32@20 "
      "reflectivity:UINT16@24 ring:UINT8@26 noise:UINT16@28 range:UINT32@32";
  const DecodedKinds want = {{"/os1_cloud_node/points", {{fields, 2}}},
                             {"/img_node/intensity_image", {{"2048x64 mono8", 2}}},
                             {"/img_node/noise_image", {{"2048x64 mono8", 2}}},
                             {"/img_node/range_image", {{"2048x64 mono8", 2}}}};
  EXPECT_EQ(DecodeEveryImportable(*mcap), want);
  // Organized 64 x 2048, ring from the uint8 field: the whole grid is kept.
  const int points = mcap->FindTopic("/os1_cloud_node/points");
  mcap->ForEachMessage({}, [&](const BagMessage& message) {
    if (message.topic != points) return true;
    const PointCloud2Message cloud = DecodePointCloud2(message.data, MessageEncoding::kRos1);
    EXPECT_EQ(cloud.header.frame_id, "os1_lidar");
    EXPECT_EQ(cloud.cloud.width, 2048);
    EXPECT_EQ(cloud.cloud.height, 64);
    EXPECT_TRUE(cloud.cloud.IsOrganized());
    EXPECT_EQ(*std::max_element(cloud.cloud.ring.begin(), cloud.cloud.ring.end()), 63);
    return false;
  });
}

// Each return keeps the time its driver gave it (core/lidar/point_times.h), read from real
// recordings: the Ouster's `t` (uint32 ns after the stamp) and Luminar's time_sec + time_nsec
// (seconds on the clock, two uint32: its sweeps' 88 ms end at their stamps).
TEST(RealBags, EachReturnKeepsTheTimeItsDriverGaveIt) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  struct Expect {
    const char* file;
    const char* topic;
    const char* words;
    double min_span_s, max_span_s;
  };
  // An OS1-64 at 10 Hz: 2048 columns over 0.1 s (the last column 2047/2048 of it after the first).
  const Expect expected[] = {
      {"mcap_ros1_ouster_os1_zstd.mcap", "/os1_cloud_node/points",
       "per-point times from 't' (UINT32), read as nanoseconds after the stamp", 0.0990, 0.1000},
      {"ros1_luminar_lidar_lz4.bag", "/luminar_pointcloud",
       "per-point times from 'time_sec+time_nsec' (UINT32+UINT32), read as seconds on the "
       "LiDAR's clock: -0.08",
       0.080, 0.095}};
  for (const Expect& e : expected) {
    SCOPED_TRACE(e.file);
    auto bag = OpenBag(shared / "datasets/ros-bags" / e.file);
    const int topic = bag->FindTopic(e.topic);
    int clouds = 0;
    bag->ForEachMessage({}, [&](const BagMessage& message) {
      if (message.topic != topic) return true;
      const PointCloud2Message m = DecodePointCloud2(message.data, MessageEncoding::kRos1);
      ++clouds;
      EXPECT_EQ(m.point_times.rfind(e.words, 0), 0u) << m.point_times;
      EXPECT_EQ(m.cloud.time_s.size(), m.cloud.size());
      if (m.cloud.time_s.empty()) return false;
      const auto [low, high] = std::minmax_element(m.cloud.time_s.begin(), m.cloud.time_s.end());
      EXPECT_GE(*high - *low, e.min_span_s);
      EXPECT_LE(*high - *low, e.max_span_s);
      EXPECT_LE(std::abs(*low), 0.2f) << "the returns lie near their stamp";
      std::printf("%s: %s\n", e.file, m.point_times.c_str());
      return true;
    });
    EXPECT_GT(clouds, 0);
  }
}

TEST(RealBags, McapRos2HumbleSensorMessages) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  auto mcap = OpenBag(shared / "datasets/ros-bags/mcap_ros2_humble_sensor_msgs.mcap");
  EXPECT_EQ(mcap->Topics().size(), 32u);
  const DecodedKinds want = {
      {"/camera_info", {{"640x480 plumb_bob", 1}}},
      {"/compressed_image", {{"640x480 jpeg", 1}}},
      {"/image", {{"640x480 rgb8", 1}}},
      {"/point_cloud2",
       {{"200 points x:FLOAT32@0 y:FLOAT32@4 z:FLOAT32@8 intensity:FLOAT32@12", 1}}}};
  EXPECT_EQ(DecodeEveryImportable(*mcap), want);
}

TEST(RealBags, McapRos2TestFixturesAndDb3Layouts) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const fs::path dir = shared / "datasets/ros-bags";
  auto cdr = OpenBag(dir / "mcap_ros2_cdr_test.mcap");
  EXPECT_EQ(TopicCounts(*cdr).at("/array_topic test_msgs/Arrays"), 4);
  EXPECT_EQ(TopicCounts(*cdr).at("/test_topic test_msgs/BasicTypes"), 3);
  auto talker = OpenBag(dir / "mcap_ros2_talker_zstd.mcap");
  EXPECT_EQ(TopicCounts(*talker).at("/topic std_msgs/String"), 10);
  // Schema 4 (message_definitions table) and Humble's schema 3.
  auto schema4 = OpenBag(dir / "db3_ros2_cdr_test_schema4.db3");
  EXPECT_EQ(TopicCounts(*schema4), TopicCounts(*cdr));
  auto vlp16 = OpenBag(dir / "db3_humble_vlp16_packets.db3");
  EXPECT_EQ(TopicCounts(*vlp16).at("/velodyne_packets velodyne_msgs/VelodyneScan"), 4);
  std::int64_t last = 0;
  int visited = 0;
  vlp16->ForEachMessage({}, [&](const BagMessage& message) {
    EXPECT_GE(message.log_time_ns, last);
    last = message.log_time_ns;
    return ++visited, true;
  });
  EXPECT_EQ(visited, 4);
}

// A file cut short (a recorder killed, a copy that stopped) is read up to its last complete record
// and says where it stopped: never a crash, an error that loses the whole recording, or a silent
// short read.
TEST(RealBags, TruncatedFilesAreReadUpToWhereTheyStopAndSaySo) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const fs::path dir = calibench::test::TempDir("truncated_bags");
  for (const char* name :
       {"ros1_luminar_lidar_lz4.bag", "mcap_ros1_ouster_os1_zstd.mcap", "ros1_turtlesim_bz2.bag"}) {
    SCOPED_TRACE(name);
    const fs::path whole = shared / "datasets/ros-bags" / name;
    const std::string bytes = calibench::test::ReadFileBytes(whole);
    const fs::path cut = dir / name;
    std::ofstream(cut, std::ios::binary).write(bytes.data(), bytes.size() * 2 / 3);
    int all = 0, read = 0;
    OpenBag(whole)->ForEachMessage({}, [&](const BagMessage&) { return ++all > 0; });
    auto bag = OpenBag(cut);
    bag->ForEachMessage({}, [&](const BagMessage&) { return ++read > 0; });
    EXPECT_NE(bag->CutShort().find("cut short at byte"), std::string::npos) << bag->CutShort();
    // Never more than the whole; the turtlesim bag's 8647 small messages all lie before the cut,
    // which tears the index records that follow its last chunk.
    EXPECT_GT(read, 0);
    EXPECT_LE(read, all);
    std::printf("%s cut at 2/3: %d of %d messages; %s\n", name, read, all, bag->CutShort().c_str());
  }
}

}  // namespace
}  // namespace calibench
