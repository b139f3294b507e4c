// Issue 32 item 4: the summary and the result say which residuals the solve had (planes, and
// board edges per pair) and, where edges are missing, what the LiDAR showed and what it means.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "core/lidar_camera/pipeline.h"
#include "core/lidar_camera/result_io.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

CalibrationOutcome Calibrate(const fs::path& dir, bool board_only, SolverMethod method) {
  SimOptions sim = SimPreset("default");
  sim.num_pairs = 6;
  sim.seed = 7;
  sim.lidar_range_noise_m = 0.005;
  sim.board_only_clouds = board_only;
  const Dataset dataset = SimulateDataset(sim, dir);
  PipelineOptions options;
  options.solver.method = method;
  return CalibrateDataset(dataset, options);
}

TEST(ResidualsAvailable, FullScansGiveEdgesInEveryPair) {
  const fs::path dir = test::TempDir("residuals_full");
  const CalibrationOutcome outcome = Calibrate(dir / "sim", false, SolverMethod::kWeightedMl);
  ASSERT_TRUE(outcome.solution) << outcome.failure;
  const ResidualCounts counts = CountResiduals(outcome);
  EXPECT_EQ(counts.plane_pairs, 6);
  EXPECT_EQ(counts.edge_pairs, 6);
  EXPECT_EQ(counts.edge_points, outcome.solution->num_edge_residuals);
  EXPECT_GT(counts.edge_points, 6 * 4);
  EXPECT_EQ(counts.note, "");
  const std::string summary = FormatSummary(outcome);
  EXPECT_NE(summary.find("residuals: board planes from 6 pairs, board edges from 6 pairs (" +
                         std::to_string(counts.edge_points) + " crossings of the sheet"),
            std::string::npos)
      << summary;
}

TEST(ResidualsAvailable, BoardOnlyCloudsSayEdgesAreUnusedAndWhy) {
  const fs::path dir = test::TempDir("residuals_board_only");
  const CalibrationOutcome outcome = Calibrate(dir / "sim", true, SolverMethod::kWeightedMl);
  ASSERT_TRUE(outcome.solution) << outcome.failure;
  const ResidualCounts counts = CountResiduals(outcome);
  EXPECT_EQ(counts.plane_pairs, 6);
  EXPECT_EQ(counts.edge_pairs, 0);
  EXPECT_EQ(counts.edge_points, 0);
  EXPECT_NE(counts.note.find("board edges unused, no pair gave an edge point ("), std::string::npos)
      << counts.note;
  EXPECT_NE(counts.note.find("the pose rests on the planes alone"), std::string::npos);
  const std::string summary = FormatSummary(outcome);
  EXPECT_NE(summary.find("board edges from 0 pairs (0 crossings of the sheet"), std::string::npos)
      << summary;
  EXPECT_NE(summary.find(counts.note), std::string::npos);

  // The result file: the counts, and per pair what its rings' ends showed.
  WriteResult(dir / "result.json", outcome, PipelineOptions{}.solver);
  const nlohmann::json json = nlohmann::json::parse(std::ifstream(dir / "result.json"));
  const nlohmann::json& available = json["solver"]["residuals_available"];
  EXPECT_EQ(available["plane_pairs"], 6);
  EXPECT_EQ(available["edge_pairs"], 0);
  EXPECT_EQ(available["note"], counts.note);
  for (const nlohmann::json& pair : json["pairs"]) {
    ASSERT_EQ(pair["status"], "accepted");
    EXPECT_EQ(pair["board_edge_points"], 0);
    ASSERT_TRUE(pair.contains("lidar_ring_ends")) << pair.dump();
  }
}

TEST(ResidualsAvailable, APlanesOnlyMethodSaysSo) {
  const fs::path dir = test::TempDir("residuals_paper");
  const CalibrationOutcome outcome = Calibrate(dir / "sim", false, SolverMethod::kCa2libGn);
  ASSERT_TRUE(outcome.solution) << outcome.failure;
  const ResidualCounts counts = CountResiduals(outcome);
  EXPECT_FALSE(counts.edges_in_model);
  EXPECT_EQ(counts.edge_points, 0);
  EXPECT_EQ(counts.note, "the method (ca2lib-gn) uses the board planes only, no board edges");
  EXPECT_NE(FormatSummary(outcome).find("residuals: board planes from 6 pairs\n"),
            std::string::npos);
}

}  // namespace
}  // namespace calibench
