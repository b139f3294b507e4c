// A real window: `calibench gui` under Xvfb for a few frames, with a screenshot of what it showed.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "core/base/image.h"
#include "core/io/cloud_io.h"
#include "core/io/dataset.h"
#include "core/io/image_io.h"
#include "tests/bag_writers.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

// The mean absolute difference between neighbouring pixels: ~0 for an empty panel, large for a
// picture (a LiDAR image, a camera frame, a point cloud).
double Texture(const ImageU8& image, int x0, int y0, int x1, int y1) {
  double sum = 0;
  int count = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x + 1 < x1; ++x) {
      const std::uint8_t* p = image.Row(y) + 3 * x;
      sum += std::abs(p[0] - p[3]) + std::abs(p[1] - p[4]) + std::abs(p[2] - p[5]);
      ++count;
    }
  return count ? sum / count : 0;
}

// xvfb-run (skipped without it, unless CI requires everything) and a 3-pair demo in `dir_`.
class GuiWindow : public ::testing::Test {
 protected:
  // The command prefix: a virtual display, and the recent-sessions list kept in the test's folder.
  std::string Xvfb() const {
    return "CALIBENCH_CONFIG_DIR=" + (dir_ / "config").string() +
           " xvfb-run -a -s '-screen 0 1600x900x24' ";
  }
  void SetUp() override {
    std::string output;
    if (test::RunCommand("command -v xvfb-run", &output) != 0) {
      if (std::getenv("CALIBENCH_REQUIRE_SHARED")) FAIL() << "xvfb-run is not installed";
      GTEST_SKIP() << "xvfb-run is not installed (apt-get install xvfb xauth)";
    }
    dir_ = test::TempDir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " simulate --preset demo --pairs 3 --out " +
                                   (dir_ / "data").string(),
                               &output),
              0)
        << output;
  }
  std::filesystem::path dir_;
};

// The one resolver (core/io/dataset_source.h) in the workbench: a folder whose manifest has
// another name opens and shows its pairs; a folder of neither kind gets the same message as every
// command.
TEST_F(GuiWindow, OpensAFolderByItsManifestWhateverItsNameAndRefusesAFolderOfNeitherKind) {
  std::filesystem::rename(dir_ / "data/dataset.json", dir_ / "data/rig_a.json");
  std::string output;
  const auto shot = dir_ / "named.png";
  ASSERT_EQ(test::RunCommand(
                Xvfb() + test::CalibenchExe() + " gui --dataset " + (dir_ / "data").string() +
                    " --size 1600x900 --quit-after-frames 90 --screenshot " + shot.string(),
                &output),
            0)
      << output;
  EXPECT_GT(Texture(LoadImage(shot), 20, 120, 513, 440), 3.0) << "the LiDAR view looks empty";
  std::filesystem::create_directories(dir_ / "neither");
  std::ofstream(dir_ / "neither/notes.txt") << "not a dataset\n";
  EXPECT_NE(test::RunCommand(Xvfb() + test::CalibenchExe() + " gui --dataset " +
                                 (dir_ / "neither").string() + " --quit-after-frames 10",
                             &output),
            0);
  EXPECT_NE(
      output.find((dir_ / "neither").string() + ": not a dataset folder (looked for a manifest"),
      std::string::npos)
      << output;
}

TEST_F(GuiWindow, OpensUnderXvfbAndShowsTheThreeViews) {
  const auto& dir = dir_;
  std::string output;
  const auto shot = dir / "window.png";
  const int code = test::RunCommand(
      Xvfb() + test::CalibenchExe() + " gui --dataset " + (dir / "data/dataset.json").string() +
          " --size 1600x900 --quit-after-frames 90 " + "--screenshot " + shot.string(),
      &output);
  ASSERT_EQ(code, 0) << output;
  const ImageU8 image = LoadImage(shot);
  ASSERT_EQ(image.width, 1600);
  ASSERT_EQ(image.height, 900);
  // The three views side by side in the top half each show a picture once the pairs loaded.
  for (int view = 0; view < 3; ++view) {
    const int x0 = view * 533 + 20, x1 = (view + 1) * 533 - 20;
    EXPECT_GT(Texture(image, x0, 120, x1, 440), 3.0)
        << "view " << view << " looks empty; see " << shot;
  }
  // The title bars of the views (the theme's blue) are where the layout puts them, below the
  // File menu's bar.
  for (int x : {10, 543, 1076}) {
    const std::uint8_t* p = image.Row(30) + 3 * x;
    EXPECT_GT(p[0], p[2]) << "no title bar at x = " << x << "; see " << shot;  // blue > red (BGR)
  }
}

