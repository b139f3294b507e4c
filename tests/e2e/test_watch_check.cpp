// `calibench watch --check R` on a recording while it is written: a drive through a simulated
// textured room (core/evaluation/check_sweep.h) recorded as an MCAP frame by frame; the drift meter
// follows it, checks every few frames, and ends when the recorder closes the file. A calibration
// turned by 1° is caught and the estimate comes back to the truth; the truth itself is not called
// miscalibrated (checked on the finished recording with `check`).
#include <gtest/gtest.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <thread>

#include "core/evaluation/check_sweep.h"
#include "core/results/result_file.h"
#include "core/results/result_json.h"
#include "core/targetless/edge_alignment.h"
#include "tests/bag_writers.h"
#include "tests/test_support.h"
#include "tests/watch_stream.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

// The scene's frames as a drive recorded at 0.6 s per frame, handed to the writer `pace_ms` apart.
void RecordDrive(const SimulatedCheckScene& scene, test::RecordingWriter* writer, int pace_ms) {
  const MessageEncoding cdr = MessageEncoding::kCdr;
  for (size_t k = 0; k < scene.frames.size(); ++k) {
    const std::int64_t t = 1'000'000'000LL + static_cast<std::int64_t>(k) * 600'000'000LL;
    writer->Add({"/camera/camera_info", "sensor_msgs/CameraInfo", t,
                 test::SerializeCameraInfo(scene.camera, t, "camera", cdr)});
    writer->Add({"/lidar/points", "sensor_msgs/PointCloud2", t,
                 test::SerializePointCloud2(scene.frames[k].cloud, t, "lidar", cdr)});
    writer->Add(
        {"/camera/image_raw", "sensor_msgs/Image", t + 5'000'000,
         test::SerializeImage(scene.frames[k].image, "mono8", t + 5'000'000, "camera", cdr)});
    std::this_thread::sleep_for(std::chrono::milliseconds(pace_ms));
  }
}

TEST(WatchCheck, TheDriftMeterFollowsADriveAndCatchesATurnedCalibration) {
  const fs::path dir = test::TempDir("watch_check");
  CheckSweepOptions options;
  options.lidar = "os0-128";
  options.moving = true;
  options.frames = 12;
  const SimulatedCheckScene scene = SimulateCheckScene(options, 3);
  Vec6 turn = Vec6::Zero();
  turn.tail<3>() = Vec3(0.6, -0.5, 0.62).normalized() * kDegToRad;
  test::WriteBareResult(dir / "truth.json", scene.cam_from_lidar);
  test::WriteBareResult(dir / "turned.json", PerturbOnCameraAxes(scene.cam_from_lidar, turn));

  const fs::path mcap = dir / "drive.mcap";
  const fs::path lines = dir / "drift.jsonl";
  std::string watch_output;
  int watch_code = -1;
  {
    auto writer = test::OpenMcapWriter(mcap, "ros2", "zstd", /*summary=*/true,
                                       /*chunk_bytes=*/256 * 1024);
    std::thread watch([&] {
      watch_code = test::RunCommand("(" + test::CalibenchExe() + " watch " + mcap.string() +
                                        " --check " + (dir / "turned.json").string() +
                                        " --check-every 4 --idle-exit 60 --json-lines > " +
                                        lines.string() + ")",
                                    &watch_output);
    });
    RecordDrive(scene, writer.get(), 400);
    writer->Close();
    watch.join();
  }
  ASSERT_EQ(watch_code, 0) << watch_output;
  const std::vector<nlohmann::json> events = test::ReadJsonLines(lines);
  ASSERT_GE(events.size(), 3u) << watch_output;
  int drifts = 0, last_seen = 0;
  for (const nlohmann::json& e : events) {
    if (e["event"] != "drift") continue;
    ++drifts;
    EXPECT_GT(e["frames_seen"].get<int>(), last_seen) << "each check over more frames";
    last_seen = e["frames_seen"];
  }
  EXPECT_GE(drifts, 2) << "checked while the drive was being written";
  const nlohmann::json& end = events.back();
  ASSERT_EQ(end["event"], "end");
  EXPECT_EQ(end["ended_because"], "the recorder closed the file");
  EXPECT_EQ(end["frames_seen"], 12);
  EXPECT_EQ(end["verdict"], "miscalibrated") << end["why"];
  // The estimate back at the truth, within its σ's reach (0.3° / 30 mm).
  Pose estimate = Pose::Identity();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) estimate.matrix()(r, c) = end["cam_from_lidar"][r][c];
  const Vec6 error = DeltaOnCameraAxes(scene.cam_from_lidar, estimate);
  EXPECT_LT(error.tail<3>().norm() * kRadToDeg, 0.3) << end["why"];
  EXPECT_LT(error.head<3>().norm(), 0.03) << end["why"];

  // The truth on the finished recording, read whole: not called miscalibrated.
  const fs::path check_json = dir / "check.json";
  std::string out;
  ASSERT_EQ(test::RunCommand("(" + test::CalibenchExe() + " check --dataset " + mcap.string() +
                                 " --result " + (dir / "truth.json").string() + " --json > " +
                                 check_json.string() + ")",
                             &out),
            0)
      << out;
  const nlohmann::json truth = nlohmann::json::parse(test::ReadFileBytes(check_json));
  EXPECT_NE(truth["verdict"], "miscalibrated") << truth["why"];
  EXPECT_EQ(truth["frames_given"], 12);

  // A folder of scenes is not followed by the drift meter: said, with the command that checks it.
  const fs::path folder = dir / "scenes";
  fs::create_directories(folder / "clouds");
  fs::create_directories(folder / "images");
  EXPECT_NE(test::RunCommand(test::CalibenchExe() + " watch " + folder.string() + " --check " +
                                 (dir / "truth.json").string(),
                             &out),
            0);
  EXPECT_NE(out.find("calibench check --dataset"), std::string::npos) << out;
}

}  // namespace
}  // namespace calibench
