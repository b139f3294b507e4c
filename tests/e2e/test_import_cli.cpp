// `calibench import` through the real executable, as a user starts: --list on recordings made by
// real ROS tools, a bag -> a dataset folder -> `calibrate`, and clear refusals.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

#include "core/io/cloud_io.h"
#include "core/io/dataset.h"
#include "core/io/image_io.h"
#include "core/sim/sim.h"
#include "tests/bag_writers.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

TEST(ImportCli, ListsTheTopicsOfRealRecordings) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  std::string output;
  const fs::path bag = shared / "datasets/ros-bags/ros1_svo_camera_imu.bag";
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " import --list " + bag.string(), &output), 0)
      << output;
  EXPECT_NE(output.find("ROS 1 bag v2.0, 4 chunks (none)"), std::string::npos) << output;
  EXPECT_NE(output.find("/camera/image_raw"), std::string::npos) << output;
  EXPECT_NE(output.find("sensor_msgs/CameraInfo"), std::string::npos) << output;
  const fs::path mcap = shared / "datasets/ros-bags/mcap_ros2_humble_sensor_msgs.mcap";
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " import --list " + mcap.string(), &output), 0)
      << output;
  EXPECT_NE(output.find("MCAP (ros2 profile)"), std::string::npos) << output;
  EXPECT_NE(output.find("/point_cloud2"), std::string::npos) << output;
  // A recording without a LiDAR cloud: listed fine, refused for import with the reason.
  EXPECT_EQ(test::RunCommand(test::CalibenchExe() + " import " + bag.string() + " --out " +
                                 test::TempDir("import_cli_no_cloud").string(),
                             &output),
            2)
      << output;
  EXPECT_NE(
      output.find(bag.string() + ": no cloud (PointCloud2, Livox CustomMsg) topic with messages"),
      std::string::npos)
      << output;
}

TEST(ImportCli, RefusesWhatIsNotARecordingByName) {
  const fs::path dir = test::TempDir("import_cli_refusals");
  std::string output;
  EXPECT_EQ(test::RunCommand(test::CalibenchExe() + " import --list " + (dir / "none.bag").string(),
                             &output),
            2);
  EXPECT_NE(output.find((dir / "none.bag").string() + ": no such file or folder"),
            std::string::npos)
      << output;
  std::ofstream(dir / "notes.bag") << "just some text, not a recording\n";
  EXPECT_EQ(test::RunCommand(
                test::CalibenchExe() + " import --list " + (dir / "notes.bag").string(), &output),
            2);
  EXPECT_NE(output.find("not a recording Calibench reads"), std::string::npos) << output;
  EXPECT_EQ(test::RunCommand(
                test::CalibenchExe() + " import " + (dir / "notes.bag").string() + " --board a5",
                &output),
            1);
  EXPECT_NE(output.find("known: a3, a4"), std::string::npos) << output;
}

TEST(ImportCli, ABagBecomesADatasetThatCalibrates) {
  const fs::path dir = test::TempDir("import_cli_" + std::to_string(getpid()));
  SimOptions sim = SimPreset("default");
  sim.num_pairs = 4;
  sim.seed = 5;
  const Dataset dataset = SimulateDataset(sim, dir / "sim");
  std::vector<test::RecordedMessage> messages;
  for (std::size_t i = 0; i < dataset.pairs.size(); ++i) {
    const std::int64_t t = (50 + 3 * static_cast<std::int64_t>(i)) * 1'000'000'000;
    const ImageU8 image = LoadImage(dataset.pairs[i].image);
    messages.push_back({"/cam/image_raw", "sensor_msgs/Image", t,
                        test::SerializeImage(image, "bgr8", t, "cam", MessageEncoding::kRos1)});
    messages.push_back(
        {"/cam/camera_info", "sensor_msgs/CameraInfo", t,
         test::SerializeCameraInfo(dataset.camera, t, "cam", MessageEncoding::kRos1)});
    messages.push_back({"/points", "sensor_msgs/PointCloud2", t + 1000,
                        test::SerializePointCloud2(LoadCloud(dataset.pairs[i].cloud), t + 1000,
                                                   "lidar", MessageEncoding::kRos1)});
  }
  test::WriteRos1Bag(dir / "rig.bag", messages, "lz4");
  std::string output;
  ASSERT_EQ(
      test::RunCommand(
          test::CalibenchExe() + " import " + (dir / "rig.bag").string() + " --board a3", &output),
      0)
      << output;
  EXPECT_NE(output.find("pairs written: 4"), std::string::npos) << output;
  // stderr is not a terminal here: a line per 10 %, then the summary line a log ends with.
  EXPECT_NE(output.find("reading 100%"), std::string::npos) << output;
  EXPECT_NE(output.find("imported 4 pairs from "), std::string::npos) << output;
  EXPECT_NE(output.find("x its length)"), std::string::npos) << output;
  // One image per cloud: nothing to judge stillness by, and the summary says so.
  EXPECT_NE(output.find("note: 4 pairs had no other image within 200 ms"), std::string::npos)
      << output;
  // Next to the bag by default.
  const fs::path imported = dir / "rig.bag.dataset";
  EXPECT_TRUE(fs::exists(imported / "dataset.json"));
  EXPECT_TRUE(fs::exists(imported / "camera.yaml"));
  EXPECT_TRUE(fs::exists(imported / "import.json"));
  EXPECT_TRUE(fs::exists(imported / "clouds/0003.pcd"));
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " calibrate --dataset " + imported.string() +
                                 " --out " + (dir / "result.json").string(),
                             &output),
            0)
      << output;
}

}  // namespace
}  // namespace calibench
