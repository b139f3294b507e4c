// `calibench watch` on a recording while its recorder writes it: an MCAP, a ROS 1 bag and a
// rosbag2 folder, written message by message at 4x real time (complete chunks reach the file as
// they fill; the index, summary or metadata.yaml only at the end). The watch follows, says each
// pair, ends when the recorder closes the file, and its pairs are exactly what `import` makes of
// the finished recording.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "tests/sim_recording.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

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

std::vector<json> ReadJsonLines(const fs::path& path) {
  std::vector<json> lines;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] != '{') continue;  // OpenCV's own warnings on stderr
    lines.push_back(json::parse(line));
  }
  return lines;
}

std::vector<std::string> Pngs(const fs::path& images) {
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(images)) files.push_back(entry.path().filename());
  std::sort(files.begin(), files.end());
  return files;
}

TEST(WatchRecording, FollowsRecordingsWhileWrittenAndEndsWithImportsPairs) {
  test::SimRecordingOptions options;
  options.poses = 4;
  options.hold_s = 2.5;
  options.move_s = 1.0;
  options.image_width = 640;
  options.image_height = 360;
  options.max_distance_m = 2.5;
  struct Case {
    const char* name;
    bool folder;  // a rosbag2 folder: capture_0.mcap, then metadata.yaml at the end
  };
  for (const Case c :
       {Case{"capture.mcap", false}, Case{"capture.bag", false}, Case{"rosbag2_capture", true}}) {
    SCOPED_TRACE(c.name);
    const fs::path dir = test::TempDir(std::string("watch_recording_") + c.name);
    const fs::path source = dir / c.name;
    const fs::path file = c.folder ? source / "capture_0.mcap" : source;
    const bool bag = fs::path(c.name).extension() == ".bag";
    if (c.folder) fs::create_directories(source);
    const fs::path stream = dir / "stream.jsonl";
    // The watch starts first: the recording does not exist yet.
    std::thread watch([&] {
      test::RunCommand(test::CalibenchExe() + " watch " + source.string() +
                       " --board a3 --json-lines --idle-exit 20 --out " +
                       (dir / "watched").string() + " > " + stream.string() + " 2>&1");
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    {
      PacedWriter writer(bag ? test::OpenRos1BagWriter(file, "lz4", 256 * 1024)
                             : test::OpenMcapWriter(file, "ros2", "lz4", true, 256 * 1024),
                         4.0);
      test::WriteSimRecording(&writer, bag ? MessageEncoding::kRos1 : MessageEncoding::kCdr,
                              options);
      writer.Close();
    }
    if (c.folder) std::ofstream(source / "metadata.yaml") << "rosbag2_bagfile_information:\n";
    watch.join();

    const std::vector<json> lines = ReadJsonLines(stream);
    ASSERT_FALSE(lines.empty());
    int pairs = 0, accepted = 0, solves = 0;
    for (const json& line : lines) {
      if (line["event"] == "pair") {
        ++pairs;
        accepted += line["accepted"].get<bool>();
      }
      solves += line["event"] == "solve";
    }
    EXPECT_EQ(pairs, 4);
    EXPECT_EQ(accepted, 4);
    EXPECT_GE(solves, 1);
    EXPECT_EQ(lines.back()["event"], "end");
    EXPECT_EQ(lines.back()["reason"], "the recording was closed by its recorder");

    // `import` of the finished recording: the same pairs, byte for byte.
    std::string output;
    ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " import " + source.string() +
                                   " --board a3 -o " + (dir / "imported").string(),
                               &output),
              0)
        << output;
    const std::vector<std::string> watched = Pngs(dir / "watched/images");
    ASSERT_EQ(watched, Pngs(dir / "imported/images"));
    ASSERT_EQ(watched.size(), 4u);
    for (const std::string& png : watched) {
      EXPECT_EQ(test::ReadFileBytes(dir / "watched/images" / png),
                test::ReadFileBytes(dir / "imported/images" / png))
          << png;
      const std::string pcd = fs::path(png).replace_extension(".pcd");
      EXPECT_EQ(test::ReadFileBytes(dir / "watched/clouds" / pcd),
                test::ReadFileBytes(dir / "imported/clouds" / pcd))
          << pcd;
    }
    // The watched folder is a dataset at any moment: calibrate reads it.
    EXPECT_EQ(test::RunCommand(test::CalibenchExe() + " calibrate --dataset " +
                                   (dir / "watched").string() + " --out " +
                                   (dir / "result.json").string(),
                               &output),
              0)
        << output;
  }
}

}  // namespace
}  // namespace calibench
