// `calibench report` and `calibrate --report`: one self-contained HTML file, one row per pair,
// held-out cross-validation that names a pair whose board moved between the LiDAR's and the
// camera's capture, and the real VLP-16 folder.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <regex>
#include <string>

#include "core/io/cloud_io.h"
#include "core/report/calibration_report.h"
#include "core/sim/sim.h"
#include "tests/acfr_manifest.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

namespace fs = std::filesystem;
using test::CalibenchExe;
using test::RunCommand;

int Count(const std::string& text, const std::regex& pattern) {
  return static_cast<int>(std::distance(std::sregex_iterator(text.begin(), text.end(), pattern),
                                        std::sregex_iterator()));
}

// Nothing the browser would fetch: every src is a data: URI, no stylesheet links, no imports,
// no url() outside data:, no href leaving the page.
void ExpectSelfContained(const std::string& html) {
  EXPECT_EQ(Count(html, std::regex(R"(src\s*=\s*["'](?!data:))")), 0) << "src= not data:";
  EXPECT_EQ(Count(html, std::regex(R"(<link\b)", std::regex::icase)), 0);
  EXPECT_EQ(Count(html, std::regex(R"(@import)")), 0);
  EXPECT_EQ(Count(html, std::regex(R"(url\(\s*["']?(?!data:))")), 0);
  EXPECT_EQ(Count(html, std::regex(R"(href\s*=\s*["'](?!#))")), 0);
  EXPECT_EQ(Count(html, std::regex(R"(<iframe|<object|<embed)")), 0);
}

void ExpectOneRowPerPair(const std::string& html, const Dataset& dataset) {
  EXPECT_EQ(Count(html, std::regex(R"(<tr data-pair=")")), static_cast<int>(dataset.pairs.size()));
  for (const PairEntry& pair : dataset.pairs)
    EXPECT_NE(html.find("<tr data-pair=\"" + pair.id + "\""), std::string::npos) << pair.id;
}

Dataset SimulateSet(const std::string& name, int pairs, std::uint64_t seed) {
  SimOptions sim = SimPreset("default");
  sim.num_pairs = pairs;
  sim.lidar_range_noise_m = 0.005;
  sim.seed = seed;
  return SimulateDataset(sim, test::TempDir(name));
}

TEST(Report, CalibrateWritesASelfContainedReportWithViews) {
  const Dataset dataset = SimulateSet("report_views", 8, 4);
  const fs::path dir = dataset.manifest.parent_path();
  std::string output;
  ASSERT_EQ(
      RunCommand(CalibenchExe() + " calibrate --dataset " + dataset.manifest.string() + " --out " +
                     (dir / "result.json").string() + " --report " + (dir / "report.html").string(),
                 &output),
      0)
      << output;
  const std::string html = test::ReadFileBytes(dir / "report.html");
  ASSERT_FALSE(html.empty());
  ExpectSelfContained(html);
  ExpectOneRowPerPair(html, dataset);
  // Both directions, labelled with what they map; Chart.js inlined with the plots' canvases.
  EXPECT_NE(html.find("p_cam = R p_lidar + t"), std::string::npos);
  EXPECT_NE(html.find("p_lidar = R p_cam + t"), std::string::npos);
  EXPECT_NE(html.find("Chart.js v3"), std::string::npos);
  EXPECT_EQ(Count(html, std::regex(R"(<canvas id=")")), 6);
  EXPECT_NE(html.find("static_transform_publisher"), std::string::npos);
  EXPECT_NE(html.find("&lt;joint name="), std::string::npos);  // the URDF snippet, escaped
  // The views: a 3D overview and one camera view per pair, inline.
  EXPECT_EQ(Count(html, std::regex(R"(<figure data-figure-pair=")")),
            static_cast<int>(dataset.pairs.size()));
  EXPECT_EQ(Count(html, std::regex(R"(src="data:image/(png|jpeg);base64,)")),
            static_cast<int>(dataset.pairs.size()) + 1);
  EXPECT_NE(html.find("Verdict: consistent"), std::string::npos);
  EXPECT_TRUE(test::TemporariesBeside(dir / "report.html").empty());
}

// The board of one pair moved between the two captures: its LiDAR points are turned 1.5 deg
// about the sheet's x axis and pushed 20 mm along its normal (small enough to pass the
// camera-guided gate, 2 deg / 30 mm). Held out, the other pairs predict its plane badly.
TEST(Report, AMovedBoardIsNamed) {
  Dataset dataset = SimulateSet("report_moved", 12, 9);
  const std::vector<Pose> cam_from_board = SampleBoardPoses(SimOptionsFromDataset(dataset));
  const int victim = 5;
  const Pose lidar_from_board =
      dataset.cam_from_lidar_ground_truth->inverse() * cam_from_board[victim];
  Pose moved = Pose::Identity();
  moved.linear() = Eigen::AngleAxisd(1.5 * kDegToRad, Vec3::UnitX()).toRotationMatrix();
  moved.translation() = Vec3(0, 0, 0.02);
  const Pose lidar_motion = lidar_from_board * moved * lidar_from_board.inverse();
  LidarCloud cloud = LoadCloud(dataset.pairs[victim].cloud);
  const double hw = 0.5 * dataset.target.SheetWidth() + 0.03;
  const double hh = 0.5 * dataset.target.SheetHeight() + 0.03;
  int on_board = 0;
  for (Eigen::Vector3f& p : cloud.points) {
    const Vec3 b = lidar_from_board.inverse() * p.cast<double>();
    if (std::abs(b.z()) > 0.05 || std::abs(b.x()) > hw || std::abs(b.y()) > hh) continue;
    p = (lidar_motion * p.cast<double>()).cast<float>();
    ++on_board;
  }
  ASSERT_GT(on_board, 50);
  SavePcd(dataset.pairs[victim].cloud, cloud);

  const fs::path dir = dataset.manifest.parent_path();
  std::string output;
  ASSERT_EQ(RunCommand(CalibenchExe() + " calibrate --dataset " + dataset.manifest.string() +
                           " --out " + (dir / "result.json").string(),
                       &output),
            0)
      << output;
  ASSERT_EQ(RunCommand(CalibenchExe() + " report --no-views --result " +
                           (dir / "result.json").string() + " --dataset " +
                           dataset.manifest.string() + " --out " + (dir / "report.html").string(),
                       &output),
            0)
      << output;
  const std::string& id = dataset.pairs[victim].id;
  EXPECT_NE(output.find("pair " + id + " disagrees"), std::string::npos) << output;
  const std::string html = test::ReadFileBytes(dir / "report.html");
  ExpectSelfContained(html);
  ExpectOneRowPerPair(html, dataset);
  EXPECT_NE(html.find("<tr data-pair=\"" + id + "\" class=\"disagrees\""), std::string::npos);
  EXPECT_EQ(Count(html, std::regex(R"(class="disagrees")")), 1) << "only the moved pair";
  EXPECT_NE(html.find("Distrust " + id), std::string::npos);
  // The same data without the moved board: consistent.
  const Dataset clean = SimulateSet("report_clean", 12, 9);
  PipelineOptions options;
  const CalibrationOutcome outcome = CalibrateDataset(clean, options);
  const CalibrationReport report = AnalyseCalibration(clean, outcome, options);
  ASSERT_TRUE(report.cross_validation);
  EXPECT_TRUE(report.cross_validation->disagreeing.empty()) << report.cross_validation->verdict;
  EXPECT_EQ(report.cross_validation->folds, 12);
  // Held out, a pair is predicted no better than when it was in the solve, and not much worse.
  EXPECT_GE(report.cross_validation->heldout_rms_angle_deg,
            report.cross_validation->train_rms_angle_deg);
  EXPECT_LT(report.cross_validation->heldout_rms_angle_deg,
            1.5 * report.cross_validation->train_rms_angle_deg);
  // σ as pairs accumulate: 3..12 pairs, shrinking overall.
  ASSERT_EQ(report.sigma_history.size(), 10u);
  EXPECT_LT(report.sigma_history.back().sigma_t_mm.norm(),
            report.sigma_history.front().sigma_t_mm.norm());
  for (const PairReportRow& row : report.pairs) {
    ASSERT_TRUE(row.influence_mm && row.heldout_angle_deg) << row.id;
    EXPECT_GT(*row.influence_mm, 0.0);
  }
}

TEST(Report, TheRealVlp16Folder) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const fs::path folder = test::WriteAcfrFolder(shared / "datasets" / "acfr-vlp16-chessboard",
                                                test::TempDir("report_acfr"));
  std::string output;
  ASSERT_EQ(RunCommand(CalibenchExe() + " calibrate --dataset " + folder.string() + " --out " +
                           (folder / "result.json").string() + " --report " +
                           (folder / "report.html").string(),
                       &output),
            0)
      << output;
  const Dataset dataset = LoadDataset(folder);
  const std::string html = test::ReadFileBytes(folder / "report.html");
  ExpectSelfContained(html);
  ExpectOneRowPerPair(html, dataset);
  EXPECT_EQ(Count(html, std::regex(R"(<figure data-figure-pair=")")), 40);
  std::printf("%s\n", output.substr(output.rfind("wrote ")).c_str());
}

}  // namespace
}  // namespace calibench
