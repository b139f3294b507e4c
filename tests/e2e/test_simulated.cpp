// End-to-end: simulate real files, calibrate them through the whole pipeline, compare with the
// simulator's ground truth. Parameterised over LiDARs, cameras and targets.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "core/io/cloud_io.h"
#include "core/lidar_camera/pipeline.h"
#include "core/sim/sim.h"
#include "tests/sim_scenes.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

using test::TrueBoardPlanes;

// An A3 sheet. The fisheye camera (fx = 450 px) needs fewer, larger ChArUco squares than the
// "charuco-a3" preset so that its 4x4 markers stay decodable (about 15 px wide) at 2 m.
BoardSpec A3Board(BoardType type, bool fisheye) {
  if (type == BoardType::kCheckerboard) return BoardPreset("a3");
  BoardSpec b = BoardPreset("charuco-a3");
  if (fisheye) {
    b.cols = 5;
    b.rows = 3;
    b.square_size = 0.08;
    b.marker_size = 0.064;
  }
  return b;
}

using Param = std::tuple<LidarModel, bool /*fisheye*/, BoardType>;

class SimulatedCalibration : public ::testing::TestWithParam<Param> {};

TEST_P(SimulatedCalibration, RecoversTheGroundTruth) {
  const auto [lidar, fisheye, board] = GetParam();
  SimOptions sim = SimPreset("default");
  sim.lidar = lidar;
  sim.fisheye = fisheye;
  sim.camera = CameraModel{};
  sim.camera.width = 0;  // the preset camera of that kind
  sim.board = A3Board(board, fisheye);
  sim.num_pairs = 20;
  // The fisheye (fx = 450 px) sees an A3 sheet 100 px wide at 2 m: on site one holds it closer.
  sim.min_distance_m = fisheye ? 1.0 : 1.2;
  sim.max_distance_m = fisheye ? 2.0 : 3.0;
  sim.lidar_range_noise_m = 0.005;
  sim.image_noise = 0.005;
  sim.seed = 17;
  const std::string name = LidarModelName(lidar) + (fisheye ? "_fisheye_" : "_pinhole_") +
                           (board == BoardType::kCharuco ? "charuco" : "checker");
  const Dataset dataset = SimulateDataset(sim, test::TempDir("e2e_" + name));
  ASSERT_TRUE(dataset.cam_from_lidar_ground_truth);

  PipelineOptions options;
  const CalibrationOutcome outcome = CalibrateDataset(dataset, options);
  int accepted = 0;
  for (const PairFeatures& p : outcome.pairs) {
    accepted += p.status == PairStatus::kAccepted;
    if (p.status != PairStatus::kAccepted) {
      EXPECT_FALSE(p.reason.empty());
      std::printf("[%s] pair %s: %s\n", name.c_str(), p.id.c_str(), p.reason.c_str());
    }
  }
  // The simulator does not check that the camera can decode every board (tiny fisheye ChArUco
  // boards at 2.5 m sometimes give < 6 corners): those pairs must fail with a reason, and they
  // must stay rare.
  EXPECT_GE(accepted, 17);
  ASSERT_TRUE(outcome.solution) << outcome.failure;
  const PoseError error =
      ComputePoseError(outcome.solution->cam_from_lidar, *dataset.cam_from_lidar_ground_truth);
  std::printf("[%s] %d pairs: translation error %.2f mm, rotation error %.3f deg\n", name.c_str(),
              accepted, error.translation_m * 1e3, error.rotation_rad * 180 / M_PI);
  // Twenty A3 boards at 1.2–3 m (fisheye 1–2 m) with 5 mm range noise. The paper's unweighted
  // solver is far from efficient on boards this small (a VLP-16 sees them with 2–5 rings): measured
  // 5–26 mm and 0.15–0.55 deg at N = 10 over this matrix. Bounds: 25 mm and 0.6 deg.
  EXPECT_LT(error.translation_m, 0.025);
  EXPECT_LT(error.rotation_rad, 0.6 * M_PI / 180);
  EXPECT_TRUE(outcome.solution->converged) << outcome.solution->termination.Describe();
  EXPECT_TRUE(outcome.solution->observability.well_constrained);

  // The same files without seeds: the board is detected in every cloud. A detected plane more
  // than 3 cm or 2 deg from the true board counts as false.
  Dataset unseeded = dataset;
  for (PairEntry& pair : unseeded.pairs) pair.lidar_seed.reset();
  const CalibrationOutcome detected = CalibrateDataset(unseeded, options);
  const auto truth = TrueBoardPlanes(dataset);
  int found = 0, lidar_ok_seeded = 0, wrong = 0;
  for (size_t i = 0; i < detected.pairs.size(); ++i) {
    const PairFeatures& p = detected.pairs[i];
    lidar_ok_seeded += outcome.pairs[i].lidar.has_value();
    if (!p.lidar) {
      std::printf("[%s] pair %s without seed: %s\n", name.c_str(), p.id.c_str(), p.reason.c_str());
      continue;
    }
    ++found;
    const Plane& board = truth.at(p.id);
    const double angle =
        std::acos(std::min(1.0, std::abs(p.lidar->plane.normal.dot(board.normal))));
    const double offset = std::abs(p.lidar->plane.distance - board.distance);
    if (angle > 2.0 * kDegToRad || offset > 0.03) {
      ++wrong;
      std::printf("[%s] pair %s: FALSE detection %.2f deg / %.1f mm off the board\n", name.c_str(),
                  p.id.c_str(), angle * kRadToDeg, offset * 1e3);
    }
  }
  ASSERT_TRUE(detected.solution) << detected.failure;
  const PoseError detected_error =
      ComputePoseError(detected.solution->cam_from_lidar, *dataset.cam_from_lidar_ground_truth);
  std::printf(
      "[%s] without seeds: %d of %d boards detected (seeded: %d), %d false; error %.2f mm, "
      "%.3f deg\n",
      name.c_str(), found, int(detected.pairs.size()), lidar_ok_seeded, wrong,
      detected_error.translation_m * 1e3, detected_error.rotation_rad * kRadToDeg);
  EXPECT_EQ(wrong, 0);
  EXPECT_GE(found, lidar_ok_seeded - 1);  // >= 98 % over the 12 combinations, asserted per set
  EXPECT_LT(detected_error.translation_m, std::max(0.0015, 1.1 * error.translation_m));
  EXPECT_LT(detected_error.rotation_rad, std::max(0.03 * kDegToRad, 1.1 * error.rotation_rad));
}

