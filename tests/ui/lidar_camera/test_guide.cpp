// The workbench as the on-site cockpit: the ghost board (where `advise` says to hold the board
// next) drawn where advise's pose projects, and a folder followed while a capture fills it —
// pairs join as they land, solved by themselves, ending where `calibrate` ends on the finished
// folder.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <thread>

#include "core/base/names.h"
#include "core/geometry/geometry.h"
#include "core/io/dataset.h"
#include "core/io/json_io.h"
#include "core/results/result_file.h"
#include "core/session/session.h"
#include "tests/acfr_manifest.h"
#include "tests/bag_writers.h"
#include "tests/sim_recording.h"
#include "tests/test_support.h"
#include "tests/ui/ui_fixture.h"
#include "tests/watch_stream.h"
#include "ui/lidar_camera/controller.h"
#include "ui/lidar_camera/ghost.h"

namespace calibench::ui {
namespace {
namespace fs = std::filesystem;

// The sheet's four corners in the board frame (the shown and the BoardSpec frames share them).
std::vector<Vec3> SheetCorners(const BoardSpec& board) {
  const double hw = board.SheetWidth() / 2, hh = board.SheetHeight() / 2;
  return {{-hw, -hh, 0}, {hw, -hh, 0}, {hw, hh, 0}, {-hw, hh, 0}};
}

TEST(Guide, TheGhostBoardInTheCameraViewLiesWhereAdvisesPoseProjects) {
  Controller controller;
  controller.OpenDataset(test::UiDataset(), {}, ExistingSession::kInMemory);
  controller.WaitIdle();
  controller.Apply(RunSolver{});
  const Snapshot s = Loaded(controller);
  ASSERT_TRUE(s.solver.result) << s.solver.failure;
  ASSERT_TRUE(s.next_pose) << s.next_pose_failure;

  // `calibench advise --json` on the same dataset, a process of its own.
  std::string output;
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " advise --dataset " +
                                 test::UiDataset().string() + " --json",
                             &output),
            0)
      << output;
  // Its one JSON object (progress lines on stderr come first here: RunCommand merges them).
  const size_t object = output.find("\n{");
  ASSERT_NE(object, std::string::npos) << output;
  const nlohmann::json advice = nlohmann::json::parse(output.substr(object + 1));
  ASSERT_FALSE(advice["next"].is_null()) << output;
  const Pose lidar_from_board = test::PoseFromRows(advice["next"]["lidar_from_board"]);
  const Pose cam_from_lidar = test::PoseFromRows(advice["cam_from_lidar"]);
  EXPECT_EQ(advice["next"]["words"], s.next_pose->words);

  // The outline the camera view draws starts each edge at a corner (SheetOutlinePixels).
  const int steps = 16;
  const std::vector<Vec2> outline =
      SheetOutlinePixels(s.dataset->camera, s.dataset->target, s.next_pose->cam_from_board, steps);
  ASSERT_EQ(outline.size(), 4u * steps);
  for (const Vec3& corner : SheetCorners(s.dataset->target)) {
    const auto expected = s.dataset->camera.Project(cam_from_lidar * lidar_from_board * corner);
    ASSERT_TRUE(expected);
    double nearest = 1e9;
    for (int k = 0; k < 4; ++k)
      nearest = std::min(nearest, (outline[k * steps] - *expected).norm());
    EXPECT_LT(nearest, 0.5) << "corner at " << expected->transpose();
  }
}

// As a capture script writes a file: under a temporary name, then renamed into place.
void WriteLikeACapture(const fs::path& from, const fs::path& to) {
  fs::create_directories(to.parent_path());
  const fs::path part = to.string() + ".part";
  fs::copy_file(from, part, fs::copy_options::overwrite_existing);
  fs::rename(part, to);
}

// The capture's stems in natural order; a pair copied in as a capture script writes it.
std::vector<std::string> CaptureStems(const fs::path& source) {
  std::vector<std::string> stems;
  for (const auto& entry : fs::directory_iterator(source / "clouds"))
    stems.push_back(entry.path().stem());
  std::sort(stems.begin(), stems.end(), NaturalOrder{});
  return stems;
}
void CopyCapturedPair(const fs::path& source, const fs::path& watched, const std::string& stem) {
  for (const char* sub : {"clouds", "images"})
    for (const auto& entry : fs::directory_iterator(source / sub))
      if (entry.path().stem() == stem)
        WriteLikeACapture(entry.path(), watched / sub / entry.path().filename());
}

