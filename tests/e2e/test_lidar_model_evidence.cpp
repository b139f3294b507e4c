// Issue 75, Deliver 1: a ring-less LiDAR's noise model chosen by the held-out pairs, not by the
// cloud's extent. The regression it names: a swept scan that is mostly board was judged a
// "segment" by the 1.5 m extent rule and fitted point-to-plane (the real rotary-stage set 47 mm
// from its authors' result, 28 mm along the rays). It came in with the segment model (ea10d64:
// ring-less clouds of little azimuth fitted point-to-plane, where before every ring-less cloud was
// fitted along its rays) and stayed with the extent rule (e6967f2). A nodding line scanner's
// board-only clouds reproduce it: the look says segment, the held-out pairs say rays.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "core/io/cloud_io.h"
#include "core/lidar_camera/pipeline.h"
#include "core/lidar_camera/result_io.h"
#include "core/results/result_json.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

double MedianOf(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

// The rotary-stage set's shape: 15 pairs, the scans all board (a nodding scanner's 28° window
// cropped to the sheet), 1 cm of range noise.
SimOptions MostlyBoard(std::uint64_t seed) {
  SimOptions sim = SimPreset("default");
  sim.lidar = LidarModel::kNodding2d;
  sim.num_pairs = 15;
  sim.min_distance_m = 0.9;
  sim.max_distance_m = 1.4;
  sim.lidar_range_noise_m = 0.01;
  sim.board_only_clouds = true;
  sim.lidar_seeds = false;
  sim.seed = seed;
  return sim;
}

TEST(LidarModelEvidence, AScanThatIsMostlyBoardGetsTheRaysItsBoardsSupport) {
  const fs::path dir = test::TempDir("lidar_model_evidence");
  std::vector<double> chosen_t, segment_t, rays_t, chosen_r, segment_r, rays_r;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const Dataset dataset = SimulateDataset(MostlyBoard(seed), dir / std::to_string(seed));
    const Pose truth = *dataset.cam_from_lidar_ground_truth;
    // The look alone says segment: the board fills the scan.
    EXPECT_EQ(ClassifyLidarGeometry(LoadCloud(dataset.pairs[0].cloud)).geometry,
              LidarGeometry::kSegment);
    const CalibrationOutcome chosen = CalibrateDataset(dataset, PipelineOptions{});
    PipelineOptions segment;
    segment.lidar_model = LidarGeometry::kSegment;
    const CalibrationOutcome by_look = CalibrateDataset(dataset, segment);
    PipelineOptions rays;
    rays.lidar_model = LidarGeometry::kNonRepetitive;
    const CalibrationOutcome along_rays = CalibrateDataset(dataset, rays);
    // Without the evidence the look decides: the regression.
    PipelineOptions unasked;
    unasked.lidar_model_evidence.enabled = false;
    const CalibrationOutcome look_only = CalibrateDataset(dataset, unasked);
    ASSERT_TRUE(chosen.solution && by_look.solution && along_rays.solution && look_only.solution);
    EXPECT_FALSE(look_only.lidar_model_evidence);
    EXPECT_EQ(DescribeLidarModel(look_only).rfind("LiDAR model: segment for all 15 pairs", 0), 0u);

    ASSERT_TRUE(chosen.lidar_model_evidence);
    const LidarModelEvidence& evidence = *chosen.lidar_model_evidence;
    EXPECT_EQ(evidence.chosen, LidarGeometry::kNonRepetitive);
    EXPECT_FALSE(evidence.tie);
    EXPECT_GT(evidence.margin, 1.2);
    EXPECT_GE(evidence.significance_z, 2.0);
    EXPECT_EQ(evidence.switched_pairs, 15);
    const std::string model = DescribeLidarModel(chosen);
    EXPECT_EQ(model.rfind("LiDAR model: non-repetitive for all 15 pairs (chosen by the held-out "
                          "pairs over the cloud's look: no rings",
                          0),
              0u)
        << model;
    EXPECT_NE(model.find("Chosen by the held-out pairs: ranges along rays (non-repetitive), their "
                         "boards "),
              std::string::npos)
        << model;
    EXPECT_NE(FormatSummary(chosen).find(model), std::string::npos);
    // The result file's contract: lidar_model.evidence {criterion, candidates, margin, ...}.
    WriteResult(dir / "result.json", chosen, PipelineOptions{}.solver);
    const nlohmann::json result = nlohmann::json::parse(test::ReadFileBytes(dir / "result.json"));
    const nlohmann::json& e = result.at("lidar_model").at("evidence");
    EXPECT_NE(e.at("criterion").get<std::string>().find("held-out"), std::string::npos);
    ASSERT_EQ(e.at("candidates").size(), 2u);
    EXPECT_EQ(e.at("candidates")[0].at("geometry"), "non-repetitive");
    EXPECT_EQ(e.at("candidates")[0].at("along_rays"), true);
    EXPECT_EQ(e.at("candidates")[1].at("geometry"), "segment");
    EXPECT_LT(e.at("candidates")[0].at("heldout_rms_m").get<double>(),
              e.at("candidates")[1].at("heldout_rms_m").get<double>());
    EXPECT_NEAR(e.at("margin").get<double>(), evidence.margin, 1e-12);
    EXPECT_EQ(e.at("chosen"), "non-repetitive");
    EXPECT_EQ(result.at("lidar_model").at("geometry"), "non-repetitive");
    if (seed == 1) std::printf("%s\n", model.c_str());

    const PoseError c = ComputePoseError(chosen.solution->cam_from_lidar, truth);
    const PoseError s = ComputePoseError(by_look.solution->cam_from_lidar, truth);
    const PoseError r = ComputePoseError(along_rays.solution->cam_from_lidar, truth);
    std::printf(
        "mostly-board seed %d: chosen %.2f mm %.3f deg (margin %.2fx, z %.1f) | segment %.2f mm "
        "%.3f deg | rays %.2f mm %.3f deg\n",
        int(seed), c.translation_m * 1e3, c.rotation_rad * kRadToDeg, evidence.margin,
        evidence.significance_z, s.translation_m * 1e3, s.rotation_rad * kRadToDeg,
        r.translation_m * 1e3, r.rotation_rad * kRadToDeg);
    chosen_t.push_back(c.translation_m);
    segment_t.push_back(s.translation_m);
    rays_t.push_back(r.translation_m);
    chosen_r.push_back(c.rotation_rad);
    segment_r.push_back(s.rotation_rad);
    rays_r.push_back(r.rotation_rad);
  }
  // At least as accurate as the best fixed model (the rays: the crop keeps the same ring-bias
  // and edge choices, so the two agree within a tenth), and clearly better than the look's.
  EXPECT_LE(MedianOf(chosen_t), 1.1 * MedianOf(rays_t));
  EXPECT_LE(MedianOf(chosen_r), 1.1 * MedianOf(rays_r));
  EXPECT_LT(MedianOf(chosen_t), 0.5 * MedianOf(segment_t));
  EXPECT_LT(MedianOf(chosen_r), 0.5 * MedianOf(segment_r));
}

