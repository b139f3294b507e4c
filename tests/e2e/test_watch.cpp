// `calibench watch` on a folder a capture is still writing: the real ACFR capture replayed pair by
// pair ends where `calibrate` on the finished folder ends; faults (a half-written file, a missing
// image, a removed file, a killed watch) each get their reason and lose no accepted pair.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "core/base/names.h"
#include "core/geometry/geometry.h"
#include "core/results/result_file.h"
#include "core/session/session.h"
#include "tests/acfr_manifest.h"
#include "tests/test_support.h"
#include "tests/watch_stream.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;
using test::PoseFromRows;
using test::ReadJsonLines;

// The ACFR folder (links) and an empty capture folder holding only its camera and target.
struct Capture {
  fs::path source;   // clouds/, images/ of the finished capture
  fs::path watched;  // what watch follows
};
Capture StartCapture(const fs::path& shared, const std::string& name) {
  const fs::path root = test::TempDir(name);
  Capture capture{test::WriteAcfrFolder(shared / "datasets/acfr-vlp16-chessboard", root / "source"),
                  root / "watched"};
  fs::create_directories(capture.watched);
  fs::copy_file(capture.source / "camera.yaml", capture.watched / "camera.yaml");
  fs::copy_file(capture.source / "target.json", capture.watched / "target.json");
  return capture;
}

std::vector<std::string> CaptureStems(const fs::path& clouds) {
  std::vector<std::string> stems;
  for (const auto& entry : fs::directory_iterator(clouds)) stems.push_back(entry.path().stem());
  std::sort(stems.begin(), stems.end(), NaturalOrder{});
  return stems;
}

// As a capture script writes a file: under a temporary name, then renamed into place.
void WriteLikeACapture(const fs::path& from, const fs::path& to) {
  fs::create_directories(to.parent_path());
  const fs::path part = to.string() + ".part";
  fs::copy_file(from, part, fs::copy_options::overwrite_existing);
  fs::rename(part, to);
}

void CopyCapturedPair(const Capture& capture, const std::string& stem) {
  for (const char* sub : {"clouds", "images"})
    for (const auto& entry : fs::directory_iterator(capture.source / sub))
      if (entry.path().stem() == stem)
        WriteLikeACapture(entry.path(), capture.watched / sub / entry.path().filename());
}

TEST(Watch, TheRealCaptureReplayedPairByPairEndsWhereCalibrateEnds) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const Capture capture = StartCapture(shared, "watch_acfr");
  const fs::path stream = capture.watched.parent_path() / "stream.jsonl";
  std::thread watch([&] {
    test::RunCommand(test::CalibenchExe() + " watch " + capture.watched.string() +
                     " --json-lines --idle-exit 4 > " + stream.string() + " 2>&1");
  });
  for (const std::string& stem : CaptureStems(capture.source / "clouds")) {
    CopyCapturedPair(capture, stem);
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  watch.join();
  const std::vector<json> lines = ReadJsonLines(stream);
  // A pair's verdict is said when it arrives and again when a later solve changes it (a board
  // found at the camera's prediction): the last one counts.
  std::map<std::string, bool> verdict;
  std::optional<json> last_solve;
  for (const json& line : lines) {
    if (line["event"] == "pair") verdict[line["name"]] = line["accepted"].get<bool>();
    if (line["event"] == "solve") last_solve = line;
  }
  int accepted = 0;
  for (const auto& [name, ok] : verdict) accepted += ok;
  EXPECT_EQ(verdict.size(), 40u);
  EXPECT_GE(accepted, 38);
  ASSERT_TRUE(last_solve);
  ASSERT_FALSE((*last_solve)["cam_from_lidar"].is_null());
  EXPECT_EQ(lines.back()["event"], "end");

  std::string out;
  const fs::path result = capture.watched.parent_path() / "result.json";
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " calibrate --dataset " +
                                 capture.watched.string() + " --out " + result.string(),
                             &out),
            0)
      << out;
  const PoseError difference = ComputePoseError(PoseFromRows((*last_solve)["cam_from_lidar"]),
                                                LoadResult(result).cam_from_source);
  std::printf("watch against calibrate: %.3f mm, %.4f deg; %d of 40 accepted\n",
              difference.translation_m * 1e3, difference.rotation_rad * kRadToDeg, accepted);
  EXPECT_LT(difference.translation_m, 0.0005);
  EXPECT_LT(difference.rotation_rad * kRadToDeg, 0.01);
  // The session beside the capture reopens what was accepted.
  const Session session = LoadSession(capture.watched / "calibench.session.json");
  int session_accepted = 0;
  for (const PairState& p : session.pairs) session_accepted += p.status == PairStatus::kAccepted;
  EXPECT_EQ(session_accepted, accepted);
}

