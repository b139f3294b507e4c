// A waved board's recording imported as a user records one (tests/sim_recording.h): every sweep
// that sees the board a pair with the camera frames around it, and the clocks' offset found from
// them; and still holds whose camera stamps run late, paired by stillness, not by stamps, with
// the offset said to be beyond what still boards can tell.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "core/capture/bag_import.h"
#include "core/geometry/geometry.h"
#include "core/io/cloud_io.h"
#include "core/io/dataset.h"
#include "core/lidar_camera/pipeline.h"
#include "core/lidar_camera/result_io.h"
#include "tests/sim_recording.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

nlohmann::json ReadImportRecord(const BagImportSummary& summary) {
  std::ifstream in(summary.manifest.parent_path() / "import.json");
  return nlohmann::json::parse(in);
}

// The imported wave calibrated as `calibrate` would: the clocks within 3 ms and 3 sigma of the
// simulated offset, the extrinsic within 1 cm and 0.3 deg of the truth.
void ExpectTheImportedWaveCalibrates(const Dataset& dataset, const WavedDataset& waved,
                                     const WaveOptions& wave, const char* label) {
  PipelineOptions pipeline;
  pipeline.threads = 2;
  const CalibrationOutcome outcome = CalibrateDataset(dataset, pipeline);
  ASSERT_TRUE(outcome.solution) << outcome.failure;
  const TimeOffsetEstimate& t = outcome.time_offset;
  ASSERT_TRUE(t.camera_minus_lidar_s) << t.why;
  const PoseError error = ComputePoseError(outcome.solution->cam_from_lidar,
                                           *waved.dataset.cam_from_lidar_ground_truth);
  std::printf("%s: offset %+.2f +- %.2f ms (true %+.0f), extrinsic %.2f mm %.3f deg\n", label,
              *t.camera_minus_lidar_s * 1e3, t.std_s * 1e3, wave.camera_minus_lidar_s * 1e3,
              error.translation_m * 1e3, error.rotation_rad * kRadToDeg);
  EXPECT_NEAR(*t.camera_minus_lidar_s, wave.camera_minus_lidar_s, 0.003);
  EXPECT_LE(std::abs(*t.camera_minus_lidar_s - wave.camera_minus_lidar_s), 3 * t.std_s + 1e-4);
  EXPECT_LT(error.translation_m, 0.01);
  EXPECT_LT(error.rotation_rad * kRadToDeg, 0.3);
}

// A pair's cloud of one 0.1 s sweep, each return at its own time after the stamp.
void ExpectOneSweepsTimes(const PairEntry& pair) {
  const LidarCloud cloud = LoadCloud(pair.cloud);
  ASSERT_TRUE(cloud.HasTime()) << pair.id;
  const auto [lo, hi] = std::minmax_element(cloud.time_s.begin(), cloud.time_s.end());
  EXPECT_GE(*lo, 0.0f);
  EXPECT_LE(*hi, 0.1f);
  EXPECT_GT(*hi - *lo, 0.09f);  // a whole sweep, not a hold's integration
}

