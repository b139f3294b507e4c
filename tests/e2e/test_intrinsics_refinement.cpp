// Issue "Camera intrinsics from the same recording", item 3: `calibrate --refine-intrinsics`
// (the joint problem of corners, LiDAR planes and edges) removes a 2 % focal-length error, and
// without refinement the camera file's intrinsics covariance is carried into the extrinsic's σ,
// which then covers the true error (χ² over 20 seeds).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <vector>

#include "core/io/dataset.h"
#include "core/lidar_camera/joint_intrinsics.h"
#include "core/lidar_camera/pipeline.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

namespace fs = std::filesystem;
constexpr double kChi2Dof6Quantile95 = 12.592;

// A VLP-16 and the 1440x1080 pinhole simulator camera, boards at 1.5-4 m, 1 cm range noise.
SimOptions Scene(int pairs, std::uint64_t seed) {
  SimOptions options = SimPreset("default");
  options.num_pairs = pairs;
  options.lidar_range_noise_m = 0.01;
  options.image_noise = 0.01;
  options.seed = seed;
  return options;
}

// The pairs of a simulated dataset, extracted with the true camera.
std::vector<PairFeatures> Extract(const Dataset& dataset) {
  std::vector<PairFeatures> features;
  PipelineOptions options;
  options.threads = 2;
  for (const PairEntry& pair : dataset.pairs) {
    PairFeatures f = ExtractPairFeatures(dataset, pair, options);
    if (f.status != PairStatus::kFailed) features.push_back(std::move(f));
  }
  return features;
}

// The extrinsic's error as the solver's right perturbation: truth = estimate · Exp(ξ).
Vec6 ErrorOf(const Pose& estimate, const Pose& truth) { return LogSE3(estimate.inverse() * truth); }

TEST(RefineIntrinsics, RemovesATwoPercentFocalLengthError) {
  double squared_true = 0.0, squared_wrong = 0.0, squared_refined = 0.0;
  constexpr int kSeeds = 6;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    const Dataset dataset =
        SimulateDataset(Scene(20, seed), test::TempDir("refine_focal_" + std::to_string(seed)));
    const Pose truth = *dataset.cam_from_lidar_ground_truth;
    const std::vector<PairFeatures> features = Extract(dataset);
    PipelineOptions options;
    options.threads = 2;
    const CalibrationOutcome with_truth = SolveFromFeatures(features, options);
    ASSERT_TRUE(with_truth.solution) << with_truth.failure;

    // The camera file's focal length 2 % long: every board looks 2 % farther.
    CameraModel wrong = dataset.camera;
    wrong.fx *= 1.02, wrong.fy *= 1.02;
    std::vector<PairFeatures> posed_wrong = features;
    PoseCornersAgain(wrong, options.pnp, &posed_wrong);
    CalibrationOutcome outcome = SolveFromFeatures(posed_wrong, options);
    ASSERT_TRUE(outcome.solution) << outcome.failure;
    const double error_wrong = ErrorOf(outcome.solution->cam_from_lidar, truth).head<3>().norm();

    options.refine_intrinsics = true;
    RefineIntrinsics(wrong, options, &outcome);
    ASSERT_TRUE(outcome.intrinsics_refinement);
    const IntrinsicsRefinement& r = *outcome.intrinsics_refinement;
    ASSERT_TRUE(r.failure.empty()) << r.failure;
    EXPECT_TRUE(r.converged);
    // From the truth the joint problem finds the same minimum: it is the data's, not the start's.
    CalibrationOutcome from_truth = with_truth;
    RefineIntrinsics(dataset.camera, options, &from_truth);
    ASSERT_TRUE(from_truth.intrinsics_refinement && from_truth.solution);
    EXPECT_NEAR(r.after.fx, from_truth.intrinsics_refinement->after.fx, 1e-3);
    EXPECT_LT(ErrorOf(outcome.solution->cam_from_lidar, from_truth.solution->cam_from_lidar)
                  .head<3>()
                  .norm(),
              1e-5);

    const double sigma_fx = std::sqrt(r.after.covariance[0]);
    const double error_true = ErrorOf(with_truth.solution->cam_from_lidar, truth).head<3>().norm();
    const double error_refined = ErrorOf(outcome.solution->cam_from_lidar, truth).head<3>().norm();
    std::printf(
        "seed %d: fx 1020 -> %.2f +- %.2f (truth 1000), fy %.2f; translation error [mm] true "
        "intrinsics %.2f, 2%% wrong %.1f, refined %.2f\n",
        seed, r.after.fx, sigma_fx, r.after.fy, 1e3 * error_true, 1e3 * error_wrong,
        1e3 * error_refined);
    // The focal length back within 0.3 % of the truth and within 4 of its σ.
    EXPECT_NEAR(r.after.fx, dataset.camera.fx, 0.003 * dataset.camera.fx);
    EXPECT_NEAR(r.after.fy, dataset.camera.fy, 0.003 * dataset.camera.fy);
    EXPECT_LT(std::abs(r.after.fx - dataset.camera.fx), 4 * sigma_fx);
    // Only the focal length moves by default.
    EXPECT_EQ(r.after.cx, wrong.cx);
    EXPECT_EQ(r.after.distortion, wrong.distortion);
    EXPECT_GT(error_wrong, 0.02);  // the wrong focal length costs centimetres
    squared_true += error_true * error_true;
    squared_wrong += error_wrong * error_wrong;
    squared_refined += error_refined * error_refined;
  }
  const double rms_true = std::sqrt(squared_true / kSeeds);
  const double rms_refined = std::sqrt(squared_refined / kSeeds);
  std::printf("RMS translation error over %d seeds [mm]: true %.2f, 2%% wrong %.1f, refined %.2f\n",
              kSeeds, 1e3 * rms_true, 1e3 * std::sqrt(squared_wrong / kSeeds), 1e3 * rms_refined);
  EXPECT_LE(rms_refined, 1.5 * rms_true);
}

