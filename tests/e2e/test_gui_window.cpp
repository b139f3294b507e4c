// A real window: `calibench gui` under Xvfb for a few frames, with a screenshot of what it showed.
#include <gtest/gtest.h>

#include <cstdio>

#include "core/base/image.h"
#include "core/io/image_io.h"
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

TEST_F(GuiWindow, OpensUnderXvfbAndShowsTheThreeViews) {
  const auto& dir = dir_;
  std::string output;
  const auto shot = dir / "window.png";
  const int code = test::RunCommand(
      "xvfb-run -a -s '-screen 0 1600x900x24' " + test::CalibenchExe() + " gui --dataset " +
          (dir / "data/dataset.json").string() + " --size 1600x900 --quit-after-frames 90 " +
          "--screenshot " + shot.string(),
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
  // The title bars of the views (the theme's blue) are where the layout puts them.
  for (int x : {10, 543, 1076}) {
    const std::uint8_t* p = image.Row(8) + 3 * x;
    EXPECT_GT(p[0], p[2]) << "no title bar at x = " << x << "; see " << shot;  // blue > red (BGR)
  }
}

// Left alone, the window draws nothing: after the pairs load it sleeps in the window system
// until input or work arrives (a loop that redraws continuously draws hundreds of frames a
// second under Xvfb, all of them "quiet").
TEST_F(GuiWindow, IdleWindowDrawsNoFrames) {
  const auto& dir = dir_;
  std::string output;
  const int code = test::RunCommand(
      "xvfb-run -a -s '-screen 0 1600x900x24' " + test::CalibenchExe() + " gui --dataset " +
          (dir / "data/dataset.json").string() + " --size 1600x900 --quit-after-seconds 6",
      &output);
  ASSERT_EQ(code, 0) << output;
  int frames = -1, quiet = -1;
  const auto at = output.find("frames drawn: ");
  ASSERT_NE(at, std::string::npos) << output;
  ASSERT_EQ(std::sscanf(output.c_str() + at, "frames drawn: %d (%d", &frames, &quiet), 2) << output;
  EXPECT_GT(frames, 0) << output;  // it did draw while loading
  EXPECT_EQ(quiet, 0) << output;
}

}  // namespace
}  // namespace calibench