TEST(WavedRecording, ImportKeepsEverySweepThatSeesTheBoardWithItsFrames) {
  const fs::path dir = test::TempDir("waved_recording");
  WaveOptions wave;
  wave.rig.lidar = LidarModel::kVlp16;
  wave.rig.lidar_range_noise_m = 0.01;
  wave.rig.seed = 5;
  wave.duration_s = 8.0;
  wave.camera_minus_lidar_s = 0.040;
  auto writer = test::OpenRos1BagWriter(dir / "wave.bag", "lz4");
  const WavedDataset waved =
      test::WriteWavedRecording(writer.get(), MessageEncoding::kRos1, wave, dir / "sim");
  writer->Close();

  BagImportOptions options;
  options.max_pairs = 0;
  const BagImportSummary summary =
      ImportBag(dir / "wave.bag", dir / "wave.dataset", waved.dataset.target, options);
  // Every sweep that sees the board, from the wave's start (the motion's first moving_after_s
  // tried once it has lasted that long), whose frames reach both sides of it.
  const std::int64_t first_ns = waved.sweep_files.front().second;
  int expected = 0;
  std::set<std::int64_t> board_sweeps;
  for (const PairEntry& pair : waved.dataset.pairs) {
    board_sweeps.insert(*pair.lidar_stamp_ns);
    const double at_s = (*pair.lidar_stamp_ns - first_ns) * 1e-9;
    expected += at_s >= 0.1 && at_s <= wave.duration_s - 0.2;
  }
  std::printf("%d sweeps, %zu see the board; %d moving pairs imported (%d expected)\n",
              waved.sweeps, waved.dataset.pairs.size(), summary.moving_pairs, expected);
  EXPECT_EQ(summary.moving_pairs, static_cast<int>(summary.pair_ids.size()));
  EXPECT_GE(summary.moving_pairs, expected * 9 / 10);
  EXPECT_LE(summary.moving_pairs, static_cast<int>(waved.dataset.pairs.size()));
  const nlohmann::json record = ReadImportRecord(summary);
  EXPECT_EQ(record.at("moving_pairs"), summary.moving_pairs);

  std::set<std::int64_t> frame_stamps;
  for (const StampedImage& frame : waved.frame_files) frame_stamps.insert(frame.stamp_ns);
  const Dataset dataset = LoadDataset(summary.manifest);
  for (const PairEntry& pair : dataset.pairs) {
    SCOPED_TRACE(pair.id);
    ASSERT_TRUE(pair.lidar_stamp_ns);
    EXPECT_TRUE(board_sweeps.count(*pair.lidar_stamp_ns));  // a sweep that sees the board
    ASSERT_GE(pair.images.size(), 3u);
    bool before = false, after = false;
    for (const StampedImage& frame : pair.images) {
      EXPECT_TRUE(frame_stamps.count(frame.stamp_ns));  // the camera's own stamps, kept
      EXPECT_TRUE(fs::exists(frame.image));
      EXPECT_LE(std::llabs(frame.stamp_ns - *pair.lidar_stamp_ns), 450'000'000);
      before |= frame.stamp_ns <= *pair.lidar_stamp_ns;
      after |= frame.stamp_ns >= *pair.lidar_stamp_ns;
    }
    EXPECT_TRUE(before && after);
    EXPECT_TRUE(LoadCloud(pair.cloud).HasTime());
  }

  ExpectTheImportedWaveCalibrates(dataset, waved, wave, "imported wave");
}

// An Ouster's per-point `t` (uint32 ns after the stamp, ouster_ros's PointOS) in a ROS 2 MCAP,
// the camera's stamps 120 ms early: each return read at its own time, the offset found.
TEST(WavedRecording, AnOustersOwnTFieldTellsACameraRunningEarly) {
  const fs::path dir = test::TempDir("waved_ouster");
  WaveOptions wave;
  wave.rig.lidar = LidarModel::kOs0_128;
  wave.rig.lidar_range_noise_m = 0.01;
  wave.rig.seed = 9;
  wave.duration_s = 8.0;
  wave.camera_minus_lidar_s = -0.120;
  auto writer = test::OpenMcapWriter(dir / "wave.mcap", "ros2", "zstd");
  const WavedDataset waved = test::WriteWavedRecording(writer.get(), MessageEncoding::kCdr, wave,
                                                       dir / "sim", test::PointLayout::kOuster);
  writer->Close();

  BagImportOptions options;
  options.max_pairs = 0;
  const BagImportSummary summary =
      ImportBag(dir / "wave.mcap", dir / "wave.dataset", waved.dataset.target, options);
  std::printf("Ouster wave: %zu of %d sweeps see the board; %d moving pairs imported\n",
              waved.dataset.pairs.size(), waved.sweeps, summary.moving_pairs);
  EXPECT_GE(summary.moving_pairs, static_cast<int>(waved.dataset.pairs.size()) * 8 / 10);
  const Dataset dataset = LoadDataset(summary.manifest);
  ASSERT_FALSE(dataset.pairs.empty());
  // The times as the sim gave them, through the driver's integer nanoseconds.
  ExpectOneSweepsTimes(dataset.pairs.front());

  ExpectTheImportedWaveCalibrates(dataset, waved, wave, "Ouster wave");
}

