// Issue "Accuracy at the Cramér–Rao bound": on simulated A3 / HDL-64 / 20-pair calibrations the
// weighted estimator's error sits near the bound, at most half the paper solver's, and its
// reported covariance is calibrated (normalised errors follow χ²(6)).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <numeric>
#include <random>
#include <vector>

#include "core/evaluation/crlb.h"
#include "core/lidar_camera/pipeline.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

constexpr int kPoolPairs = 60;
constexpr int kPairsPerTrial = 20;
constexpr int kTrials = 100;
constexpr double kChi2Dof6Quantile95 = 12.592;

struct Pool {
  std::vector<PairFeatures> features;  // accepted pairs only
  std::vector<int> sim_index;          // the simulator's pair index of each
  SimulationBoundInput bound_input;
  Pose truth;
  double corner_sigma_px = 0.0;  // mean of the PnP residual-based estimates
};

// The protocol: an A3 checkerboard, an HDL-64, boards at 1.5–6 m.
SimOptions A3Hdl64(double range_noise_m, std::uint64_t seed) {
  return test::A3Hdl64Options(kPoolPairs, range_noise_m, seed);
}

Pool MakePool(double range_noise_m, std::uint64_t seed) {
  const SimOptions options = A3Hdl64(range_noise_m, seed);
  const auto dir = test::TempDir("accuracy_bound_" + std::to_string(seed) + "_" +
                                 std::to_string(static_cast<int>(range_noise_m * 1e3)) + "mm");
  const Dataset dataset = SimulateDataset(options, dir);
  Pool pool;
  pool.truth = *dataset.cam_from_lidar_ground_truth;
  PipelineOptions extract;
  for (size_t k = 0; k < dataset.pairs.size(); ++k) {
    PairFeatures f = ExtractPairFeatures(dataset, dataset.pairs[k], extract);
    if (f.status == PairStatus::kFailed) continue;
    pool.corner_sigma_px += f.camera->corner_sigma_px;
    pool.features.push_back(std::move(f));
    pool.sim_index.push_back(static_cast<int>(k));
  }
  pool.corner_sigma_px /= std::max<size_t>(1, pool.features.size());
  pool.bound_input = MakeSimulationBoundInput(options, pool.corner_sigma_px);
  return pool;
}

struct TrialStats {
  double rmse_t_mm = 0, rmse_r_deg = 0;
  double bound_t_mm = 0, bound_r_deg = 0;  // RMS over trials of the per-trial bound
  double chi2_fraction = 0;                // fraction with normalised error < 12.59
  double mean_chi2 = 0;
};

TrialStats RunTrials(const Pool& pool, SolverMethod method, std::uint64_t seed,
                     bool board_edges = true) {
  std::mt19937_64 rng(seed);
  PipelineOptions options;
  options.solver.method = method;
  options.solver.use_board_edges = board_edges;
  TrialStats stats;
  int below = 0;
  std::vector<int> order(pool.features.size());
  for (int trial = 0; trial < kTrials; ++trial) {
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    order.resize(kPairsPerTrial);
    std::vector<PairFeatures> subset;
    std::vector<int> sim_subset;
    for (int k : order) {
      subset.push_back(pool.features[k]);
      sim_subset.push_back(pool.sim_index[k]);
    }
    order.resize(pool.features.size());
    const CalibrationOutcome outcome = SolveFromFeatures(subset, options);
    EXPECT_TRUE(outcome.solution) << outcome.failure;
    if (!outcome.solution) continue;
    const Pose& estimate = outcome.solution->cam_from_lidar;
    const PoseError error = ComputePoseError(estimate, pool.truth);
    stats.rmse_t_mm += std::pow(error.translation_m * 1e3, 2) / kTrials;
    stats.rmse_r_deg += std::pow(error.rotation_rad * 180 / M_PI, 2) / kTrials;
    const CramerRaoBound bound = SimulationBound(pool.bound_input, sim_subset);
    stats.bound_t_mm += std::pow(bound.translation_rms_m * 1e3, 2) / kTrials;
    stats.bound_r_deg += std::pow(bound.rotation_rms_deg, 2) / kTrials;
    // Normalised error in the solver's own parametrisation: estimate = truth · Exp(e).
    const Vec6 e = LogSE3(pool.truth.inverse() * estimate);
    const double chi2 = e.dot(outcome.solution->covariance.ldlt().solve(e));
    stats.mean_chi2 += chi2 / kTrials;
    if (chi2 < kChi2Dof6Quantile95) ++below;
  }
  stats.rmse_t_mm = std::sqrt(stats.rmse_t_mm);
  stats.rmse_r_deg = std::sqrt(stats.rmse_r_deg);
  stats.bound_t_mm = std::sqrt(stats.bound_t_mm);
  stats.bound_r_deg = std::sqrt(stats.bound_r_deg);
  stats.chi2_fraction = static_cast<double>(below) / kTrials;
  return stats;
}