// A camera file's covariance, as a good calibration gives it: focal 0.3 % (fx, fy correlated),
// principal point 2 px, distortion to a few 1e-3; k3 held at 0.
std::vector<double> CameraFileCovariance() {
  const std::vector<double> sigma = {3.0, 3.0, 2.0, 2.0, 0.002, 0.004, 0.0003, 0.0003, 0.0};
  std::vector<double> covariance(81, 0.0);
  for (int i = 0; i < 9; ++i) covariance[i * 9 + i] = sigma[i] * sigma[i];
  covariance[1] = covariance[9] = 0.9 * sigma[0] * sigma[1];
  return covariance;
}

TEST(IntrinsicsCovariance, PropagatedSigmaCoversTheTrueError) {
  const std::vector<double> covariance = CameraFileCovariance();
  Eigen::Matrix<double, 9, 9> sigma;
  for (int i = 0; i < 81; ++i) sigma(i / 9, i % 9) = covariance[i];
  const Eigen::Matrix<double, 8, 8> estimated = sigma.topLeftCorner<8, 8>();  // k3 held
  const Eigen::LLT<Eigen::Matrix<double, 8, 8>> llt(estimated);
  ASSERT_EQ(llt.info(), Eigen::Success);
  constexpr int kSeeds = 20;
  int covered = 0, covered_without = 0;
  double sum_chi2 = 0.0;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    const Dataset dataset =
        SimulateDataset(Scene(10, 100 + seed), test::TempDir("intrinsics_sigma"));
    const Pose truth = *dataset.cam_from_lidar_ground_truth;
    std::vector<PairFeatures> features = Extract(dataset);
    // The camera file: the truth moved by a draw from its own covariance.
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> normal;
    Eigen::Matrix<double, 8, 1> z;
    for (int i = 0; i < 8; ++i) z[i] = normal(rng);
    const Eigen::Matrix<double, 8, 1> draw = llt.matrixL() * z;
    CameraModel file = dataset.camera;
    std::vector<double> k = IntrinsicParameters(file);
    for (int i = 0; i < 8; ++i) k[i] += draw[i];
    SetIntrinsicParameters(k, &file);
    file.covariance = covariance;
    PipelineOptions options;
    options.threads = 2;
    PoseCornersAgain(file, options.pnp, &features);
    CalibrationOutcome outcome = SolveFromFeatures(features, options);
    ASSERT_TRUE(outcome.solution) << outcome.failure;
    const Mat6 without = outcome.solution->covariance;
    AddIntrinsicsUncertainty(outcome.pairs, file, options, &*outcome.solution);
    const SolverResult& s = *outcome.solution;
    ASSERT_FALSE(s.intrinsics_covariance.isZero(0.0));
    EXPECT_TRUE((s.covariance - without - s.intrinsics_covariance).isZero(1e-15));
    const Vec6 e = ErrorOf(s.cam_from_lidar, truth);
    const double chi2 = e.dot(s.covariance.ldlt().solve(e));
    const double chi2_without = e.dot(without.ldlt().solve(e));
    std::printf("seed %d: error %.2f mm %.3f deg, chi2 %.2f (without the intrinsics' %.1f)\n", seed,
                1e3 * e.head<3>().norm(), e.tail<3>().norm() * 180 / M_PI, chi2, chi2_without);
    covered += chi2 <= kChi2Dof6Quantile95;
    covered_without += chi2_without <= kChi2Dof6Quantile95;
    sum_chi2 += chi2;
  }
  std::printf(
      "95%% ellipsoid covers %d of %d (without the intrinsics' covariance %d); mean chi2 "
      "%.2f (6 expected)\n",
      covered, kSeeds, covered_without, sum_chi2 / kSeeds);
  // Honest: about 19 of 20 inside the 95 % ellipsoid (≥ 17 holds with 98 % probability), and not
  // so wide that the σ means little (mean χ² ≥ 2 of the expected 6).
  EXPECT_GE(covered, 17);
  EXPECT_GE(sum_chi2 / kSeeds, 2.0);
  // Without it the σ claims far more than the camera file knows.
  EXPECT_LE(covered_without, 12);
}

