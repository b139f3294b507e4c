// One state: the user's word on a capture (a painted board, a rejected pair, a solver setting)
// lives in the one session beside it, and every front end reads and keeps it. An edit made in the
// workbench, the session reopened, `calibench watch` resumed over the capture grown since, and
// `calibench calibrate --session` all solve with that edit, and the session each leaves still
// holds it (docs/architecture.md, "One state").
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "core/geometry/geometry.h"
#include "core/io/camera_file.h"
#include "core/io/dataset.h"
#include "core/lidar_camera/result_io.h"
#include "core/results/result_file.h"
#include "core/session/session.h"
#include "tests/acfr_manifest.h"
#include "tests/test_support.h"
#include "tests/ui/ui_fixture.h"
#include "tests/watch_stream.h"
#include "ui/lidar_camera/controller.h"

namespace calibench::ui {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

// The real ACFR capture as a folder a capture script fills: its camera and target, and poses
// first..last linked into clouds/ and images/ (more can be added later, as a capture grows).
void CapturePoses(const fs::path& all, const fs::path& capture, int first, int last) {
  fs::create_directories(capture / "clouds");
  fs::create_directories(capture / "images");
  if (!fs::exists(capture / "camera.yaml")) {
    fs::copy(all / "camera.yaml", capture / "camera.yaml", fs::copy_options::copy_symlinks);
    fs::copy_file(all / "target.json", capture / "target.json");
  }
  for (int n = first; n <= last; ++n) {
    const std::string id = "pose" + std::to_string(n);
    fs::copy(all / "clouds" / (id + ".pcd"), capture / "clouds" / (id + ".pcd"),
             fs::copy_options::copy_symlinks);
    fs::copy(all / "images" / (id + ".png"), capture / "images" / (id + ".png"),
             fs::copy_options::copy_symlinks);
  }
}

int IndexOf(const Snapshot& s, const std::string& id) {
  for (size_t i = 0; i < s.pairs.size(); ++i)
    if (s.pairs[i].id == id) return static_cast<int>(i);
  return -1;
}

const PairState* StateOf(const Session& session, const std::string& id) {
  for (const PairState& pair : session.pairs)
    if (pair.id == id) return &pair;
  return nullptr;
}

// The workbench as the window opens a folder: the session beside it resumed when there is one.
Snapshot OpenLikeTheWindow(Controller& controller, const fs::path& capture) {
  controller.OpenDataset(capture, {}, ExistingSession::kResume);
  return Loaded(controller);
}

constexpr double kHuberDelta = 0.2;  // not the default (0.1): the user's setting, to be kept

TEST(OneState, AWorkbenchEditHoldsInTheReopenedSessionInWatchAndInCalibrate) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const fs::path dir = test::TempDir("one_state");
  const fs::path all =
      test::WriteAcfrFolder(shared / "datasets/acfr-vlp16-chessboard", dir / "all");
  const fs::path capture = dir / "capture";
  const fs::path session_path = capture / "calibench.session.json";
  CapturePoses(all, capture, 1, 12);

  // 1. The workbench: pose2's board painted by hand (a small brush dragged across it), pose3
  //    rejected, the Huber threshold changed, solved; autosaved.
  std::vector<int> painted;
  Mat4 workbench_solution;
  {
    Controller controller;
    const Snapshot opened = OpenLikeTheWindow(controller, capture);
    ASSERT_EQ(opened.pairs.size(), 12u);
    const int pose2 = IndexOf(opened, "pose2");
    const int pose3 = IndexOf(opened, "pose3");
    ASSERT_TRUE(pose2 >= 0 && pose3 >= 0);
    const PairView& detected = opened.pairs[pose2];
    ASSERT_TRUE(detected.lidar) << detected.lidar_failure;
    const int pixel =
        detected.lidar_image
            ->pixel_of_point[detected.lidar->inliers[detected.lidar->inliers.size() / 2]];
    const int columns = detected.lidar_image->columns;
    controller.Apply(ClearBrush{pose2});
    for (int dc = -16; dc <= 16; dc += 4)
      controller.Apply(BrushStroke{pose2, pixel / columns,
                                   (pixel % columns + dc + columns) % columns, 2.0f, false});
    controller.Apply(EndStroke{});
    controller.Apply(SetPairStatus{pose3, PairStatus::kRejected});
    JobSettings settings = opened.settings;
    settings.huber_delta = kHuberDelta;
    settings.estimate_range_offset = false;
    controller.Apply(SetSettings{settings});
    controller.Apply(RunSolver{});
    const Snapshot solved = Loaded(controller);
    ASSERT_TRUE(solved.solver.result) << solved.solver.failure;
    ASSERT_TRUE(solved.pairs[pose2].lidar) << solved.pairs[pose2].lidar_failure;
    ASSERT_EQ(solved.pairs[pose2].brush_origin, BrushOrigin::kPainted);
    painted = solved.pairs[pose2].brush_pixels;
    ASSERT_FALSE(painted.empty());
    workbench_solution = solved.solver.result->cam_from_lidar.matrix();
  }  // the window closed: its lock released

