// `calibench watch` on a recording while its recorder writes it: an MCAP, a ROS 1 bag and rosbag2
// folders of an MCAP and of a .db3, written message by message at 4x real time (complete chunks
// reach the file as they fill; the index, summary or metadata.yaml only at the end). The watch
// follows, says each pair, ends when the recorder closes the file, and its pairs are exactly what
// `import` makes of the finished recording.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <thread>

#include "core/geometry/geometry.h"
#include "core/io/cloud_io.h"
#include "core/io/json_io.h"
#include "core/results/result_file.h"
#include "tests/sim_recording.h"
#include "tests/test_support.h"
#include "tests/watch_stream.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;
using test::PoseFromRows;
using test::ReadJsonLines;

// Hands messages on no faster than `speedup` times the recording's own clock.
class PacedWriter : public test::RecordingWriter {
 public:
  PacedWriter(std::unique_ptr<test::RecordingWriter> inner, double speedup)
      : inner_(std::move(inner)), speedup_(speedup) {}
  void Add(const test::RecordedMessage& message) override {
    if (first_ns_ == 0) {
      first_ns_ = message.log_time_ns;
      start_ = std::chrono::steady_clock::now();
    }
    const auto due = start_ + std::chrono::nanoseconds(static_cast<std::int64_t>(
                                  (message.log_time_ns - first_ns_) / speedup_));
    std::this_thread::sleep_until(due);
    inner_->Add(message);
  }
  void Close() override { inner_->Close(); }

 private:
  std::unique_ptr<test::RecordingWriter> inner_;
  double speedup_;
  std::int64_t first_ns_ = 0;
  std::chrono::steady_clock::time_point start_;
};

std::vector<std::string> Pngs(const fs::path& images) {
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(images)) files.push_back(entry.path().filename());
  std::sort(files.begin(), files.end());
  return files;
}

// `import` of the finished recording into dir/imported gives the pairs the watch wrote into
// dir/watched, byte for byte (images and clouds); their images' names.
std::vector<std::string> ExpectImportGivesTheWatchedPairs(const fs::path& source,
                                                          const fs::path& dir, size_t pairs) {
  std::string output;
  EXPECT_EQ(test::RunCommand(test::CalibenchExe() + " import " + source.string() +
                                 " --board a3 -o " + (dir / "imported").string(),
                             &output),
            0)
      << output;
  const std::vector<std::string> watched = Pngs(dir / "watched/images");
  EXPECT_EQ(watched, Pngs(dir / "imported/images"));
  EXPECT_EQ(watched.size(), pairs) << test::ReadFileBytes(dir / "stream.jsonl");
  for (const std::string& png : watched) {
    EXPECT_EQ(test::ReadFileBytes(dir / "watched/images" / png),
              test::ReadFileBytes(dir / "imported/images" / png))
        << png;
    const std::string pcd = fs::path(png).replace_extension(".pcd");
    EXPECT_EQ(test::ReadFileBytes(dir / "watched/clouds" / pcd),
              test::ReadFileBytes(dir / "imported/clouds" / pcd))
        << pcd;
  }
  return watched;
}