// The command a user runs: a dataset whose camera.yaml has the focal length 2 % long.
TEST(RefineIntrinsicsCli, CalibrateRefinesAndSaysSo) {
  const fs::path dir = test::TempDir("refine_cli");
  const Dataset dataset = SimulateDataset(Scene(16, 7), dir / "set");
  nlohmann::json manifest;
  std::ifstream(dataset.manifest) >> manifest;
  manifest["camera"]["fx"] = 1.02 * dataset.camera.fx;
  manifest["camera"]["fy"] = 1.02 * dataset.camera.fy;
  const fs::path wrong = dir / "set/wrong.json";
  std::ofstream(wrong) << manifest.dump(1);
  const std::string exe = test::CalibenchExe();
  std::string output;
  ASSERT_EQ(test::RunCommand(exe + " calibrate --dataset " + wrong.string() +
                                 " --refine-intrinsics --out " + (dir / "r.json").string(),
                             &output),
            0)
      << output;
  EXPECT_NE(output.find("intrinsics refined with the extrinsic"), std::string::npos) << output;
  nlohmann::json result;
  std::ifstream(dir / "r.json") >> result;
  ASSERT_TRUE(result.contains("intrinsics")) << result.dump(1);
  const nlohmann::json& in = result["intrinsics"];
  EXPECT_TRUE(in["refined"].get<bool>());
  EXPECT_DOUBLE_EQ(in["before"]["fx"].get<double>(), 1.02 * dataset.camera.fx);
  EXPECT_NEAR(in["after"]["fx"].get<double>(), dataset.camera.fx, 0.003 * dataset.camera.fx);
  EXPECT_GT(in["sigmas"]["fx"].get<double>(), 0.0);
  EXPECT_EQ(in["held"].size(), 7u);  // cx cy k1 k2 p1 p2 k3
  ASSERT_TRUE(result.contains("covariance_from_intrinsics"));
  const auto& m = result["cam_from_lidar"]["matrix"];
  Mat4 estimate;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) estimate(r, c) = m[r][c].get<double>();
  EXPECT_LT(
      (estimate.topRightCorner<3, 1>() - dataset.cam_from_lidar_ground_truth->translation()).norm(),
      0.005);

  // The camera with a covariance (as `calibench intrinsics` writes it): the σ carries it, and
  // says so; --ignore-intrinsics-covariance leaves it out.
  manifest["camera"]["fx"] = dataset.camera.fx;
  manifest["camera"]["fy"] = dataset.camera.fy;
  manifest["camera"]["intrinsics_covariance"] = CameraFileCovariance();
  const fs::path with_covariance = dir / "set/with_covariance.json";
  std::ofstream(with_covariance) << manifest.dump(1);
  ASSERT_EQ(test::RunCommand(exe + " calibrate --dataset " + with_covariance.string() + " --out " +
                                 (dir / "c.json").string(),
                             &output),
            0)
      << output;
  EXPECT_NE(output.find("the intrinsics' covariance is in the std above"), std::string::npos)
      << output;
  nlohmann::json carried;
  std::ifstream(dir / "c.json") >> carried;
  ASSERT_TRUE(carried.contains("covariance_from_intrinsics"));
  EXPECT_GT(carried["covariance_from_intrinsics"]["covariance_6x6"][5][5].get<double>(), 0.0);
  ASSERT_EQ(
      test::RunCommand(exe + " calibrate --dataset " + with_covariance.string() +
                           " --ignore-intrinsics-covariance --out " + (dir / "n.json").string(),
                       &output),
      0)
      << output;
  nlohmann::json ignored;
  std::ifstream(dir / "n.json") >> ignored;
  EXPECT_FALSE(ignored.contains("covariance_from_intrinsics"));
  EXPECT_LT(ignored["covariance_6x6"][5][5].get<double>(),
            carried["covariance_6x6"][5][5].get<double>());

  // A value it does not know is refused, naming the choices.
  EXPECT_NE(test::RunCommand(
                exe + " calibrate --dataset " + wrong.string() + " --refine-intrinsics=everything",
                &output),
            0);
  EXPECT_NE(output.find("focal, pinhole or all"), std::string::npos) << output;
}

}  // namespace
}  // namespace calibench