  // 2. Reopened: the same edits, the same solution.
  {
    Controller controller;
    const Snapshot reopened = OpenLikeTheWindow(controller, capture);
    ASSERT_EQ(reopened.pairs.size(), 12u);
    EXPECT_EQ(reopened.pairs[IndexOf(reopened, "pose2")].brush_pixels, painted);
    // Still painted once loaded: its plane from the brush, the session keeping it.
    EXPECT_EQ(reopened.pairs[IndexOf(reopened, "pose2")].brush_origin, BrushOrigin::kPainted);
    EXPECT_EQ(reopened.pairs[IndexOf(reopened, "pose2")].board_origin.source, BoardSource::kBrush);
    EXPECT_EQ(reopened.pairs[IndexOf(reopened, "pose3")].status, PairStatus::kRejected);
    EXPECT_EQ(reopened.settings.huber_delta, kHuberDelta);
    ASSERT_TRUE(reopened.solver.result);
    EXPECT_EQ(reopened.solver.result->cam_from_lidar.matrix(), workbench_solution);
  }

  // 3. The capture grows by four poses while no workbench is open; `watch` resumes it.
  CapturePoses(all, capture, 13, 16);
  const fs::path stream = dir / "watch.jsonl";
  std::string output;
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " watch " + capture.string() +
                             " --json-lines --idle-exit 3 > " + stream.string() + " 2>&1"),
            0)
      << test::ReadFileBytes(stream);
  std::map<std::string, json> verdict;  // the last said, by pair
  bool resumed_edits = false;
  for (const json& line : test::ReadJsonLines(stream)) {
    if (line["event"] == "pair") verdict[line["name"]] = line;
    const std::string said = "1 painted board, 1 rejected pair and the solver settings hold";
    if (line["event"] == "resumed" &&
        line["reason"].get<std::string>().find(said) != std::string::npos)
      resumed_edits = true;
  }
  EXPECT_TRUE(resumed_edits) << test::ReadFileBytes(stream);
  EXPECT_EQ(verdict.size(), 16u);
  ASSERT_TRUE(verdict.count("pose3"));
  EXPECT_FALSE(verdict["pose3"]["accepted"].get<bool>());
  EXPECT_EQ(verdict["pose3"]["reason"], kRejectedByUser);
  ASSERT_TRUE(verdict.count("pose2"));
  EXPECT_TRUE(verdict["pose2"]["accepted"].get<bool>()) << verdict["pose2"].dump();

  const Session after_watch = LoadSession(session_path);
  ASSERT_EQ(after_watch.pairs.size(), 16u);
  ASSERT_TRUE(StateOf(after_watch, "pose2")->brush);
  EXPECT_EQ(StateOf(after_watch, "pose2")->brush->pixels, painted);
  EXPECT_EQ(StateOf(after_watch, "pose3")->status, PairStatus::kRejected);
  EXPECT_EQ(after_watch.settings.huber_delta, kHuberDelta);
  ASSERT_TRUE(after_watch.result);

  // 4. `calibrate --session` on what watch left: watch's own solve (each started from the last)
  //    at the same minimum.
  const fs::path result_path = dir / "calibrated.json";
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " calibrate --session " +
                                 session_path.string() + " --out " + result_path.string(),
                             &output),
            0)
      << output;
  const LoadedResult calibrated = LoadResult(result_path);
  const PoseError watch_vs_calibrate =
      ComputePoseError(after_watch.result->cam_from_lidar, calibrated.cam_from_source);
  std::printf("watch against calibrate --session: %.4f mm, %.5f deg\n",
              watch_vs_calibrate.translation_m * 1e3, watch_vs_calibrate.rotation_rad * kRadToDeg);
  EXPECT_LT(watch_vs_calibrate.translation_m, 0.0005);
  EXPECT_LT(watch_vs_calibrate.rotation_rad * kRadToDeg, 0.01);

  // 5. Two poses more while nothing follows; the workbench reopens the grown capture's session
  //    (its pairs kept, the new ones pending) and solves as `calibrate --session` does.
  CapturePoses(all, capture, 17, 18);
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " calibrate --session " +
                                 session_path.string() + " --out " + result_path.string(),
                             &output),
            0)
      << output;
  const LoadedResult grown = LoadResult(result_path);
  Controller controller;
  const Snapshot last = OpenLikeTheWindow(controller, capture);
  ASSERT_EQ(last.pairs.size(), 18u) << last.status_line;
  EXPECT_EQ(last.pairs[IndexOf(last, "pose2")].brush_pixels, painted);
  EXPECT_EQ(last.pairs[IndexOf(last, "pose2")].brush_origin, BrushOrigin::kPainted);
  EXPECT_EQ(last.pairs[IndexOf(last, "pose3")].status, PairStatus::kRejected);
  EXPECT_EQ(last.settings.huber_delta, kHuberDelta);
  controller.Apply(RunSolver{});
  const Snapshot solved = Loaded(controller);
  ASSERT_TRUE(solved.solver.result) << solved.solver.failure;
  EXPECT_EQ(solved.solver.result->cam_from_lidar.matrix(), grown.cam_from_source.matrix());
  for (const PairView& pair : solved.pairs) {
    if (!verdict.count(pair.id)) continue;  // pose17, pose18: new since watch
    EXPECT_EQ(pair.status == PairStatus::kAccepted, verdict[pair.id]["accepted"].get<bool>())
        << pair.id << ": the workbench says " << pair.reason << ", watch said "
        << verdict[pair.id].dump();
  }
  EXPECT_EQ(solved.pairs[IndexOf(solved, "pose18")].status, PairStatus::kAccepted);
}