// A Livox-class rosette waved (Mid-40 frames as livox_ros_driver's CustomMsg, each point's
// offset_time after the frame's timebase): its LiDAR sees nothing still, so the camera's word on
// the blind tries tells the wave, and each frame alone is a moving pair.
TEST(WavedRecording, ALivoxCustomMsgWaveIsTakenFrameByFrame) {
  const fs::path dir = test::TempDir("waved_livox");
  WaveOptions wave;
  wave.rig.lidar = LidarModel::kMid40;
  wave.rig.lidar_range_noise_m = 0.01;
  wave.rig.seed = 13;
  wave.duration_s = 10.0;
  wave.across_m = 0.4;  // within the 38.4 deg circle
  wave.camera_minus_lidar_s = 0.040;
  auto writer = test::OpenRos1BagWriter(dir / "wave.bag", "lz4");
  const WavedDataset waved =
      test::WriteWavedRecording(writer.get(), MessageEncoding::kRos1, wave, dir / "sim");
  writer->Close();

  BagImportOptions options;
  options.max_pairs = 0;
  const BagImportSummary summary =
      ImportBag(dir / "wave.bag", dir / "wave.dataset", waved.dataset.target, options);
  std::printf("Livox wave: %zu of %d frames see the board; %d moving pairs imported\n",
              waved.dataset.pairs.size(), waved.sweeps, summary.moving_pairs);
  EXPECT_EQ(summary.moving_pairs, static_cast<int>(summary.pair_ids.size()));
  // Every frame but the blind tries' (one a second) and the wave's ends.
  EXPECT_GE(summary.moving_pairs, static_cast<int>(waved.dataset.pairs.size()) * 3 / 4);
  const Dataset dataset = LoadDataset(summary.manifest);
  ASSERT_FALSE(dataset.pairs.empty());
  ExpectOneSweepsTimes(dataset.pairs[dataset.pairs.size() / 2]);

  ExpectTheImportedWaveCalibrates(dataset, waved, wave, "Livox wave");
}

// Issue 77's Show: a still-hold recording whose camera stamps run 80 ms late. The holds are
// found by stillness, so the pairs are the holds as ever; the offset is not claimed.
TEST(WavedRecording, StillHoldsWithLateCameraStampsPairByStillnessAndTellNoOffset) {
  const fs::path dir = test::TempDir("late_camera_holds");
  test::SimRecordingOptions options = test::SmallSimRecording(6);
  options.point_times = true;
  options.camera_minus_lidar_s = 0.080;
  auto writer = test::OpenRos1BagWriter(dir / "late.bag", "lz4");
  const test::SimRecordingTruth truth =
      test::WriteSimRecording(writer.get(), MessageEncoding::kRos1, options);
  writer->Close();
  const BagImportSummary summary =
      ImportBag(dir / "late.bag", dir / "late.dataset", truth.board, {});
  ASSERT_EQ(summary.pair_ids.size(), 6u);
  EXPECT_EQ(summary.moving_pairs, 0);
  const nlohmann::json record = ReadImportRecord(summary);
  for (std::size_t i = 0; i < 6; ++i) {
    const std::int64_t stamp = record["pairs"][i]["cloud_stamp_ns"].get<std::int64_t>();
    EXPECT_GE(stamp, truth.hold_start_ns[i]) << i;
    EXPECT_LT(stamp, truth.hold_end_ns[i]) << i;
  }
  PipelineOptions pipeline;
  pipeline.threads = 2;
  const CalibrationOutcome outcome = CalibrateDataset(LoadDataset(summary.manifest), pipeline);
  ASSERT_TRUE(outcome.solution) << outcome.failure;
  EXPECT_FALSE(outcome.time_offset.camera_minus_lidar_s);
  std::printf("late camera, still holds: \"%s\"\n", outcome.time_offset.why.c_str());
  EXPECT_EQ(outcome.time_offset.why.rfind("every pair is a still hold", 0), 0u);
  const Pose error = truth.cam_from_lidar.inverse() * outcome.solution->cam_from_lidar;
  EXPECT_LT(error.translation().norm(), 0.03);
  EXPECT_LT(Eigen::AngleAxisd(error.rotation()).angle() * kRadToDeg, 1.0);
}

}  // namespace
}  // namespace calibench
