// `cmake --install`: the installed calibench finds its assets/ beside it (share/calibench/assets)
// when run from another directory, and writes a report and a target with them.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tests/test_support.h"

namespace calibench {
namespace {

namespace fs = std::filesystem;
using test::RunCommand;

TEST(Install, TheInstalledBinaryFindsItsAssetsFromAnotherDirectory) {
  const fs::path prefix = test::TempDir("install_prefix");
  std::string output;
  ASSERT_EQ(RunCommand("cmake --install '" + std::string(CALIBENCH_BINARY_DIR) + "' --prefix '" +
                           prefix.string() + "'",
                       &output),
            0)
      << output;
  const fs::path exe = prefix / "bin" / "calibench";
  ASSERT_TRUE(fs::exists(exe));
  for (const char* asset :
       {"report/report.html", "report/report.css", "report/report.js", "targets/a4.json",
        "targets/charuco-a3.json", "lidars/vlp16.json", "workbench/layout.json"})
    EXPECT_TRUE(fs::exists(prefix / "share/calibench/assets" / asset)) << asset;

  const fs::path elsewhere = test::TempDir("install_elsewhere");
  const std::string in_elsewhere = "cd '" + elsewhere.string() + "' && '" + exe.string() + "'";
  ASSERT_EQ(RunCommand(in_elsewhere + " --version", &output), 0) << output;
  EXPECT_NE(output.find("assets: " + (prefix / "share/calibench/assets").string()),
            std::string::npos)
      << output;
  ASSERT_EQ(RunCommand(in_elsewhere + " simulate --out sim --pairs 6 --seed 2", &output), 0)
      << output;
  ASSERT_EQ(
      RunCommand(in_elsewhere + " calibrate --dataset sim/dataset.json --out result.json", &output),
      0)
      << output;
  ASSERT_EQ(RunCommand(in_elsewhere + " report --no-views --result result.json --dataset " +
                           "sim/dataset.json --out report.html",
                       &output),
            0)
      << output;
  const std::string html = test::ReadFileBytes(elsewhere / "report.html");
  EXPECT_NE(html.find("Calibench calibration report"), std::string::npos);
  EXPECT_EQ(html.find("{{"), std::string::npos) << "a placeholder left unfilled";
  ASSERT_EQ(RunCommand(in_elsewhere + " target --preset a4 --out a4.pdf", &output), 0) << output;
  EXPECT_TRUE(fs::exists(elsewhere / "a4.pdf"));
}

}  // namespace
}  // namespace calibench