TEST(WatchRecording, FollowsRecordingsWhileWrittenAndEndsWithImportsPairs) {
  const test::SimRecordingOptions options = test::SmallSimRecording(4);
  struct Case {
    const char* name;
    const char* file;  // in a rosbag2 folder (metadata.yaml written at the end); "" = no folder
  };
  for (const Case c :
       {Case{"capture.mcap", ""}, Case{"capture.bag", ""}, Case{"rosbag2_mcap", "capture_0.mcap"},
        Case{"rosbag2_db3", "capture_0.db3"}}) {
    SCOPED_TRACE(c.name);
    const fs::path dir = test::TempDir(std::string("watch_recording_") + c.name);
    const fs::path source = dir / c.name;
    const bool folder = *c.file != 0;
    const fs::path file = folder ? source / c.file : source;
    const bool bag = file.extension() == ".bag", db3 = file.extension() == ".db3";
    if (folder) fs::create_directories(source);
    const fs::path stream = dir / "stream.jsonl";
    // The MCAP at the recording's own pace, the others 4x faster (the test's time).
    const double speedup = std::string(c.name) == "capture.mcap" ? 1.0 : 4.0;
    auto open_writer = [&] {
      return std::make_unique<PacedWriter>(
          bag   ? test::OpenRos1BagWriter(file, "lz4", 256 * 1024)
          : db3 ? test::OpenDb3Writer(file, 50)
                : test::OpenMcapWriter(file, "ros2", "lz4", true, 256 * 1024),
          speedup);
    };
    // A single file: the watch starts first, the recording does not exist yet. A rosbag2 folder
    // is recognised by its files: `ros2 bag record` creates the first one with the folder.
    std::unique_ptr<PacedWriter> writer = folder ? open_writer() : nullptr;
    std::thread watch([&] {
      test::RunCommand(test::CalibenchExe() + " watch " + source.string() +
                       " --board a3 --json-lines --idle-exit 20 --out " +
                       (dir / "watched").string() + " > " + stream.string() + " 2>&1");
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    std::string write_error;
    try {
      if (!writer) writer = open_writer();
      test::WriteSimRecording(writer.get(), bag ? MessageEncoding::kRos1 : MessageEncoding::kCdr,
                              options);
      writer->Close();
    } catch (const std::exception& e) {
      write_error = e.what();  // the watch still ends (--idle-exit) and is joined below
    }
    if (folder) std::ofstream(source / "metadata.yaml") << "rosbag2_bagfile_information:\n";
    watch.join();
    ASSERT_EQ(write_error, "");

    const std::vector<json> lines = ReadJsonLines(stream);
    ASSERT_FALSE(lines.empty());
    int pairs = 0, accepted = 0, solves = 0;
    std::optional<json> last_solve;
    for (const json& line : lines) {
      if (line["event"] == "pair") {
        ++pairs;
        accepted += line["accepted"].get<bool>();
      }
      if (line["event"] == "solve") {
        ++solves;
        last_solve = line;
      }
    }
    EXPECT_EQ(pairs, 4);
    EXPECT_EQ(accepted, 4);
    EXPECT_GE(solves, 1);
    EXPECT_EQ(lines.back()["event"], "end");
    EXPECT_EQ(lines.back()["reason"], "the recording was closed by its recorder");

    // `import` of the finished recording: the same pairs, byte for byte.
    ExpectImportGivesTheWatchedPairs(source, dir, 4);
    std::string output;
    // `calibrate` on the imported recording ends where the watch's last solve ended.
    ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " calibrate --dataset " +
                                   (dir / "imported").string() + " --out " +
                                   (dir / "result.json").string(),
                               &output),
              0)
        << output;
    ASSERT_TRUE(last_solve && !(*last_solve)["cam_from_lidar"].is_null());
    const PoseError difference = ComputePoseError(PoseFromRows((*last_solve)["cam_from_lidar"]),
                                                  LoadResult(dir / "result.json").cam_from_source);
    EXPECT_LT(difference.translation_m, 0.0005);
    EXPECT_LT(difference.rotation_rad * kRadToDeg, 0.01);
    // And the watched folder is a dataset at any moment: calibrate reads it too.
    EXPECT_EQ(test::RunCommand(test::CalibenchExe() + " calibrate --dataset " +
                                   (dir / "watched").string() + " --out " +
                                   (dir / "watched_result.json").string(),
                               &output),
              0)
        << output;
  }
}

