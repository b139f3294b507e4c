// `calibench check` on a recording read directly (an MCAP written by the test-side writer from the
// simulator: a VLP-16 and a camera streaming while a board is held at 4 poses), against the
// calibration of the same capture imported as a folder: the same frames either way, one JSON
// object on stdout, exit 0 whatever the verdict; and `render --view check` (the check window).
#include <gtest/gtest.h>

#include <cstdlib>
#include <nlohmann/json.hpp>

#include "core/io/image_io.h"
#include "tests/bag_writers.h"
#include "tests/sim_recording.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

TEST(CheckRecording, AnMcapIsCheckedDirectlyWithOneJsonObjectOnStdout) {
  const auto dir = test::TempDir("check_recording");
  const auto mcap = dir / "drive.mcap";
  {
    auto writer = test::OpenMcapWriter(mcap, "ros2", "zstd");
    test::WriteSimRecording(writer.get(), MessageEncoding::kCdr, test::SmallSimRecording(4));
    writer->Close();
  }
  const std::string exe = test::CalibenchExe();
  std::string out;
  ASSERT_EQ(test::RunCommand(
                exe + " import " + mcap.string() + " --out " + (dir / "folder").string(), &out),
            0)
      << out;
  ASSERT_EQ(test::RunCommand(exe + " calibrate --dataset " + (dir / "folder").string() + " --out " +
                                 (dir / "result.json").string(),
                             &out),
            0)
      << out;
  const auto json_path = dir / "check.json";
  ASSERT_EQ(
      test::RunCommand("(" + exe + " check --dataset " + mcap.string() + " --result " +
                           (dir / "result.json").string() + " --json > " + json_path.string() + ")",
                       &out),
      0)
      << out;
  const nlohmann::json j = nlohmann::json::parse(test::ReadFileBytes(json_path));
  const std::string verdict = j["verdict"];
  EXPECT_TRUE(verdict == "consistent" || verdict == "miscalibrated" || verdict == "cannot tell");
  // One frame per 0.5 s of a ~13 s recording, each cloud with its image.
  EXPECT_GE(j["frames_given"].get<int>(), 20) << out;
  EXPECT_GE(j["frames_used"].get<int>(), 10) << j["why"];
  EXPECT_NE(out.find("read frame"), std::string::npos) << "progress goes to stderr";
  // A small room with a board and blank walls: this scene fixes little, and says so.
  EXPECT_EQ(verdict, "cannot tell") << j["why"];
  EXPECT_FALSE(j["unconstrained_axes"].empty());

  // The report of that calibration with the check as a section.
  const auto html = dir / "report.html";
  ASSERT_EQ(
      test::RunCommand(exe + " report --result " + (dir / "result.json").string() + " --dataset " +
                           (dir / "folder").string() + " --check " + json_path.string() +
                           " --no-views --no-cross-validation --out " + html.string(),
                       &out),
      0)
      << out;
  const std::string page = test::ReadFileBytes(html);
  EXPECT_NE(page.find("id=\"targetless-check\""), std::string::npos);
  EXPECT_NE(page.find(verdict), std::string::npos);

  // `render --view check`: the workbench with its check window open, after the same check.
  const auto png = dir / "check.png";
  const int code = test::RunCommand(
      exe + " render --view check --dataset " + (dir / "folder").string() + " --result " +
          (dir / "result.json").string() + " --size 1280x800 --out " + png.string(),
      &out);
  if (code != 0 && out.find("no headless OpenGL") != std::string::npos &&
      std::getenv("CALIBENCH_REQUIRE_GL") == nullptr)
    GTEST_SKIP() << "no headless OpenGL here: " << out;
  ASSERT_EQ(code, 0) << out;
  const ImageU8 drawn = LoadImage(png);
  EXPECT_EQ(drawn.width, 1280);
  EXPECT_EQ(drawn.height, 800);
  EXPECT_NE(out.find("targetless check of"), std::string::npos) << out;
  // Without --result the workbench's own calibration is checked: none without --solve.
  EXPECT_NE(test::RunCommand(exe + " render --view check --dataset " + (dir / "folder").string() +
                                 " --out " + png.string(),
                             &out),
            0);
  EXPECT_NE(out.find("solve first"), std::string::npos) << out;
}

}  // namespace
}  // namespace calibench