void Report(const char* name, double noise_mm, const TrialStats& s) {
  std::printf(
      "%-24s %4.0f mm: RMSE %.2f mm / %.3f deg, bound %.2f mm / %.3f deg, ratio %.2f / %.2f, "
      "chi2<12.59 %.2f, mean chi2 %.2f\n",
      name, noise_mm, s.rmse_t_mm, s.rmse_r_deg, s.bound_t_mm, s.bound_r_deg,
      s.rmse_t_mm / s.bound_t_mm, s.rmse_r_deg / s.bound_r_deg, s.chi2_fraction, s.mean_chi2);
}

class AccuracyBound : public ::testing::TestWithParam<double> {};

TEST_P(AccuracyBound, WeightedSitsAtTheBoundAndHalvesThePaperSolver) {
  const double noise_m = GetParam();
  const Pool pool = MakePool(noise_m, 20261121);
  ASSERT_GE(pool.features.size(), 40u) << "too few usable pairs in the pool";
  std::printf("pool: %zu usable pairs, corner sigma %.3f px\n", pool.features.size(),
              pool.corner_sigma_px);
  // The bound (calibench evaluate --crlb) is that of the plane pairs: the weighted estimator is
  // held to it with the board edges off, and the default (edges on) must do at least as well.
  const TrialStats planes_only = RunTrials(pool, SolverMethod::kWeightedMl, 7, false);
  const TrialStats weighted = RunTrials(pool, SolverMethod::kWeightedMl, 7);
  const TrialStats paper = RunTrials(pool, SolverMethod::kCa2libGn, 7);
  const TrialStats kim = RunTrials(pool, SolverMethod::kKim, 7);
  Report("weighted-ml, planes only", noise_m * 1e3, planes_only);
  Report("weighted-ml + edges", noise_m * 1e3, weighted);
  Report("ca2lib-gn", noise_m * 1e3, paper);
  Report("kim", noise_m * 1e3, kim);
  // Issue 5: the weighted estimator within 1.3x the bound, at most half the paper solver's error,
  // and its reported covariance calibrated, with and without the edges: the mean normalised
  // squared error within 3 standard errors of χ²(6)'s mean (6 ± 3·√(12/100)), and the fraction
  // below its 95% quantile in [0.90, 0.99] (the binomial's standard error over 100 trials is
  // 0.022: the band is −2.3 to +1.8 of them).
  EXPECT_LE(planes_only.rmse_t_mm, 1.3 * planes_only.bound_t_mm);
  EXPECT_LE(planes_only.rmse_r_deg, 1.3 * planes_only.bound_r_deg);
  EXPECT_LE(planes_only.rmse_t_mm, 0.5 * paper.rmse_t_mm);
  EXPECT_LE(planes_only.rmse_r_deg, 0.5 * paper.rmse_r_deg);
  EXPECT_LE(weighted.rmse_t_mm, planes_only.rmse_t_mm);
  EXPECT_LE(weighted.rmse_r_deg, planes_only.rmse_r_deg);
  for (const TrialStats* stats : {&planes_only, &weighted}) {
    EXPECT_GE(stats->chi2_fraction, 0.90);
    EXPECT_LE(stats->chi2_fraction, 0.99);
    EXPECT_GT(stats->mean_chi2, 6.0 - 3.0 * std::sqrt(12.0 / kTrials));
    EXPECT_LT(stats->mean_chi2, 6.0 + 3.0 * std::sqrt(12.0 / kTrials));
  }
}

INSTANTIATE_TEST_SUITE_P(RangeNoise, AccuracyBound, ::testing::Values(0.008, 0.020),
                         [](const auto& info) {
                           return std::to_string(static_cast<int>(info.param * 1000)) + "mm";
                         });

}  // namespace
}  // namespace calibench

