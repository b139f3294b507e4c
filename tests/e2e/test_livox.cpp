// Issue 46 item 3: Livox-class scanners end to end on the simulator, without seeds. A still hold
// integrated into one cloud (1 s: 100-200 k returns) and single 0.1 s frames of a Mid-40-like
// rosette; Avia-like and Mid-360-like holds. Each set: the pairs accepted, the error against the
// set's planes-only Cramér–Rao bound and against the reported σ, and the summary's words (a
// non-repetitive scan, never a segment or a moved sensor).
#include <gtest/gtest.h>

#include <cstdio>

#include "core/evaluation/crlb.h"
#include "core/lidar_camera/pipeline.h"
#include "core/lidar_camera/result_io.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

struct LivoxCase {
  LidarModel lidar;
  double frame_s;
  int min_accepted;        // of 20
  double max_bound_ratio;  // error / CRLB, translation and rotation
  // Accepted pairs whose board gave edge points (the beam's crossings of the sheet's border).
  int min_edge_pairs = 0;
};

SimOptions LivoxSet(const LivoxCase& c) {
  SimOptions sim = SimPreset("default");  // A3 checkerboard, 1440x1080 pinhole
  sim.lidar = c.lidar;
  sim.lidar_frame_s = c.frame_s;
  sim.num_pairs = 20;
  sim.min_distance_m = 2.0;
  sim.max_distance_m = 6.0;
  sim.lidar_range_noise_m = 0.02;  // a Livox Mid-40's 2 cm (1σ)
  sim.seed = 1;
  return sim;
}

void CheckLivoxSet(const LivoxCase& c, const fs::path& dir) {
  const SimOptions sim = LivoxSet(c);
  Dataset dataset = SimulateDataset(sim, dir);
  for (PairEntry& pair : dataset.pairs) pair.lidar_seed.reset();  // seedless
  const CalibrationOutcome outcome = CalibrateDataset(dataset, PipelineOptions{});
  ASSERT_TRUE(outcome.solution) << outcome.failure;
  int accepted = 0, with_edges = 0;
  double corner_sigma_px = 0;
  for (const PairFeatures& p : outcome.pairs) {
    accepted += p.status == PairStatus::kAccepted;
    with_edges += p.status == PairStatus::kAccepted && p.lidar && !p.lidar->edge_points.empty();
    if (p.status != PairStatus::kAccepted)
      std::printf("  %s: %s\n", p.id.c_str(), p.reason.c_str());
    if (p.camera) corner_sigma_px += p.camera->corner_sigma_px / outcome.pairs.size();
  }
  const CramerRaoBound bound = SimulationBound(MakeSimulationBoundInput(sim, corner_sigma_px));
  const Pose truth = *dataset.cam_from_lidar_ground_truth;
  const PoseError error = ComputePoseError(outcome.solution->cam_from_lidar, truth);
  const double sigma_t =
      TranslationStd(outcome.solution->covariance, outcome.solution->cam_from_lidar).norm();
  const double sigma_r =
      std::sqrt(outcome.solution->covariance.bottomRightCorner<3, 3>().trace()) * kRadToDeg;
  const double error_r = error.rotation_rad * kRadToDeg;
  std::printf(
      "%s %.1f s: %d/20 accepted, %d with edges; error %.2f mm %.3f deg; bound %.2f mm %.3f deg "
      "(ratio %.2f, "
      "%.2f); sigma %.2f mm %.3f deg (%.1f, %.1f sigma)\n",
      LidarModelName(c.lidar).c_str(), c.frame_s, accepted, with_edges, error.translation_m * 1e3,
      error_r, bound.translation_rms_m * 1e3, bound.rotation_rms_deg,
      error.translation_m / bound.translation_rms_m, error_r / bound.rotation_rms_deg,
      sigma_t * 1e3, sigma_r, error.translation_m / sigma_t, error_r / sigma_r);
  EXPECT_GE(accepted, c.min_accepted);
  EXPECT_GE(with_edges, c.min_edge_pairs);
  EXPECT_LE(error.translation_m, c.max_bound_ratio * bound.translation_rms_m);
  EXPECT_LE(error_r, c.max_bound_ratio * bound.rotation_rms_deg);
  EXPECT_LE(error.translation_m, 3.0 * sigma_t);
  EXPECT_LE(error_r, 3.0 * sigma_r);
  const std::string summary = FormatSummary(outcome);
  EXPECT_NE(summary.find("LiDAR model: non-repetitive for all"), std::string::npos) << summary;
  EXPECT_EQ(summary.find("segment"), std::string::npos) << summary;
  EXPECT_EQ(summary.find("moved"), std::string::npos) << summary;
  EXPECT_NE(summary.find("well constrained"), std::string::npos) << summary;
}

TEST(Livox, Mid40HoldsSeedless) {
  CheckLivoxSet({LidarModel::kMid40, 1.0, 19, 2.0, 18}, test::TempDir("livox_mid40_hold"));
}

// Single frames leave a far board a few strokes of the rosette: the plane is fitted from where the
// board faces the sensor along them (FitBoardPlane), not across them, and calibrates within the
// bound.
TEST(Livox, Mid40FramesSeedless) {
  CheckLivoxSet({LidarModel::kMid40, 0.1, 18, 2.0}, test::TempDir("livox_mid40_frame"));
}

// Six lasers share the Avia's point rate: each one's returns step farther along its stroke than a
// Mid-40's, and its crossings of the sheet's border are edge points all the same.
TEST(Livox, AviaHoldsSeedless) {
  CheckLivoxSet({LidarModel::kAvia, 1.0, 19, 2.0, 18}, test::TempDir("livox_avia_hold"));
}

// An Avia's six lasers draw six rosettes a frame: enough strokes over a board at 2-6 m for a
// plane (one laser's frame left most boards one stroke or none: 2/20).
TEST(Livox, AviaFramesSeedless) {
  CheckLivoxSet({LidarModel::kAvia, 0.1, 18, 2.0, 15}, test::TempDir("livox_avia_frame"));
}

TEST(Livox, Mid360HoldsSeedless) {
  CheckLivoxSet({LidarModel::kMid360, 1.0, 19, 1.5, 18}, test::TempDir("livox_mid360_hold"));
}

// A Mid-360 frame holds ~1 return per square degree over 360 x 59 degrees: a board at 2-3 m is
// crossed by one stroke per laser, too sparse for any neighbourhood to be planar. The board is the
// cluster that stands apart from the room in range (RangeClusters); before it, 0/20 were found.
TEST(Livox, Mid360FramesSeedless) {
  CheckLivoxSet({LidarModel::kMid360, 0.1, 18, 2.0, 15}, test::TempDir("livox_mid360_frame"));
}

}  // namespace
}  // namespace calibench