// Left alone, the window draws nothing: after the pairs load it sleeps in the window system
// until input or work arrives (a loop that redraws continuously draws hundreds of frames a
// second under Xvfb, all of them "quiet").
TEST_F(GuiWindow, IdleWindowDrawsNoFrames) {
  const auto& dir = dir_;
  std::string output;
  const int code = test::RunCommand(Xvfb() + test::CalibenchExe() + " gui --dataset " +
                                        (dir / "data/dataset.json").string() +
                                        " --size 1600x900 --quit-after-seconds 6",
                                    &output);
  ASSERT_EQ(code, 0) << output;
  int frames = -1, quiet = -1;
  const auto at = output.find("frames drawn: ");
  ASSERT_NE(at, std::string::npos) << output;
  ASSERT_EQ(std::sscanf(output.c_str() + at, "frames drawn: %d (%d", &frames, &quiet), 2) << output;
  EXPECT_GT(frames, 0) << output;  // it did draw while loading
  EXPECT_EQ(quiet, 0) << output;
}

// A folder dropped onto the window opens there (GLFW's drop callback, driven as the window
// system drives it), and joins the recent sessions.
TEST_F(GuiWindow, ADroppedDatasetOpens) {
  std::string output;
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " simulate --preset demo --pairs 2 --seed 9 " +
                                 "--out " + (dir_ / "dropped").string(),
                             &output),
            0)
      << output;
  const int code = test::RunCommand(Xvfb() + test::CalibenchExe() + " gui --dataset " +
                                        (dir_ / "data").string() + " --test-drop " +
                                        (dir_ / "dropped").string() + " --quit-after-frames 40",
                                    &output);
  ASSERT_EQ(code, 0) << output;
  EXPECT_TRUE(std::filesystem::exists(dir_ / "dropped/calibench.session.json")) << output;
  const std::string recent = test::ReadFileBytes(dir_ / "config/recent.json");
  const auto dropped_at = recent.find((dir_ / "dropped/calibench.session.json").string());
  const auto first_at = recent.find((dir_ / "data/calibench.session.json").string());
  ASSERT_NE(dropped_at, std::string::npos) << recent;
  ASSERT_NE(first_at, std::string::npos) << recent;
  EXPECT_LT(dropped_at, first_at) << recent;  // newest first
}