// The real ACFR capture (its folder form, linked) and an empty folder to watch beside it.
struct Capture {
  fs::path root, source, watched;
};
Capture StartCapture(const fs::path& shared, const std::string& name) {
  Capture capture;
  capture.root = test::TempDir(name);
  capture.source =
      test::WriteAcfrFolder(shared / "datasets/acfr-vlp16-chessboard", capture.root / "source");
  capture.watched = capture.root / "watched";
  fs::create_directories(capture.watched);
  return capture;
}
void CopySetup(const Capture& capture) {
  fs::copy_file(capture.source / "camera.yaml", capture.watched / "camera.yaml");
  fs::copy_file(capture.source / "target.json", capture.watched / "target.json");
}

// The controller once `pairs` pairs are in, loaded, solved with and nothing changes any more.
Snapshot WaitUntilSettled(Controller& controller, size_t pairs) {
  Snapshot s;
  std::uint64_t seen = 0;
  for (int wait = 0; wait < 600; ++wait) {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    s = controller.GetSnapshot();
    if (s.pairs.size() == pairs && s.loading_done == s.loading_total && !s.busy &&
        s.solver.result && s.generation == seen)
      break;
    seen = s.generation;
  }
  return s;
}

// A capture that grew while the workbench was closed: watching it again resumes its session (the
// user's rejection stays, no backup is made) and the pairs written since join as new.
TEST(Guide, WatchingAGrownCaptureAgainResumesItsSessionAndAddsTheNewPairs) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const Capture capture = StartCapture(shared, "guide_resume");
  const fs::path &source = capture.source, &watched = capture.watched;
  CopySetup(capture);
  const std::vector<std::string> stems = CaptureStems(source);
  for (size_t i = 0; i < 8; ++i) CopyCapturedPair(source, watched, stems[i]);
  {
    Controller first;
    first.SetAutoSolve(true);
    first.WatchFolder(watched);
    ASSERT_EQ(WaitUntilSettled(first, 8).pairs.size(), 8u);
    first.Apply(SetPairStatus{2, PairStatus::kRejected});
    first.StopWatching();
    first.WaitIdle();
  }
  for (size_t i = 8; i < 12; ++i) CopyCapturedPair(source, watched, stems[i]);
  Controller again;
  again.SetAutoSolve(true);
  again.WatchFolder(watched);
  const Snapshot s = WaitUntilSettled(again, 12);
  again.StopWatching();
  ASSERT_EQ(s.pairs.size(), 12u) << s.status_line;
  EXPECT_EQ(s.pairs[2].status, PairStatus::kRejected);
  EXPECT_EQ(s.pairs[2].reason, kRejectedByUser);
  for (size_t i = 0; i < 12; ++i) EXPECT_EQ(s.pairs[i].id, stems[i]);
  for (const auto& entry : fs::directory_iterator(watched))
    EXPECT_NE(entry.path().extension(), ".bak") << entry.path() << ": the session was not resumed";
}

