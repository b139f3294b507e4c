// Issue "Accuracy at the Cramér–Rao bound", item 5: board-edge constraints. The rings' crossings
// of the sheet's edges sit on the edges at the true extrinsic (within their stated σ), and with
// few pairs they pin the in-plane translation that planes leave to the other poses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>
#include <vector>

#include "core/lidar_camera/pipeline.h"
#include "core/sim/sim.h"
#include "core/target/board_edges.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

SimOptions A3Hdl64(int pairs, std::uint64_t seed) {
  return test::A3Hdl64Options(pairs, 0.008, seed);
}

TEST(BoardEdges, CrossingsLieOnTheTrueEdgesWithinTheirSigma) {
  const SimOptions options = A3Hdl64(12, 41);
  const Dataset dataset = SimulateDataset(options, test::TempDir("board_edges_truth"));
  const std::vector<SimPairTruth> truth = SimulatePairTruth(options);
  const Pose cam_from_lidar = *dataset.cam_from_lidar_ground_truth;
  const SimOptions resolved = ResolveSimOptions(options);
  const Vec2 half(0.5 * resolved.board.SheetWidth(), 0.5 * resolved.board.SheetHeight());
  double sum = 0, sum_sq = 0;
  int count = 0, pairs_with_edges = 0;
  for (size_t k = 0; k < dataset.pairs.size(); ++k) {
    const PairFeatures f = ExtractPairFeatures(dataset, dataset.pairs[k], PipelineOptions{});
    if (f.status == PairStatus::kFailed) continue;
    pairs_with_edges += !f.lidar->edge_points.empty();
    for (const LidarEdgePoint& edge : f.lidar->edge_points) {
      double sigma = 0;
      const double e = BoardEdgeResidual(cam_from_lidar, truth[k].cam_from_board, half, edge,
                                         SolverOptions{}.edge_floor_sigma_m, nullptr, &sigma);
      sum += e / sigma;
      sum_sq += (e / sigma) * (e / sigma);
      ++count;
    }
  }
  const double mean = sum / count, rms = std::sqrt(sum_sq / count);
  std::printf(
      "%d edge crossings on %d pairs: normalised residual at the truth mean %+.3f, RMS %.3f\n",
      count, pairs_with_edges, mean, rms);
  EXPECT_GE(pairs_with_edges, 10);
  EXPECT_GE(count, 100);
  // Unbiased (the mean of `count` unit-variance residuals has a standard error of 1/√count) and
  // honestly scaled (uniform gap error plus the floor: RMS at most 1).
  EXPECT_LT(std::abs(mean), 4.0 / std::sqrt(count));
  EXPECT_GT(rms, 0.4);
  EXPECT_LT(rms, 1.2);
}

// Few pairs: the edges' worth shows in the translation. 40 trials of 4 pairs from a 40-pair pool.
TEST(BoardEdges, HelpMostWithFewPairs) {
  const SimOptions options = A3Hdl64(40, 42);
  const Dataset dataset = SimulateDataset(options, test::TempDir("board_edges_few"));
  const Pose truth = *dataset.cam_from_lidar_ground_truth;
  std::vector<PairFeatures> pool;
  for (const PairEntry& pair : dataset.pairs) {
    PairFeatures f = ExtractPairFeatures(dataset, pair, PipelineOptions{});
    if (f.status != PairStatus::kFailed) pool.push_back(std::move(f));
  }
  ASSERT_GE(pool.size(), 30u);
  std::mt19937_64 rng(5);
  double with_t = 0, without_t = 0, with_r = 0, without_r = 0;
  constexpr int kTrials = 40;
  for (int trial = 0; trial < kTrials; ++trial) {
    std::vector<PairFeatures> subset = pool;
    std::shuffle(subset.begin(), subset.end(), rng);
    subset.resize(4);
    for (const bool edges : {true, false}) {
      PipelineOptions o;
      o.solver.use_board_edges = edges;
      const CalibrationOutcome outcome = SolveFromFeatures(subset, o);
      ASSERT_TRUE(outcome.solution) << outcome.failure;
      const PoseError error = ComputePoseError(outcome.solution->cam_from_lidar, truth);
      (edges ? with_t : without_t) += std::pow(error.translation_m * 1e3, 2) / kTrials;
      (edges ? with_r : without_r) += std::pow(error.rotation_rad * 180 / M_PI, 2) / kTrials;
    }
  }
  std::printf(
      "4 pairs, %d trials: RMSE with edges %.2f mm / %.3f deg, without %.2f mm / %.3f deg\n",
      kTrials, std::sqrt(with_t), std::sqrt(with_r), std::sqrt(without_t), std::sqrt(without_r));
  EXPECT_LT(std::sqrt(with_t), 0.8 * std::sqrt(without_t));
  EXPECT_LT(std::sqrt(with_r), 1.1 * std::sqrt(without_r));
}

}  // namespace
}  // namespace calibench