// The LRF window has the File menu's bar over its views; a LiDAR-camera dataset dropped onto it
// is refused with the reason and leaves the open dataset alone; an LRF manifest dropped after it
// opens.
TEST_F(GuiWindow, TheLrfWindowOpensADroppedManifestAndRefusesOtherDatasets) {
  std::string output;
  for (const char* name : {"lrf_a", "lrf_b"}) {
    ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " simulate --kind lrf --observations 4 " +
                                   "--seed " + (name[4] == 'a' ? "3" : "4") + " --out " +
                                   (dir_ / name).string(),
                               &output),
              0)
        << output;
  }
  const auto shot = dir_ / "lrf_window.png";
  const int code = test::RunCommand(
      Xvfb() + test::CalibenchExe() + " gui --dataset " + (dir_ / "lrf_a/manifest.json").string() +
          " --test-drop " + (dir_ / "data/dataset.json").string() + " --test-drop " +
          (dir_ / "lrf_b/manifest.json").string() +
          " --size 1600x900 --quit-after-frames 60 --screenshot " + shot.string(),
      &output);
  ASSERT_EQ(code, 0) << output;
  // The refused drop is named with the reason, the manifest dropped last is what is open.
  EXPECT_NE(output.find("calibench gui: "), std::string::npos) << output;
  EXPECT_NE(output.find("data/dataset.json"), std::string::npos) << output;
  EXPECT_NE(output.find("open at the end: " + (dir_ / "lrf_b/manifest.json").string()),
            std::string::npos)
      << output;
  // Refused alone, the LiDAR-camera dataset leaves set A open.
  ASSERT_EQ(test::RunCommand(Xvfb() + test::CalibenchExe() + " gui --dataset " +
                                 (dir_ / "lrf_a/manifest.json").string() + " --test-drop " +
                                 (dir_ / "data").string() + " --quit-after-frames 30",
                             &output),
            0)
      << output;
  EXPECT_NE(output.find("calibench gui: "), std::string::npos) << output;
  EXPECT_NE(output.find("open at the end: " + (dir_ / "lrf_a/manifest.json").string()),
            std::string::npos)
      << output;
  const ImageU8 image = LoadImage(shot);
  // The views' title bars (the theme's blue) sit below the menu bar, as in the LiDAR-camera
  // window; without a menu bar they would start at the top row.
  for (int x : {10, 543, 1076}) {
    const std::uint8_t* bar = image.Row(30) + 3 * x;
    EXPECT_GT(bar[0], bar[2]) << "no title bar at x = " << x << "; see " << shot;
    const std::uint8_t* menu = image.Row(5) + 3 * x;
    EXPECT_LE(std::abs(menu[0] - menu[2]), 12)
        << "no grey menu bar at x = " << x << "; see " << shot;
  }
}

// `gui --bag`: the recording is imported behind a progress bar, then opened.
TEST_F(GuiWindow, ABagOpensAfterItsImport) {
  const Dataset dataset = LoadDataset(dir_ / "data");
  std::vector<test::RecordedMessage> messages;
  for (std::size_t i = 0; i < dataset.pairs.size(); ++i) {
    const std::int64_t t = (30 + static_cast<std::int64_t>(i)) * 1'000'000'000;
    messages.push_back({"/cam/image_raw", "sensor_msgs/Image", t,
                        test::SerializeImage(LoadImage(dataset.pairs[i].image), "bgr8", t, "cam",
                                             MessageEncoding::kRos1)});
    messages.push_back(
        {"/cam/camera_info", "sensor_msgs/CameraInfo", t,
         test::SerializeCameraInfo(dataset.camera, t, "cam", MessageEncoding::kRos1)});
    messages.push_back({"/points", "sensor_msgs/PointCloud2", t,
                        test::SerializePointCloud2(LoadCloud(dataset.pairs[i].cloud), t, "lidar",
                                                   MessageEncoding::kRos1)});
  }
  test::WriteRos1Bag(dir_ / "rig.bag", messages, "bz2");
  std::string output;
  // --board takes the dataset's own target (a manifest's "target" object).
  const int code = test::RunCommand(
      Xvfb() + test::CalibenchExe() + " gui --bag " + (dir_ / "rig.bag").string() + " --board " +
          (dir_ / "data/dataset.json").string() + " --quit-after-frames 60",
      &output);
  ASSERT_EQ(code, 0) << output;
  EXPECT_EQ(LoadDataset(dir_ / "rig.bag.dataset").pairs.size(), dataset.pairs.size()) << output;
  EXPECT_TRUE(std::filesystem::exists(dir_ / "rig.bag.dataset/calibench.session.json")) << output;
  // Not a recording: refused before a window opens, naming the file.
  std::ofstream(dir_ / "text.bag") << "hello";
  EXPECT_EQ(test::RunCommand(Xvfb() + test::CalibenchExe() + " gui --bag " +
                                 (dir_ / "text.bag").string() + " --quit-after-frames 5",
                             &output),
            2);
  EXPECT_NE(output.find((dir_ / "text.bag").string() + ": not a recording"), std::string::npos)
      << output;
}

}  // namespace
}  // namespace calibench