// A session open in a workbench is not followed into: `watch` says which process holds it and
// exits non-zero, and the session is left as the workbench has it.
TEST(OneState, WatchRefusesASessionOpenInAWorkbench) {
  const fs::path dataset = test::UiDataset();
  const fs::path dir = test::TempDir("one_state_locked");
  const fs::path capture = dir / "capture";
  fs::create_directories(capture);
  for (const char* name : {"clouds", "images"})
    fs::copy(dataset.parent_path() / name, capture / name, fs::copy_options::recursive);
  const Dataset read = LoadDataset(dataset);
  SaveTargetFile(capture / "target.json", read.target);
  SaveCameraFile(capture / "camera.yaml", read.camera, CameraFileFormat::kRosCameraInfo);
  Controller controller;
  OpenLikeTheWindow(controller, capture);
  controller.Apply(SetPairStatus{0, PairStatus::kRejected});  // an edit: the session is saved
  Loaded(controller);
  const std::string before = test::ReadFileBytes(capture / "calibench.session.json");
  std::string output;
  EXPECT_NE(
      test::RunCommand(test::CalibenchExe() + " watch " + capture.string() + " --idle-exit 1 2>&1",
                       &output),
      0);
  EXPECT_NE(output.find("open in a Calibench workbench"), std::string::npos) << output;
  EXPECT_EQ(test::ReadFileBytes(capture / "calibench.session.json"), before);
}

}  // namespace
}  // namespace calibench::ui