TEST(Guide, AFolderFollowedWhileTheRealCaptureFillsItEndsWhereCalibrateEnds) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const Capture capture = StartCapture(shared, "guide_watch");
  const fs::path &root = capture.root, &source = capture.source, &watched = capture.watched;
  Controller controller;
  controller.SetAutoSolve(true);
  controller.WatchFolder(watched);  // empty: it waits for the camera and the target
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_NE(controller.GetSnapshot().status_line.find("waiting for camera.yaml"), std::string::npos)
      << controller.GetSnapshot().status_line;
  CopySetup(capture);
  const std::vector<std::string> stems = CaptureStems(source);
  for (size_t i = 0; i < stems.size(); ++i) {
    CopyCapturedPair(source, watched, stems[i]);
    // Slower than a pair's processing (a user takes seconds per pose), so that every pair is
    // solved with as it lands: 400 ms, and longer while the workbench is still busy with it (a
    // loaded machine, a sanitizer build), up to 10 s.
    std::this_thread::sleep_for(std::chrono::milliseconds(400));
    for (int wait = 0; wait < 48; ++wait) {
      const Snapshot now = controller.GetSnapshot();
      if (now.pairs.size() > i && now.loading_done == now.loading_total && !now.busy) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
  }
  WaitUntilSettled(controller, stems.size());
  controller.StopWatching();
  controller.WaitIdle();
  const Snapshot s = controller.GetSnapshot();
  ASSERT_EQ(s.pairs.size(), stems.size()) << s.status_line;
  ASSERT_TRUE(s.solver.result) << s.solver.failure << "; " << s.status_line;
  int accepted = 0;
  for (const PairView& pair : s.pairs) accepted += pair.status == PairStatus::kAccepted;
  EXPECT_GE(accepted, 37) << s.status_line;
  // The meter followed the capture: one point per solve that added pairs.
  ASSERT_TRUE(s.meter);
  std::printf("meter: %zu points, %d to %d pairs\n", s.meter_history.size(),
              s.meter_history.front().pairs, s.meter_history.back().pairs);
  // (Pairs that land while the worker is busy are solved with together: on a loaded machine
  // fewer points than pairs.)
  ASSERT_GE(s.meter_history.size(), 8u);
  EXPECT_GT(s.meter_history.back().pairs, s.meter_history.front().pairs);
  EXPECT_TRUE(s.next_pose || !s.next_pose_failure.empty());

  std::string out;
  const fs::path result = root / "result.json";
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " calibrate --dataset " + watched.string() +
                                 " --out " + result.string(),
                             &out),
            0)
      << out;
  const PoseError difference =
      ComputePoseError(s.solver.result->cam_from_lidar, LoadResult(result).cam_from_source);
  std::printf("workbench watch against calibrate: %.3f mm, %.4f deg; %d of %zu accepted\n",
              difference.translation_m * 1e3, difference.rotation_rad * kRadToDeg, accepted,
              stems.size());
  EXPECT_LT(difference.translation_m, 0.002);
  EXPECT_LT(difference.rotation_rad * kRadToDeg, 0.02);
  // The session beside the capture holds every pair.
  EXPECT_EQ(LoadSession(watched / "calibench.session.json").pairs.size(), stems.size());
}

// A recording (an MCAP as `ros2 bag record` writes it) followed in the workbench: its pairs join
// as `watch` finds them (one per hold), written to the dataset folder, solved by themselves near
// the truth and where `calibrate` on that folder ends.
TEST(Guide, ARecordingFollowedInTheWorkbenchGivesItsHoldsAndTheTruth) {
  const fs::path dir = test::TempDir("guide_recording");
  const test::SimRecordingOptions options = test::SmallSimRecording(6);
  auto writer = test::OpenMcapWriter(dir / "capture.mcap", "ros2", "lz4", /*summary=*/true);
  const test::SimRecordingTruth truth =
      test::WriteSimRecording(writer.get(), MessageEncoding::kCdr, options);
  writer->Close();
  auto controller = std::make_unique<Controller>();
  controller->SetAutoSolve(true);
  controller->WatchRecording(dir / "capture.mcap", dir / "capture.dataset", truth.board, {});
  WaitUntilSettled(*controller, 6);
  controller->StopWatching();
  controller->WaitIdle();
  const Snapshot s = controller->GetSnapshot();
  ASSERT_EQ(s.pairs.size(), 6u) << s.status_line;
  ASSERT_TRUE(s.solver.result) << s.solver.failure << "; " << s.status_line;
  const PoseError to_truth =
      ComputePoseError(s.solver.result->cam_from_lidar, truth.cam_from_lidar);
  std::string out;
  const fs::path result = dir / "result.json";
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " calibrate --dataset " +
                                 (dir / "capture.dataset").string() + " --out " + result.string(),
                             &out),
            0)
      << out;
  const PoseError to_calibrate =
      ComputePoseError(s.solver.result->cam_from_lidar, LoadResult(result).cam_from_source);
  std::printf(
      "recording in the workbench: %.2f mm, %.3f deg from the truth; %.3f mm, %.4f deg "
      "from calibrate on its folder\n",
      to_truth.translation_m * 1e3, to_truth.rotation_rad * kRadToDeg,
      to_calibrate.translation_m * 1e3, to_calibrate.rotation_rad * kRadToDeg);
  EXPECT_LT(to_truth.translation_m, 0.02);
  EXPECT_LT(to_truth.rotation_rad * kRadToDeg, 0.5);
  EXPECT_LT(to_calibrate.translation_m, 0.001);
  EXPECT_LT(to_calibrate.rotation_rad * kRadToDeg, 0.05);

  // Watched again (the workbench was closed): the recording is read again and the session the
  // first watch left resumes over the same pairs, the user's rejection kept, no backup made.
  controller->Apply(SetPairStatus{1, PairStatus::kRejected});
  controller->WaitIdle();
  controller.reset();  // closes the session (and its lock)
  Controller again;
  again.SetAutoSolve(true);
  again.WatchRecording(dir / "capture.mcap", dir / "capture.dataset", truth.board, {});
  const Snapshot resumed = WaitUntilSettled(again, 6);
  again.StopWatching();
  ASSERT_EQ(resumed.pairs.size(), 6u) << resumed.status_line;
  for (size_t i = 0; i < 6; ++i) EXPECT_EQ(resumed.pairs[i].id, s.pairs[i].id);
  EXPECT_EQ(resumed.pairs[1].status, PairStatus::kRejected);
  EXPECT_EQ(resumed.pairs[1].reason, kRejectedByUser);
  for (const auto& entry : fs::directory_iterator(dir / "capture.dataset"))
    EXPECT_NE(entry.path().extension(), ".bak") << entry.path() << ": the session was not resumed";
}