// Where the held-out pairs cannot tell the models apart, each pair keeps its cloud's look's model
// and the summary says the data could not tell: the rotary-stage scanner of the simulator (its
// mirror off the axis, estimated from the scan), 10 pairs of 5 mm, whose boards fit alike either
// way. The better held-out fit of such a tie is a coin: point-to-plane here, 2.17 mm from the
// truth against the rays' 0.47 mm.
TEST(LidarModelEvidence, ATieKeepsTheLooksModelAndSaysSo) {
  const fs::path dir = test::TempDir("lidar_model_evidence_tie");
  SimOptions sim = SimPreset("default");
  sim.lidar = LidarModel::kSwept2d;
  sim.num_pairs = 10;
  sim.lidar_range_noise_m = 0.005;
  sim.image_noise = 0.02;
  sim.seed = 1;
  const Dataset dataset = SimulateDataset(sim, dir / "swept");
  const CalibrationOutcome outcome = CalibrateDataset(dataset, PipelineOptions{});
  PipelineOptions forced;
  forced.lidar_model = LidarGeometry::kSwept;
  const CalibrationOutcome swept = CalibrateDataset(dataset, forced);
  ASSERT_TRUE(outcome.solution && swept.solution);
  ASSERT_TRUE(outcome.lidar_model_evidence);
  const LidarModelEvidence& evidence = *outcome.lidar_model_evidence;
  EXPECT_TRUE(evidence.tie);
  EXPECT_LT(evidence.significance_z, 2.0);
  EXPECT_EQ(evidence.chosen, LidarGeometry::kSwept);
  EXPECT_EQ(evidence.switched_pairs, 0);
  const std::string said = DescribeLidarModel(outcome);
  EXPECT_EQ(said.rfind("LiDAR model: swept for all 10 pairs", 0), 0u) << said;
  EXPECT_NE(said.find("The held-out pairs cannot tell "), std::string::npos) << said;
  EXPECT_NE(said.find("the cloud's look decides (swept)"), std::string::npos) << said;
  // Kept means the same fits: the forced model's result.
  EXPECT_LT(ComputePoseError(outcome.solution->cam_from_lidar, swept.solution->cam_from_lidar)
                .translation_m,
            1e-9);
  // Too few pairs to ask: the look's model stands, and nothing is claimed.
  SimOptions few = MostlyBoard(4);
  few.num_pairs = 5;
  const CalibrationOutcome five = CalibrateDataset(SimulateDataset(few, dir / "few"), {});
  ASSERT_TRUE(five.solution) << five.failure;
  EXPECT_FALSE(five.lidar_model_evidence);
  EXPECT_EQ(DescribeLidarModel(five).find("held-out"), std::string::npos);
}

}  // namespace
}  // namespace calibench
