// The workbench opening files: the browser's folder listing, the recent sessions, what a path
// is, the window shell opening datasets, sessions and recordings (without a window), and the
// workbench's Export in every format.
#include <gtest/gtest.h>

#include <fstream>

#include "core/io/cloud_io.h"
#include "core/io/dataset.h"
#include "core/io/image_io.h"
#include "core/results/export.h"
#include "tests/bag_writers.h"
#include "tests/test_support.h"
#include "tests/ui/ui_fixture.h"
#include "ui/lidar_camera/window_shell.h"
#include "ui/state/folder_listing.h"
#include "ui/state/recent_files.h"

namespace calibench::ui {
namespace {
namespace fs = std::filesystem;

void TouchFile(const fs::path& path, const std::string& text = "x") {
  fs::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

TEST(FolderListing, FoldersFirstInNaturalOrderWithTheirKinds) {
  const fs::path dir = test::TempDir("folder_listing");
  fs::create_directories(dir / "pose10");
  fs::create_directories(dir / "pose2");
  fs::create_directories(dir / "rig/clouds");
  fs::create_directories(dir / "rig/images");
  TouchFile(dir / "ros2_rec/metadata.yaml");
  TouchFile(dir / "run10.bag");
  TouchFile(dir / "run2.mcap");
  TouchFile(dir / "run3.db3");
  TouchFile(dir / "work.session.json");
  TouchFile(dir / "notes.txt");
  TouchFile(dir / ".hidden.bag");
  fs::create_directories(dir / ".git");
  const std::vector<FolderEntry> entries = ListFolder(dir);
  std::vector<std::string> listed;
  for (const FolderEntry& entry : entries)
    listed.push_back(entry.name + ":" + EntryKindLabel(entry.kind));
  const std::vector<std::string> expected = {
      "pose2:folder",        "pose10:folder",      "rig:dataset",         "ros2_rec:rosbag2",
      "run2.mcap:recording", "run3.db3:recording", "run10.bag:recording", "work.session.json:json"};
  EXPECT_EQ(listed, expected);
  EXPECT_THROW(ListFolder(dir / "missing"), IoError);
}

TEST(RecentFiles, NewestFirstCappedPersistedAndTolerantOfABrokenList) {
  const fs::path dir = test::TempDir("recent_files");
  const fs::path list = dir / "config/recent.json";
  {
    RecentFiles recent(list, 3);
    for (int i = 0; i < 5; ++i) {
      TouchFile(dir / ("s" + std::to_string(i) + ".session.json"));
      EXPECT_EQ(recent.Add(dir / ("s" + std::to_string(i) + ".session.json")), "");
    }
    recent.Add(dir / "s2.session.json");  // again: moves to the front
  }
  RecentFiles reloaded(list, 3);
  EXPECT_EQ(reloaded.load_error(), "");
  const std::vector<fs::path> expected = {dir / "s2.session.json", dir / "s4.session.json",
                                          dir / "s3.session.json"};
  EXPECT_EQ(reloaded.Paths(), expected);
  fs::remove(dir / "s4.session.json");  // a session deleted since is not offered
  EXPECT_EQ(reloaded.Paths().size(), 2u);
  TouchFile(list, "{ not json");
  RecentFiles broken(list, 3);
  EXPECT_TRUE(broken.Paths().empty());
  EXPECT_NE(broken.load_error().find(list.string()), std::string::npos) << broken.load_error();
}

// A recording made from the workbench tests' dataset: every pair's cloud, image (three times:
// the board still) and CameraInfo.
fs::path RecordingOfUiDataset(const fs::path& dir) {
  const Dataset dataset = LoadDataset(test::UiDataset());
  std::vector<test::RecordedMessage> messages;
  for (std::size_t i = 0; i < dataset.pairs.size(); ++i) {
    const std::int64_t t = (20 + 2 * static_cast<std::int64_t>(i)) * 1'000'000'000;
    const ImageU8 image = LoadImage(dataset.pairs[i].image);
    for (const std::int64_t offset : {-30'000'000, 0, 30'000'000}) {
      messages.push_back(
          {"/cam/image_raw", "sensor_msgs/Image", t + offset,
           test::SerializeImage(image, "bgr8", t + offset, "cam", MessageEncoding::kCdr)});
      messages.push_back(
          {"/cam/camera_info", "sensor_msgs/CameraInfo", t + offset,
           test::SerializeCameraInfo(dataset.camera, t + offset, "cam", MessageEncoding::kCdr)});
    }
    messages.push_back({"/lidar/points", "sensor_msgs/PointCloud2", t,
                        test::SerializePointCloud2(LoadCloud(dataset.pairs[i].cloud), t, "lidar",
                                                   MessageEncoding::kCdr)});
  }
  std::sort(messages.begin(), messages.end(),
            [](const auto& a, const auto& b) { return a.log_time_ns < b.log_time_ns; });
  test::WriteMcap(dir / "rig.mcap", messages, "ros2", "zstd");
  return dir / "rig.mcap";
}

TEST(WindowShell, OpensRecordingsDatasetsAndSessionsAndSaysWhyNot) {
  const fs::path dir = test::TempDir("window_shell");
  ShellOptions options;
  options.board = LoadDataset(test::UiDataset()).target;
  options.recent_file = dir / "recent.json";
  WindowShell shell(options);
  const fs::path recording = RecordingOfUiDataset(dir);
  EXPECT_EQ(KindOfPath(recording), OpenKind::kRecording);
  EXPECT_EQ(KindOfPath(test::UiDataset()), OpenKind::kDataset);
  shell.OpenFromUser(recording);
  shell.FinishImport();
  ASSERT_EQ(shell.error(), "");
  ASSERT_TRUE(shell.last_import());
  EXPECT_EQ(shell.last_import()->pair_ids.size(), 4u);
  Snapshot s = Loaded(shell.controller());
  EXPECT_EQ(s.pairs.size(), 4u);
  EXPECT_EQ(s.session_path, dir / "rig.mcap.dataset/calibench.session.json");
  EXPECT_EQ(KindOfPath(s.session_path), OpenKind::kSession);
  // Opening what is open already is refused by name (its lock is this window's own).
  shell.OpenFromUser(dir / "rig.mcap.dataset");
  EXPECT_NE(shell.error().find("is open in this window already"), std::string::npos);
  // A folder that is no dataset: the error names it, and the open work stays.
  fs::create_directories(dir / "empty");
  shell.OpenFromUser(dir / "empty");
  EXPECT_NE(shell.error().find((dir / "empty").string()), std::string::npos) << shell.error();
  EXPECT_EQ(Loaded(shell.controller()).pairs.size(), 4u);
  // Another dataset (a copy of the shared one, whose folder the goldens' renders use); both
  // sessions are in the recent list, newest first.
  const fs::path session = s.session_path;
  const fs::path shared =
      fs::is_directory(test::UiDataset()) ? test::UiDataset() : test::UiDataset().parent_path();
  fs::copy(shared, dir / "copy", fs::copy_options::recursive);
  shell.OpenFromUser(dir / "copy");
  s = Loaded(shell.controller());
  EXPECT_EQ(s.pairs.size(), 4u);
  EXPECT_NE(s.session_path, session);
  const std::vector<fs::path> recent = RecentFiles(options.recent_file).Paths();
  ASSERT_EQ(recent.size(), 2u);
  EXPECT_EQ(recent[0], dir / "copy/calibench.session.json");
  EXPECT_EQ(recent[1], session);
}

// The workbench's Export writes every format next to the session; each reads back to the solve.
TEST(WindowShell, ExportWritesEveryFormatThatReadsBackToTheSolution) {
  const fs::path dir = test::TempDir("controller_export_formats");
  Controller controller;
  controller.OpenDataset(test::UiDataset(), dir / "work.session.json");
  Loaded(controller);
  controller.Apply(RunSolver{});
  const Snapshot solved = Loaded(controller);
  ASSERT_TRUE(solved.solver.result);
  const Pose cam_from_lidar = solved.solver.result->cam_from_lidar;
  for (const ExportFormat format : AllExportFormats()) {
    for (const CameraFrame camera_frame : {CameraFrame::kOptical, CameraFrame::kLink}) {
      ExportFrames frames;
      frames.lidar = "os0_sensor";
      frames.camera = "front_camera";
      frames.camera_frame = camera_frame;
      const std::string name = CameraFrameName(camera_frame) + "_" + DefaultExportFileName(format);
      controller.Apply(ExportResult{name, format, frames});
      const Snapshot s = controller.GetSnapshot();
      ASSERT_FALSE(s.status_is_error) << s.status_line;
      const ImportedTransform read = ReadExportedTransform(dir / name);
      EXPECT_TRUE(test::MatrixNear(CamFromLidarOf(read.parent_from_child, frames).matrix(),
                                   cam_from_lidar.matrix(), 1e-9))
          << name;
    }
  }
  ExportFrames same;
  same.lidar = same.camera = "base";
  controller.Apply(ExportResult{"bad.urdf", ExportFormat::kUrdf, same});
  EXPECT_TRUE(controller.GetSnapshot().status_is_error);
  EXPECT_FALSE(fs::exists(dir / "bad.urdf"));
}

}  // namespace
}  // namespace calibench::ui