TEST(Watch, FaultsGetTheirReasonAndAKilledWatchLosesNoAcceptedPair) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const Capture capture = StartCapture(shared, "watch_faults");
  for (const char* stem : {"pose1", "pose2", "pose3", "pose4", "pose5"})
    CopyCapturedPair(capture, stem);
  // pose6: a cloud that stops growing half-written.
  const std::string cloud = test::ReadFileBytes(capture.source / "clouds/pose6.pcd");
  std::ofstream(capture.watched / "clouds/pose6.pcd", std::ios::binary)
      << cloud.substr(0, cloud.size() / 2);
  WriteLikeACapture(capture.source / "images/pose6.png", capture.watched / "images/pose6.png");
  // pose7: its image never arrives; pose8: an image removed while watched.
  WriteLikeACapture(capture.source / "clouds/pose7.pcd", capture.watched / "clouds/pose7.pcd");
  WriteLikeACapture(capture.source / "images/pose8.png", capture.watched / "images/pose8.png");

  const fs::path first = capture.watched.parent_path() / "first.jsonl";
  const fs::path pid_file = capture.watched.parent_path() / "pid";
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " watch " + capture.watched.string() +
                             " --json-lines --partner-timeout 1 > " + first.string() +
                             " 2>&1 & echo $! > " + pid_file.string()),
            0);
  // Until pose8's removal is reported (after the pairs and pose7's timeout), then SIGKILL.
  bool removed_seen = false;
  std::this_thread::sleep_for(std::chrono::seconds(2));
  fs::remove(capture.watched / "images/pose8.png");
  for (int wait = 0; wait < 600 && !removed_seen; ++wait) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    removed_seen = test::ReadFileBytes(first).find("\"removed\"") != std::string::npos;
  }
  std::ifstream pid_in(pid_file);
  pid_t pid = 0;
  pid_in >> pid;
  ASSERT_GT(pid, 0);
  kill(pid, SIGKILL);
  ASSERT_TRUE(removed_seen) << test::ReadFileBytes(first);

  std::map<std::string, json> pair_of;
  std::map<std::string, std::string> note_of;
  for (const json& line : ReadJsonLines(first)) {
    if (line["event"] == "pair") pair_of[line["name"]] = line;
    if (line["event"] == "incomplete" || line["event"] == "removed")
      note_of[line["name"]] =
          line["event"].get<std::string>() + ": " + line["reason"].get<std::string>();
  }
  for (const char* stem : {"pose1", "pose2", "pose3", "pose4", "pose5"})
    EXPECT_TRUE(pair_of[stem]["accepted"].get<bool>()) << stem << " " << pair_of[stem];
  ASSERT_TRUE(pair_of.count("pose6"));
  EXPECT_FALSE(pair_of["pose6"]["accepted"].get<bool>());
  EXPECT_NE(pair_of["pose6"]["reason"].get<std::string>().find("pose6.pcd"), std::string::npos)
      << pair_of["pose6"];
  EXPECT_NE(note_of["pose7"].find("incomplete: "), std::string::npos) << note_of["pose7"];
  EXPECT_NE(note_of["pose7"].find("pose7.pcd has no image"), std::string::npos);
  EXPECT_NE(note_of["pose8"].find("removed: "), std::string::npos) << note_of["pose8"];

  // The session written before the kill holds every accepted pair; a restarted watch on the same
  // folder accepts them again and goes on.
  const Session killed = LoadSession(capture.watched / "calibench.session.json");
  int kept = 0;
  for (const PairState& p : killed.pairs) kept += p.status == PairStatus::kAccepted;
  EXPECT_EQ(kept, 5);
  CopyCapturedPair(capture, "pose9");
  std::string out;
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " watch " + capture.watched.string() +
                                 " --json-lines --partner-timeout 1 --idle-exit 2",
                             &out),
            0)
      << out;
  const Session restarted = LoadSession(capture.watched / "calibench.session.json");
  int accepted = 0;
  for (const PairState& p : restarted.pairs) accepted += p.status == PairStatus::kAccepted;
  EXPECT_EQ(accepted, 6) << out;
  // The six pairs detected before the kill came from the feature cache, not detected again.
  EXPECT_NE(out.find("\"event\":\"resumed\""), std::string::npos) << out;
  EXPECT_NE(out.find("6 pairs taken from"), std::string::npos) << out;
}

}  // namespace
}  // namespace calibench
