// Import of recordings made as on-site: the board held still at each pose, carried between poses,
// the LiDAR and the camera streaming throughout (tests/sim_recording.h). One pair per hold, the
// same from MCAP and from a ROS 1 bag, only a couple of board searches per hold, the board
// chosen right without --board, and a refusal that says what to pass when no preset fits.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/capture/bag_import.h"
#include "core/io/cloud_io.h"
#include "core/io/dataset.h"
#include "core/io/image_io.h"
#include "core/io/json_io.h"
#include "core/lidar_camera/pipeline.h"
#include "core/lidar_camera/result_io.h"
#include "core/target/board_camera.h"
#include "tests/sim_recording.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

test::SimRecordingTruth Record(const fs::path& path, const test::SimRecordingOptions& options) {
  const bool bag = path.extension() == ".bag";
  auto writer = bag ? test::OpenRos1BagWriter(path, "lz4")
                    : test::OpenMcapWriter(path, "ros2", "lz4", /*summary=*/true);
  const test::SimRecordingTruth truth = test::WriteSimRecording(
      writer.get(), bag ? MessageEncoding::kRos1 : MessageEncoding::kCdr, options);
  writer->Close();
  return truth;
}

// The hold a stamp falls in, -1 when the board was moving.
int HoldOf(const test::SimRecordingTruth& truth, std::int64_t stamp) {
  for (std::size_t i = 0; i < truth.hold_start_ns.size(); ++i)
    if (stamp >= truth.hold_start_ns[i] && stamp < truth.hold_end_ns[i]) return static_cast<int>(i);
  return -1;
}

nlohmann::json ImportRecord(const BagImportSummary& summary) {
  std::ifstream in(summary.manifest.parent_path() / "import.json");
  return nlohmann::json::parse(in);
}

TEST(RecordingImport, OnePairPerHoldTheSameFromMcapAndBag) {
  const fs::path dir = test::TempDir("recording_import_holds");
  test::SimRecordingOptions options = test::SmallSimRecording(6);
  options.point_times = true;  // velodyne's XYZIRT: each return's `time` after the stamp
  std::vector<nlohmann::json> records;
  for (const char* name : {"capture.mcap", "capture.bag"}) {
    SCOPED_TRACE(name);
    const test::SimRecordingTruth truth = Record(dir / name, options);
    const BagImportSummary summary =
        ImportBag(dir / name, dir / (std::string(name) + ".dataset"), truth.board, {});
    ASSERT_EQ(summary.pair_ids.size(), 6u);
    // A couple of searches per hold, not one per image (there are 15 a second).
    EXPECT_LE(summary.images_searched, 2 * options.poses) << summary.images_searched;
    EXPECT_GE(summary.images, 15 * 20);
    const nlohmann::json record = ImportRecord(summary);
    std::vector<int> holds;
    for (const auto& pair : record["pairs"]) {
      const int hold = HoldOf(truth, pair["cloud_stamp_ns"].get<std::int64_t>());
      EXPECT_GE(hold, 0) << pair.dump();
      holds.push_back(hold);
    }
    EXPECT_EQ(holds, (std::vector<int>{0, 1, 2, 3, 4, 5}));
    // Each return keeps its time, said once: the field `t` after the manifest's lidar_stamp_ns.
    EXPECT_EQ(summary.point_times.rfind("per-point times from 'time' (FLOAT32), read as seconds "
                                        "after the stamp: 0.0",
                                        0),
              0u)
        << summary.point_times;
    EXPECT_EQ(summary.pairs_with_point_times, 6);
    EXPECT_EQ(record["point_times"], summary.point_times);
    // Each pair's image shows its hold's pose.
    const Dataset dataset = LoadDataset(summary.manifest);
    for (std::size_t i = 0; i < dataset.pairs.size(); ++i) {
      ASSERT_TRUE(dataset.pairs[i].lidar_stamp_ns);
      EXPECT_EQ(*dataset.pairs[i].lidar_stamp_ns,
                record["pairs"][i]["cloud_stamp_ns"].get<std::int64_t>());
      const LidarCloud cloud = LoadCloud(dataset.pairs[i].cloud);
      ASSERT_EQ(cloud.time_s.size(), cloud.size());
      const auto [low, high] = std::minmax_element(cloud.time_s.begin(), cloud.time_s.end());
      EXPECT_GE(*low, 0.0f);  // a 10 Hz sweep stamped at its start
      EXPECT_LE(*high, 0.1f);
      EXPECT_GE(*high - *low, 0.09f);
    }
    for (std::size_t i = 0; i < dataset.pairs.size(); ++i) {
      std::string why;
      const auto detection = DetectBoard(LoadImage(dataset.pairs[i].image), truth.board, {}, &why);
      ASSERT_TRUE(detection) << why;
      const auto observation = EstimateBoardPose(truth.camera, *detection, {}, &why);
      ASSERT_TRUE(observation) << why;
      const Pose& held = truth.held_cam_from_board[holds[i]];
      EXPECT_LT((observation->cam_from_board.translation() - held.translation()).norm(), 0.01);
    }
    // And the calibration from it lands on the simulated mount.
    PipelineOptions pipeline;
    pipeline.threads = 2;
    const CalibrationOutcome outcome = CalibrateDataset(dataset, pipeline);
    ASSERT_TRUE(outcome.solution) << outcome.failure;
    EXPECT_NE(FormatSummary(outcome).find("LiDAR times: 6 of 6 boards' returns carry their own "
                                          "times"),
              std::string::npos)
        << FormatSummary(outcome);
    const Pose error = truth.cam_from_lidar.inverse() * outcome.solution->cam_from_lidar;
    EXPECT_LT(error.translation().norm(), 0.03);
    EXPECT_LT(Eigen::AngleAxisd(error.rotation()).angle() * kRadToDeg, 1.0);
    records.push_back(record["pairs"]);
  }
  EXPECT_EQ(records[0], records[1]);
}

