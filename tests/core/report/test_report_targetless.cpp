// The report's targetless-check section (core/report/targetless_section.h): `check --json`'s
// object read back and drawn; anything else refused with the file named.
#include <gtest/gtest.h>

#include <fstream>

#include "core/report/targetless_section.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

void Write(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

TEST(ReportTargetlessSection, ACheckIsReadBackAndDrawn) {
  const auto dir = test::TempDir("report_targetless");
  const auto path = dir / "check.json";
  Write(path, R"({"verdict": "miscalibrated", "why": "the scene's edges align 1.00 deg away",
    "frames_used": 38, "frames_given": 40, "unconstrained_axes": ["translation along camera z"],
    "cam_from_lidar": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]],
    "change_t_mm": [1.5, -2.0, 3.0], "change_r_deg": [0.9, 0.1, -0.2],
    "sigma_t_mm": [4.0, 5.0, 60.0], "sigma_r_deg": [0.1, 0.05, 0.08], "change_sigmas": 6.2,
    "weakest_profile": {"direction": [0,0,1,0,0,0], "offsets_tolerance": [-2, -1, 0, 1, 2],
                        "costs": [10, 4, 1, 5, 12]}})");
  const TargetlessCheckSection section = LoadTargetlessCheck(path);
  EXPECT_EQ(section.verdict, "miscalibrated");
  EXPECT_EQ(section.frames_used, 38);
  ASSERT_TRUE(section.has_estimate);
  EXPECT_DOUBLE_EQ(section.change_r_deg.x(), 0.9);
  EXPECT_DOUBLE_EQ(section.sigma_t_mm.z(), 60.0);
  ASSERT_EQ(section.weakest_costs.size(), 5u);
  const std::string html = TargetlessCheckHtml(section);
  EXPECT_NE(html.find("id=\"targetless-check\""), std::string::npos);
  EXPECT_NE(html.find("verdict bad"), std::string::npos);
  EXPECT_NE(html.find("0.900"), std::string::npos) << html;
  EXPECT_NE(html.find("translation along camera z"), std::string::npos);
  EXPECT_NE(html.find("<polyline"), std::string::npos);
  EXPECT_NE(html.find("38 of 40 frames"), std::string::npos);
}

TEST(ReportTargetlessSection, WithoutAnEstimateOnlyTheVerdict) {
  const auto dir = test::TempDir("report_targetless_none");
  const auto path = dir / "check.json";
  Write(path, R"({"verdict": "cannot tell", "why": "too few edges <both> see",
    "frames_used": 0, "frames_given": 3, "cam_from_lidar": null, "unconstrained_axes": []})");
  const TargetlessCheckSection section = LoadTargetlessCheck(path);
  EXPECT_FALSE(section.has_estimate);
  const std::string html = TargetlessCheckHtml(section);
  EXPECT_NE(html.find("verdict warn"), std::string::npos);
  EXPECT_NE(html.find("&lt;both&gt;"), std::string::npos) << "text is escaped";
  EXPECT_EQ(html.find("<table"), std::string::npos);
}

TEST(ReportTargetlessSection, AResultFileIsNotACheck) {
  const auto dir = test::TempDir("report_targetless_bad");
  const auto path = dir / "result.json";
  Write(path, R"({"format": "calibench.result.v1", "cam_from_lidar": []})");
  try {
    LoadTargetlessCheck(path);
    FAIL() << "accepted a file without a verdict";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("calibench check"), std::string::npos) << e.what();
  }
  Write(path, R"({"verdict": "consistent", "cam_from_lidar": [[1]], "change_t_mm": [1, 2]})");
  EXPECT_THROW(LoadTargetlessCheck(path), IoError);
}

}  // namespace
}  // namespace calibench
