// The corners of the three formats a recorder leaves behind: a ROS 1 bag whose recorder was
// killed (no index), a rosbag2 recording split over several files in a folder, an MCAP without a
// summary; and recordings that are not what their name says.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>

#include "core/recording/bag.h"
#include "core/recording/ros_messages.h"
#include "tests/bag_writers.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

// n small clouds on /points and n CameraInfo on /info, one second apart.
std::vector<test::RecordedMessage> SmallRecording(int n, MessageEncoding encoding,
                                                  std::int64_t first_second) {
  LidarCloud cloud;
  for (int i = 0; i < 10; ++i) cloud.points.emplace_back(1.0f + i, 0.5f, -0.25f);
  cloud.width = 10;
  CameraModel camera;
  camera.width = 64;
  camera.height = 48;
  camera.fx = camera.fy = 50;
  camera.cx = 32;
  camera.cy = 24;
  camera.distortion = {0, 0, 0, 0, 0};
  std::vector<test::RecordedMessage> messages;
  for (int i = 0; i < n; ++i) {
    const std::int64_t t = (first_second + i) * 1'000'000'000;
    messages.push_back({"/points", "sensor_msgs/PointCloud2", t,
                        test::SerializePointCloud2(cloud, t, "lidar", encoding)});
    messages.push_back({"/info", "sensor_msgs/CameraInfo", t + 1,
                        test::SerializeCameraInfo(camera, t, "cam", encoding)});
  }
  return messages;
}

std::map<std::string, std::int64_t> CountsOf(const BagReader& bag) {
  std::map<std::string, std::int64_t> counts;
  for (const BagTopic& topic : bag.Topics()) counts[topic.name] = topic.message_count;
  return counts;
}

int Visit(BagReader& bag) {
  int visited = 0;
  bag.ForEachMessage({}, [&](const BagMessage& message) {
    const BagTopic& topic = bag.Topics()[message.topic];
    if (topic.type == kPointCloud2Type) {
      EXPECT_EQ(DecodePointCloud2(message.data, topic.encoding).cloud.size(), 10u);
    }
    return ++visited, true;
  });
  return visited;
}

// `rosbag record` killed: the chunks are there, the index and the header's index_pos are not.
TEST(BagFormats, AnUnindexedRos1BagIsReadThrough) {
  const fs::path dir = test::TempDir("bag_formats_unindexed");
  const fs::path bag = dir / "killed.bag";
  test::WriteRos1Bag(bag, SmallRecording(5, MessageEncoding::kRos1, 10), "lz4", 300);
  std::string bytes = test::ReadFileBytes(bag);
  // The bag header's index_pos field: cut the file there and zero it.
  const std::size_t field = bytes.find("index_pos=") + std::strlen("index_pos=");
  std::uint64_t index_pos = 0;
  std::memcpy(&index_pos, bytes.data() + field, 8);
  bytes.resize(index_pos);
  std::memset(bytes.data() + field, 0, 8);
  std::ofstream(bag, std::ios::binary | std::ios::trunc).write(bytes.data(), bytes.size());
  auto reader = OpenBag(bag);
  EXPECT_NE(reader->Format().find("no index"), std::string::npos) << reader->Format();
  const std::map<std::string, std::int64_t> expected = {{"/info", 5}, {"/points", 5}};
  EXPECT_EQ(CountsOf(*reader), expected);
  EXPECT_EQ(Visit(*reader), 10);
}

// A rosbag2 recording split in two files (db3 and mcap), in a folder with metadata.yaml: one
// recording, topics merged, messages of both files.
TEST(BagFormats, ARosbag2FolderOfSeveralFilesIsOneRecording) {
  const fs::path dir = test::TempDir("bag_formats_folder") / "rosbag2_2026_11_23";
  fs::create_directories(dir);
  test::WriteDb3(dir / "rosbag2_2026_11_23_0.db3", SmallRecording(3, MessageEncoding::kCdr, 10));
  test::WriteMcap(dir / "rosbag2_2026_11_23_1.mcap", SmallRecording(4, MessageEncoding::kCdr, 13),
                  "ros2", "zstd", /*summary=*/false);
  std::ofstream(dir / "metadata.yaml") << "rosbag2_bagfile_information:\n  version: 5\n";
  EXPECT_TRUE(LooksLikeBag(dir));
  auto reader = OpenBag(dir);
  EXPECT_NE(reader->Format().find("rosbag2 folder of 2 files"), std::string::npos)
      << reader->Format();
  const std::map<std::string, std::int64_t> expected = {{"/info", 7}, {"/points", 7}};
  EXPECT_EQ(CountsOf(*reader), expected);
  std::int64_t last = 0;
  int visited = 0;
  reader->ForEachMessage({}, [&](const BagMessage& message) {
    EXPECT_GE(message.log_time_ns, last);  // the files in order, each in time order
    last = message.log_time_ns;
    return ++visited, true;
  });
  EXPECT_EQ(visited, 14);
}

TEST(BagFormats, AFileIsKnownByItsBytesNotItsName) {
  const fs::path dir = test::TempDir("bag_formats_sniff");
  test::WriteMcap(dir / "really_an_mcap.bag", SmallRecording(2, MessageEncoding::kRos1, 10), "ros1",
                  "lz4");
  EXPECT_EQ(OpenBag(dir / "really_an_mcap.bag")->Format().rfind("MCAP", 0), 0u);
  std::ofstream(dir / "photo.mcap", std::ios::binary) << "\x89PNG\r\n\x1a\n not a recording";
  EXPECT_FALSE(LooksLikeBag(dir / "photo.mcap"));
  try {
    OpenBag(dir / "photo.mcap");
    ADD_FAILURE() << "a PNG opened as a recording";
  } catch (const IoError& error) {
    EXPECT_NE(std::string(error.what()).find((dir / "photo.mcap").string()), std::string::npos);
  }
  fs::create_directories(dir / "empty_folder");
  EXPECT_THROW(OpenBag(dir / "empty_folder"), IoError);
}

}  // namespace
}  // namespace calibench