// Issue 46 item 3: a Livox Mid-40's recording, its frames as livox_ros_driver/CustomMsg (ROS 1
// bag) and livox_ros_driver2/CustomMsg (ROS 2 MCAP): one pair per hold as with PointCloud2, each
// pair's cloud the hold's frames integrated (about a second of the rosette, not one 0.1 s frame),
// and the calibration from them on the simulated mount.
TEST(RecordingImport, ALivoxCustomMsgRecordingIntegratesEachHold) {
  const fs::path dir = test::TempDir("recording_import_livox");
  test::SimRecordingOptions options = test::SmallSimRecording(6);
  options.lidar = LidarModel::kMid40;
  options.lidar_range_noise_m = 0.02;
  std::vector<nlohmann::json> records;
  for (const char* name : {"livox.mcap", "livox.bag"}) {
    SCOPED_TRACE(name);
    const test::SimRecordingTruth truth = Record(dir / name, options);
    const BagImportSummary summary =
        ImportBag(dir / name, dir / (std::string(name) + ".dataset"), truth.board, {});
    ASSERT_EQ(summary.pair_ids.size(), 6u);
    const nlohmann::json record = ImportRecord(summary);
    std::vector<int> holds;
    for (const auto& pair : record["pairs"])
      holds.push_back(HoldOf(truth, pair["cloud_stamp_ns"].get<std::int64_t>()));
    EXPECT_EQ(holds, (std::vector<int>{0, 1, 2, 3, 4, 5}));
    const Dataset dataset = LoadDataset(summary.manifest);
    // The hold's frames integrated, each return at its own time after the tried frame's stamp.
    EXPECT_EQ(summary.pairs_with_point_times, 6);
    for (const PairEntry& pair : dataset.pairs) {
      const LidarCloud cloud = LoadCloud(pair.cloud);
      EXPECT_FALSE(cloud.HasRing());
      ASSERT_EQ(cloud.time_s.size(), cloud.size());
      const auto [low, high] = std::minmax_element(cloud.time_s.begin(), cloud.time_s.end());
      EXPECT_GE(*high - *low, 0.5f) << pair.id << ": the frames of about a second";
      // A Mid-40 frame holds 10 k returns in a closed room; the second about a try 100 k (the
      // first hold's try comes half a second after the recording starts: 60 k).
      EXPECT_GE(cloud.size(), 50'000u) << pair.id;
      EXPECT_LE(cloud.size(), 110'000u) << pair.id;
    }
    PipelineOptions pipeline;
    pipeline.threads = 2;
    const CalibrationOutcome outcome = CalibrateDataset(dataset, pipeline);
    for (const PairFeatures& p : outcome.pairs)
      if (p.status != PairStatus::kAccepted)
        std::printf("  %s: %s\n", p.id.c_str(), p.reason.c_str());
    ASSERT_TRUE(outcome.solution) << outcome.failure;
    int accepted = 0;
    for (const PairFeatures& p : outcome.pairs) accepted += p.status == PairStatus::kAccepted;
    EXPECT_EQ(accepted, 6);
    EXPECT_NE(DescribeLidarModel(outcome).find("non-repetitive"), std::string::npos);
    const PoseError error =
        ComputePoseError(outcome.solution->cam_from_lidar, truth.cam_from_lidar);
    std::printf("%s: %d pairs, error %.2f mm %.3f deg\n", name, accepted, error.translation_m * 1e3,
                error.rotation_rad * kRadToDeg);
    EXPECT_LT(error.translation_m, 0.02);
    EXPECT_LT(error.rotation_rad * kRadToDeg, 0.5);
    records.push_back(record["pairs"]);
  }
  EXPECT_EQ(records[0], records[1]);
}

// A LiDAR whose sweeps never agree (15 cm of range noise: rain, a non-repeating scan): the
// holds are still found, by trying a sweep every second and letting the camera judge.
TEST(RecordingImport, ALidarThatNeverSeesTheSceneStillHidesNoHold) {
  const fs::path dir = test::TempDir("recording_import_noisy_lidar");
  test::SimRecordingOptions options = test::SmallSimRecording(4);
  options.lidar_range_noise_m = 0.15;
  const test::SimRecordingTruth truth = Record(dir / "noisy.mcap", options);
  const BagImportSummary summary =
      ImportBag(dir / "noisy.mcap", dir / "noisy.dataset", truth.board, {});
  std::vector<int> holds;
  const nlohmann::json record = ImportRecord(summary);
  for (const auto& pair : record["pairs"])
    holds.push_back(HoldOf(truth, pair["cloud_stamp_ns"].get<std::int64_t>()));
  EXPECT_EQ(holds, (std::vector<int>{0, 1, 2, 3}));
}

BoardSpec Board(int cols, int rows, double square, double width, double height) {
  BoardSpec board;
  board.type = BoardType::kCheckerboard;
  board.cols = cols;
  board.rows = rows;
  board.square_size = square;
  board.board_width = width;
  board.board_height = height;
  return board;
}

TEST(RecordingImport, ChoosesThePresetThatFitsWithoutBeingTold) {
  const fs::path dir = test::TempDir("recording_import_board");
  for (const char* preset : {"a4", "a3"}) {
    SCOPED_TRACE(preset);
    test::SimRecordingOptions options = test::SmallSimRecording(3);
    options.board = BoardPreset(preset);
    const fs::path bag = dir / (std::string(preset) + ".mcap");
    Record(bag, options);
    const BagImportSummary summary =
        ImportBag(bag, dir / (std::string(preset) + ".dataset"), std::nullopt, {});
    EXPECT_EQ(summary.board.cols, options.board.cols);
    EXPECT_EQ(summary.board.rows, options.board.rows);
    EXPECT_EQ(summary.board.square_size, options.board.square_size);
    EXPECT_EQ(summary.board_source.rfind(preset, 0), 0u) << summary.board_source;
    EXPECT_EQ(summary.pair_ids.size(), 3u);
    EXPECT_EQ(LoadDataset(summary.manifest).target.cols, options.board.cols);
  }
}

TEST(RecordingImport, ABoardNoPresetExplainsIsRefusedUntilItsTargetLiesBeside) {
  const fs::path dir = test::TempDir("recording_import_large_board");
  // 8x6 inner corners of 70 mm: a4's 5x4 and a3's 7x5 grids are found inside it.
  test::SimRecordingOptions options = test::SmallSimRecording(10);
  options.board = Board(8, 6, 0.07, 0.70, 0.56);
  fs::create_directories(dir / "site");
  const fs::path bag = dir / "site" / "large.mcap";
  const test::SimRecordingTruth truth = Record(bag, options);
  std::int64_t read_when_refused = 0, total = 0;
  try {
    ImportBag(bag, dir / "refused.dataset", std::nullopt, {},
              [&](const std::string& phase, std::int64_t done, std::int64_t all) {
                if (phase == "reading") read_when_refused = done, total = all;
              });
    ADD_FAILURE() << "a board no preset explains was not refused";
  } catch (const IoError& error) {
    // Said as soon as the presets have ruled themselves out, not after the whole recording.
    EXPECT_GT(total, 0);
    EXPECT_LT(read_when_refused, total * 6 / 10) << read_when_refused << " of " << total;
    std::printf("refused after %.0f %% of the recording\n", 100.0 * read_when_refused / total);
    const std::string what = error.what();
    EXPECT_NE(what.find("no preset board explains the images"), std::string::npos) << what;
    EXPECT_NE(what.find("part of a larger board"), std::string::npos) << what;
    EXPECT_NE(what.find("--board"), std::string::npos) << what;
    EXPECT_NE(what.find("--target"), std::string::npos) << what;
  }
  // Named after the recording, as `calibench target` names the file it prints beside a board.
  std::ofstream(dir / "site" / "large.target.json") << json_io::TargetToJson(options.board).dump(2);
  const BagImportSummary summary = ImportBag(bag, dir / "beside.dataset", std::nullopt, {});
  EXPECT_EQ(summary.board.cols, 8);
  EXPECT_EQ(summary.board.square_size, 0.07);
  EXPECT_NE(summary.board_source.find("large.target.json"), std::string::npos);
  EXPECT_NE(summary.board_source.find("beside the recording"), std::string::npos);
  EXPECT_EQ(summary.pair_ids.size(), truth.held_cam_from_board.size());
}

// The last message a reader gets from a recording (its complete part, for one cut short).
std::int64_t LastLogTime(const fs::path& path) {
  std::int64_t last = 0;
  OpenBag(path)->ForEachMessage({}, [&](const BagMessage& message) {
    last = std::max(last, message.log_time_ns);
    return true;
  });
  return last;
}

// A recorder killed mid-write: no index or summary, the last chunk (or sqlite pages) torn off.
// import reads what is complete, says where it stopped, and gives every hold before it.
TEST(RecordingImport, ARecordingCutShortImportsItsCompletePart) {
  const fs::path dir = test::TempDir("recording_import_torn");
  const test::SimRecordingOptions options = test::SmallSimRecording(6);
  for (const char* name : {"torn.mcap", "torn.bag", "torn.db3"}) {
    SCOPED_TRACE(name);
    const fs::path path = dir / name;
    test::SimRecordingTruth truth;
    if (path.extension() == ".db3") {
      auto writer = test::OpenDb3Writer(path, 50);
      truth = test::WriteSimRecording(writer.get(), MessageEncoding::kCdr, options);
      writer->Close();
    } else {
      truth = Record(path, options);
    }
    fs::resize_file(path, fs::file_size(path) * 6 / 10 + 7);
    const std::int64_t complete_until = LastLogTime(path);
    int complete_holds = 0;
    for (const std::int64_t end : truth.hold_end_ns) complete_holds += end <= complete_until;
    ASSERT_GE(complete_holds, 2);
    const BagImportSummary summary =
        ImportBag(path, dir / (std::string(name) + ".dataset"), truth.board, {});
    EXPECT_NE(summary.cut_short.find("cut short"), std::string::npos) << summary.cut_short;
    EXPECT_NE(summary.cut_short.find(path.string()), std::string::npos) << summary.cut_short;
    std::printf("%s: %s; %zu pairs, %d holds complete\n", name, summary.cut_short.c_str(),
                summary.pair_ids.size(), complete_holds);
    // Every hold before the tear, and at most the one it cut into.
    EXPECT_GE(static_cast<int>(summary.pair_ids.size()), complete_holds);
    EXPECT_LE(static_cast<int>(summary.pair_ids.size()), complete_holds + 1);
    EXPECT_EQ(ImportRecord(summary).value("cut_short", ""), summary.cut_short);
    // The command says it too, and succeeds.
    std::string output;
    EXPECT_EQ(
        test::RunCommand(test::CalibenchExe() + " import " + path.string() + " --board a3 -o " +
                             (dir / (std::string(name) + ".cli")).string(),
                         &output),
        0)
        << output;
    EXPECT_NE(output.find("cut short"), std::string::npos) << output;
  }
}

// The peak resident memory (kB) of `command` by /usr/bin/time -v, -1 when unreadable; its exit
// code in *code.
long PeakKb(const std::string& command, int* code) {
  std::string output;
  *code = test::RunCommand("/usr/bin/time -v " + command, &output);
  const std::string key = "Maximum resident set size (kbytes): ";
  const auto at = output.find(key);
  return at == std::string::npos ? -1 : std::stol(output.substr(at + key.size()));
}

// Issue 46's recording at full length: a Mid-40 at 10 Hz as CustomMsg, 20 poses held 6 s each
// (ROS 1 bag and MCAP, ~160 s, ~1 GB each). `import` and `watch` (following the finished file)
// give one integrated pair per hold, the same pairs; import's peak memory against a VLP-16
// PointCloud2 recording of the same length. Minutes and gigabytes: run by
// scripts/long_recordings.sh (CALIBENCH_LONG=1), not by CI.
TEST(RecordingImport, LongLivoxRecordingAsUsersRecordIt) {
  if (!std::getenv("CALIBENCH_LONG"))
    GTEST_SKIP() << "a long measurement: scripts/long_recordings.sh runs it (CALIBENCH_LONG=1)";
  const fs::path dir = test::TempDir("recording_import_livox_long");
  test::SimRecordingOptions options;  // 6 s holds, 2 s moves, 10 Hz clouds, 15 Hz images
  options.poses = 20;
  options.image_width = 640;
  options.image_height = 360;
  options.max_distance_m = 3.0;
  test::SimRecordingOptions spinning = options;
  options.lidar = LidarModel::kMid40;
  options.lidar_range_noise_m = 0.02;
  struct Run {
    const char* name;
    const test::SimRecordingOptions* recording;
  };
  long spinning_peak_kb = 0;
  std::vector<std::string> livox_clouds;
  for (const Run run :
       {Run{"vlp16.mcap", &spinning}, Run{"livox.mcap", &options}, Run{"livox.bag", &options}}) {
    SCOPED_TRACE(run.name);
    const test::SimRecordingTruth truth = Record(dir / run.name, *run.recording);
    const fs::path imported = dir / (std::string(run.name) + ".imported");
    int code = 0;
    const long peak_kb = PeakKb(test::CalibenchExe() + " import " + (dir / run.name).string() +
                                    " --board a3 -o " + imported.string(),
                                &code);
    ASSERT_EQ(code, 0);
    const Dataset dataset = LoadDataset(imported);
    PipelineOptions pipeline;
    pipeline.threads = 2;
    const CalibrationOutcome outcome = CalibrateDataset(dataset, pipeline);
    ASSERT_TRUE(outcome.solution) << outcome.failure;
    int accepted = 0;
    for (const PairFeatures& p : outcome.pairs) accepted += p.status == PairStatus::kAccepted;
    const PoseError error =
        ComputePoseError(outcome.solution->cam_from_lidar, truth.cam_from_lidar);
    std::printf(
        "%s: %.0f s, %.0f MB; import peak %.0f MB; %zu pairs, %d accepted; error %.2f mm "
        "%.3f deg\n",
        run.name, truth.seconds, fs::file_size(dir / run.name) / 1e6, peak_kb / 1e3,
        dataset.pairs.size(), accepted, error.translation_m * 1e3, error.rotation_rad * kRadToDeg);
    EXPECT_EQ(dataset.pairs.size(), 20u);
    EXPECT_GE(accepted, 18);
    EXPECT_LT(error.translation_m, 0.01);
    EXPECT_LT(error.rotation_rad * kRadToDeg, 0.3);
    if (run.recording == &spinning) {
      spinning_peak_kb = peak_kb;
      continue;
    }
    // Bounded as import's memory is for PointCloud2: a second of sweeps instead of 0.4 s.
    EXPECT_LT(peak_kb, 2 * spinning_peak_kb);
    // `watch` on the finished recording: the same pairs, byte for byte.
    const fs::path watched = dir / (std::string(run.name) + ".watched");
    ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " watch " + (dir / run.name).string() +
                               " --board a3 --json-lines --idle-exit 5 --out " + watched.string() +
                               " > " + (dir / "watch.jsonl").string() + " 2>/dev/null"),
              0);
    for (const PairEntry& pair : dataset.pairs) {
      const fs::path cloud = watched / "clouds" / pair.cloud.filename();
      ASSERT_TRUE(fs::exists(cloud)) << cloud;
      EXPECT_EQ(test::ReadFileBytes(cloud), test::ReadFileBytes(pair.cloud)) << cloud;
      EXPECT_GE(LoadCloud(cloud).size(), 50'000u) << cloud;  // integrated: 10 k in one frame
    }
  }
}

}  // namespace
}  // namespace calibench