// A Livox Mid-40 recording (`livox_ros_driver/CustomMsg` in a ROS 1 bag, 10 Hz) while it is
// written: the watch integrates each still hold's ring-less sweeps into one cloud as import does,
// and its pairs are import's, byte for byte.
TEST(WatchRecording, ALivoxCustomMsgRecordingGivesImportsIntegratedPairs) {
  test::SimRecordingOptions options = test::SmallSimRecording(5);
  options.lidar = LidarModel::kMid40;
  options.lidar_range_noise_m = 0.02;
  const fs::path dir = test::TempDir("watch_recording_livox");
  const fs::path source = dir / "livox.bag", stream = dir / "stream.jsonl";
  std::thread watch([&] {
    test::RunCommand(test::CalibenchExe() + " watch " + source.string() +
                     " --board a3 --json-lines --idle-exit 20 --out " + (dir / "watched").string() +
                     " > " + stream.string() + " 2>/dev/null");
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  PacedWriter writer(test::OpenRos1BagWriter(source, "lz4", 256 * 1024), 4.0);
  test::WriteSimRecording(&writer, MessageEncoding::kRos1, options);
  writer.Close();
  watch.join();
  const std::vector<json> lines = ReadJsonLines(stream);
  ASSERT_FALSE(lines.empty());
  int pairs = 0, accepted = 0;
  for (const json& line : lines) {
    if (line["event"] != "pair") continue;
    ++pairs;
    accepted += line["accepted"].get<bool>();
  }
  EXPECT_EQ(pairs, 5) << test::ReadFileBytes(stream);
  EXPECT_EQ(accepted, 5) << test::ReadFileBytes(stream);
  EXPECT_EQ(lines.back()["reason"], "the recording was closed by its recorder");
  // Integrated: a 0.1 s Mid-40 frame holds ~10 k returns, the hold's second several times that.
  for (const std::string& png : ExpectImportGivesTheWatchedPairs(source, dir, 5)) {
    const std::string pcd = fs::path(png).replace_extension(".pcd");
    EXPECT_GE(LoadCloud(dir / "watched/clouds" / pcd).size(), 40'000u) << pcd;
  }
}

// Passes every message on with `extra` messages of a busy topic the watch does not use (an IMU at
// a few hundred hertz) before it.
class WithBusyTopic : public test::RecordingWriter {
 public:
  WithBusyTopic(std::unique_ptr<test::RecordingWriter> inner, int extra)
      : inner_(std::move(inner)), extra_(extra) {}
  void Add(const test::RecordedMessage& message) override {
    for (int i = 0; i < extra_; ++i)
      inner_->Add({"/imu/data", "sensor_msgs/Imu", message.log_time_ns - extra_ + i,
                   std::vector<std::uint8_t>(64, static_cast<std::uint8_t>(i))});
    inner_->Add(message);
  }
  void Close() override { inner_->Close(); }

 private:
  std::unique_ptr<test::RecordingWriter> inner_;
  int extra_;
};

// A recording already finished when the watch starts (copied from the robot, say) is read in one
// go: its topics are chosen as soon as they appear, so none of its thousands of messages is held
// back and lost (the watch once kept the last 2000 and gave the late holds as the first pairs).
TEST(WatchRecording, AFinishedRecordingIsReadWhole) {
  const test::SimRecordingOptions options = test::SmallSimRecording(6);
  const fs::path dir = test::TempDir("watch_recording_finished");
  const fs::path source = dir / "finished.mcap";
  WithBusyTopic writer(test::OpenMcapWriter(source, "ros2", "lz4", true, 256 * 1024), 8);
  const test::SimRecordingTruth truth =
      test::WriteSimRecording(&writer, MessageEncoding::kCdr, options);
  writer.Close();
  ASSERT_GT(truth.messages * 9, 2000);
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " watch " + source.string() +
                             " --board a3 --json-lines --idle-exit 10 --out " +
                             (dir / "watched").string() + " > " + (dir / "stream.jsonl").string() +
                             " 2>/dev/null"),
            0);
  ExpectImportGivesTheWatchedPairs(source, dir, 6);
}

// A board no preset explains, on a recording still being written: the true reason said as soon as
// the presets rule themselves out (not "no new data" while data still comes), the watch follows
// on, and the pairs come once the board's target file is put beside the recording.
TEST(WatchRecording, ABoardNoPresetExplainsIsSaidLiveAndTheWatchWaitsForIt) {
  test::SimRecordingOptions options = test::SmallSimRecording(10);
  options.board.type = BoardType::kCheckerboard;
  options.board.cols = 8;
  options.board.rows = 6;
  options.board.square_size = 0.07;
  options.board.board_width = 0.70;
  options.board.board_height = 0.56;
  const fs::path dir = test::TempDir("watch_recording_unknown_board");
  const fs::path source = dir / "large.mcap", stream = dir / "stream.jsonl";
  // --idle-exit 10: shorter than the recording; only data that keeps coming keeps the watch on.
  std::thread watch([&] {
    test::RunCommand(test::CalibenchExe() + " watch " + source.string() +
                     " --json-lines --idle-exit 10 --out " + (dir / "watched").string() + " > " +
                     stream.string() + " 2>/dev/null");
  });
  // The recorder pauses after the sixth pose until the watch says why no pair comes (at most a
  // minute), then the user puts the board's file beside the recording and the recording goes on.
  const test::SimRecordingTruth plan = test::PlanSimRecording(options);
  bool said_while_written = false;
  auto pause = [&] {
    for (int i = 0; i < 600; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      if (test::ReadFileBytes(stream).find("no preset board explains the images") ==
          std::string::npos)
        continue;
      said_while_written = true;
      break;
    }
    std::ofstream(dir / "large.target.json.tmp") << json_io::TargetToJson(options.board).dump(2);
    fs::rename(dir / "large.target.json.tmp", dir / "large.target.json");
  };
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  test::PausingWriter writer(
      std::make_unique<PacedWriter>(test::OpenMcapWriter(source, "ros2", "lz4", true, 256 * 1024),
                                    2.0),
      pause, plan.hold_end_ns[5]);
  test::WriteSimRecording(&writer, MessageEncoding::kCdr, options);
  writer.Close();
  watch.join();
  EXPECT_TRUE(said_while_written) << test::ReadFileBytes(stream);
  const std::vector<json> lines = ReadJsonLines(stream);
  ASSERT_FALSE(lines.empty());
  int pairs = 0;
  bool board_from_file = false;
  for (const json& line : lines) {
    pairs += line["event"] == "pair";
    board_from_file |= line["event"] == "note" &&
                       line["reason"].get<std::string>().find("board: from") != std::string::npos;
  }
  EXPECT_TRUE(board_from_file) << test::ReadFileBytes(stream);
  EXPECT_GE(pairs, 6) << test::ReadFileBytes(stream);
  EXPECT_EQ(lines.back()["reason"], "the recording was closed by its recorder");
}

}  // namespace
}  // namespace calibench