namespace calibench {
namespace {

double NormalisedPlaneError(const Plane& estimate, const Plane& truth, const Mat4& covariance) {
  const Vec4 e = estimate.Coefficients() - truth.Coefficients();
  Eigen::JacobiSVD<Mat4> svd(covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Vec4 inverse = Vec4::Zero();
  for (int k = 0; k < 3; ++k) inverse(k) = 1.0 / svd.singularValues()(k);
  return e.dot(svd.matrixV() * inverse.asDiagonal() * svd.matrixU().transpose() * e);
}

// Each side's plane covariance describes its actual error (mean normalised error ≈ 3, χ²(3)):
// the weighted solver's calibration rests on this.
TEST(AccuracyBound, FeatureCovariancesMatchTheirErrors) {
  for (double noise_m : {0.008, 0.020}) {
    const SimOptions options = A3Hdl64(noise_m, 99);
    SimOptions small = options;
    small.num_pairs = 20;
    const auto dir = test::TempDir("feature_covariance_" + std::to_string(int(noise_m * 1e3)));
    const Dataset dataset = SimulateDataset(small, dir);
    const std::vector<SimPairTruth> truth = SimulatePairTruth(small);
    const Pose cam_from_lidar = *dataset.cam_from_lidar_ground_truth;
    double lidar_sum = 0, camera_sum = 0, lidar_d_bias = 0;
    std::vector<double> lidar_chi2, camera_chi2;
    int count = 0;
    for (size_t k = 0; k < dataset.pairs.size(); ++k) {
      const PairFeatures f = ExtractPairFeatures(dataset, dataset.pairs[k], PipelineOptions{});
      if (f.status == PairStatus::kFailed) continue;
      const Pose& pose = truth[k].cam_from_board;
      const Plane camera_truth = OrientTowardsOrigin(
          Plane{pose.linear().col(2), -pose.linear().col(2).dot(pose.translation())});
      const Plane lidar_truth =
          OrientTowardsOrigin(TransformPlane(cam_from_lidar.inverse(), camera_truth));
      lidar_chi2.push_back(NormalisedPlaneError(f.lidar->plane, lidar_truth, f.lidar->covariance));
      camera_chi2.push_back(
          NormalisedPlaneError(f.camera->plane, camera_truth, f.camera->plane_covariance));
      lidar_sum += lidar_chi2.back();
      camera_sum += camera_chi2.back();
      lidar_d_bias += f.lidar->plane.distance - lidar_truth.distance;
      if (std::getenv("CALIBENCH_VERBOSE"))
        std::printf(
            "pair %zu z %.2f m: cam sigma %.3f px, normal err %.3f deg, d err %.2f mm "
            "(std %.2f), cam chi2 %.1f | lidar d err %.2f mm (std %.2f) chi2 %.1f\n",
            k, pose.translation().z(), f.camera->corner_sigma_px,
            std::acos(std::min(1.0, f.camera->plane.normal.dot(camera_truth.normal))) * 180 / M_PI,
            (f.camera->plane.distance - camera_truth.distance) * 1e3,
            std::sqrt(f.camera->plane_covariance(3, 3)) * 1e3,
            NormalisedPlaneError(f.camera->plane, camera_truth, f.camera->plane_covariance),
            (f.lidar->plane.distance - lidar_truth.distance) * 1e3,
            std::sqrt(f.lidar->covariance(3, 3)) * 1e3,
            NormalisedPlaneError(f.lidar->plane, lidar_truth, f.lidar->covariance));
      ++count;
    }
    std::printf(
        "range noise %.0f mm, %d pairs: mean normalised error LiDAR %.2f, camera %.2f "
        "(expect 3); mean LiDAR d error %.2f mm\n",
        noise_m * 1e3, count, lidar_sum / count, camera_sum / count, lidar_d_bias / count * 1e3);
    auto median = [](std::vector<double> v) {
      std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
      return v[v.size() / 2];
    };
    // The median of χ²(3) is 2.37. Means are dominated by a few pairs (a planar-PnP flip, far
    // boards hit by two rings) that the solver's outlier gate handles; see docs/results.md.
    std::printf("  medians: LiDAR %.2f, camera %.2f (χ²(3) median 2.37)\n", median(lidar_chi2),
                median(camera_chi2));
    EXPECT_GT(median(lidar_chi2), 1.0);
    EXPECT_LT(median(lidar_chi2), 5.0);
    EXPECT_GT(median(camera_chi2), 1.0);
    EXPECT_LT(median(camera_chi2), 5.0);
  }
}

}  // namespace
}  // namespace calibench