// A pair whose cloud holds a second, identical sheet: detection cannot tell the two apart and
// fails naming both; the camera's prediction from the other pairs' solution finds the right one.
TEST(CameraGuidedCompletion, ResolvesTwoBoardsInOneCloudWithTheCameraPrediction) {
  const Dataset dataset = test::CompletionMattersScene(test::TempDir("camera_guided"));
  const auto truth = TrueBoardPlanes(dataset);
  PipelineOptions without_guidance;
  without_guidance.camera_guided = false;
  const CalibrationOutcome alone = CalibrateDataset(dataset, without_guidance);
  EXPECT_EQ(alone.pairs[3].status, PairStatus::kFailed);
  EXPECT_NE(alone.pairs[3].reason.find("two board-like planes"), std::string::npos)
      << alone.pairs[3].reason;

  const CalibrationOutcome guided = CalibrateDataset(dataset, PipelineOptions{});
  const PairFeatures& pair = guided.pairs[3];
  ASSERT_EQ(pair.status, PairStatus::kAccepted) << pair.reason;
  EXPECT_EQ(pair.board_origin.source, BoardSource::kCameraGuided);
  ASSERT_TRUE(pair.lidar);
  const Plane& board = truth.at(pair.id);
  EXPECT_LT(std::acos(std::min(1.0, std::abs(pair.lidar->plane.normal.dot(board.normal)))),
            2.0 * kDegToRad);
  EXPECT_NEAR(pair.lidar->plane.distance, board.distance, 0.03);
  for (const PairFeatures& p : guided.pairs) EXPECT_EQ(p.status, PairStatus::kAccepted) << p.id;
}

std::string ParamName(const ::testing::TestParamInfo<Param>& info) {
  std::string lidar = LidarModelName(std::get<0>(info.param));
  for (char& c : lidar)
    if (c == '-') c = '_';
  return lidar + (std::get<1>(info.param) ? "_Fisheye" : "_Pinhole") +
         (std::get<2>(info.param) == BoardType::kCharuco ? "_Charuco" : "_Checkerboard");
}

INSTANTIATE_TEST_SUITE_P(
    AllSensorsAndTargets, SimulatedCalibration,
    ::testing::Combine(::testing::Values(LidarModel::kHdl64, LidarModel::kVlp16,
                                         LidarModel::kOs0_128),
                       ::testing::Bool(),
                       ::testing::Values(BoardType::kCheckerboard, BoardType::kCharuco)),
    ParamName);

}  // namespace
}  // namespace calibench