// A recording still being written whose board no preset explains: the workbench says why (the
// "Which board?" window reads Snapshot::board_problem) and keeps following; the board picked
// there (a target file) brings the held pairs, and the rest as the recording goes on.
TEST(Guide, ABoardNoPresetExplainsIsPickedInTheWorkbench) {
  const fs::path dir = test::TempDir("guide_pick_board");
  test::SimRecordingOptions options = test::SmallSimRecording(8);
  options.board.type = BoardType::kCheckerboard;
  options.board.cols = 8;  // 8x6 inner corners of 70 mm: a3's and a4's grids are found inside it
  options.board.rows = 6;
  options.board.square_size = 0.07;
  options.board.board_width = 0.70;
  options.board.board_height = 0.56;
  Controller controller;
  controller.SetAutoSolve(true);
  controller.WatchRecording(dir / "large.mcap", dir / "large.dataset", std::nullopt, {});
  // The recorder pauses after the fifth pose until the workbench says why no pair comes; the user
  // picks the board there, and three more poses are recorded.
  Snapshot s;
  auto pick = [&] {
    for (int wait = 0; wait < 600 && s.board_problem.empty(); ++wait) {
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      s = controller.GetSnapshot();
    }
    EXPECT_NE(s.board_problem.find("no preset board explains the images"), std::string::npos)
        << s.status_line;
    EXPECT_TRUE(s.pairs.empty());
    // A wrong pick is refused in words, nothing taken.
    controller.Apply(PickBoard{"a5"});
    EXPECT_TRUE(controller.GetSnapshot().status_is_error);
    const fs::path target = dir / "my_board.json";
    std::ofstream(target) << json_io::TargetToJson(options.board).dump(2);
    controller.Apply(PickBoard{target.string()});
  };
  test::PausingWriter writer(test::OpenMcapWriter(dir / "large.mcap", "ros2", "lz4", true), pick,
                             test::PlanSimRecording(options).hold_end_ns[4]);
  test::WriteSimRecording(&writer, MessageEncoding::kCdr, options);
  writer.Close();
  // Until the recording's end is read and every pair is in and solved.
  std::uint64_t seen = 0;
  int still = 0;  // polls in a row with nothing new
  for (int wait = 0; wait < 600 && still < 5; ++wait) {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    s = controller.GetSnapshot();
    const bool settled = s.pairs.size() >= 6 && s.loading_done == s.loading_total && !s.busy &&
                         s.solver.result && s.generation == seen;
    still = settled ? still + 1 : 0;
    seen = s.generation;
  }
  controller.StopWatching();
  EXPECT_GE(s.pairs.size(), 6u) << s.status_line;
  EXPECT_TRUE(s.board_problem.empty()) << s.board_problem;
  ASSERT_TRUE(s.solver.result) << s.solver.failure;
  EXPECT_EQ(LoadDataset(dir / "large.dataset").target.square_size, 0.07);
}

}  // namespace
}  // namespace calibench::ui
