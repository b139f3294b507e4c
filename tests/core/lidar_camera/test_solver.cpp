#include <gtest/gtest.h>

#include <random>

#include "core/lidar_camera/solver.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

Pose GroundTruth() {
  // LiDAR x forward / z up, camera z forward / y down, with an offset.
  Mat3 axes;
  axes << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  Pose cam_from_lidar = Pose::Identity();
  cam_from_lidar.linear() = ExpSO3(Vec3(0.02, -0.03, 0.01)) * axes;
  cam_from_lidar.translation() = Vec3(0.05, -0.12, 0.08);
  return cam_from_lidar;
}

// Board planes in front of the camera with normals tilted up to max_tilt around the view axis.
std::vector<PlanePair> MakePairs(int n, double max_tilt_rad, double noise_normal, double noise_d,
                                 std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  const Pose cam_from_lidar = GroundTruth();
  std::vector<PlanePair> pairs;
  for (int i = 0; i < n; ++i) {
    const Vec3 tilt_axis = Vec3(uniform(rng), uniform(rng), 0).normalized();
    const Vec3 n_cam = ExpSO3(tilt_axis * max_tilt_rad * std::abs(uniform(rng))) * Vec3(0, 0, -1);
    const Plane camera_plane{n_cam, 1.5 + 2.0 * std::abs(uniform(rng))};
    Plane lidar_plane = TransformPlane(cam_from_lidar.inverse(), camera_plane);
    lidar_plane.normal =
        (lidar_plane.normal + noise_normal * Vec3(normal(rng), normal(rng), normal(rng)))
            .normalized();
    lidar_plane.distance += noise_d * normal(rng);
    pairs.push_back({std::to_string(i), lidar_plane, camera_plane});
  }
  return pairs;
}

TEST(Solver, InitialGuessIsExactOnNoiseFreePlanes) {
  const auto pairs = MakePairs(5, 0.6, 0, 0, 1);
  std::string why;
  const auto guess = InitialGuessFromPlanes(pairs, &why);
  ASSERT_TRUE(guess) << why;
  EXPECT_TRUE(test::MatrixNear(guess->matrix(), GroundTruth().matrix(), 1e-9));
}

TEST(Solver, GaussNewtonConvergesFromTheIdentityToTheTruth) {
  const auto pairs = MakePairs(3, 0.6, 0, 0, 2);
  PlaneAlignmentSolver solver(pairs, SolverOptions{}, Pose::Identity());
  const SolverResult result = solver.Run();
  EXPECT_TRUE(result.converged);
  EXPECT_LT(RotationAngle(result.cam_from_lidar.linear(), GroundTruth().linear()), 1e-8);
  EXPECT_LT((result.cam_from_lidar.translation() - GroundTruth().translation()).norm(), 1e-8);
  EXPECT_TRUE(result.observability.well_constrained);
  ASSERT_GE(result.cost_history.size(), 2u);
  for (size_t i = 1; i < result.cost_history.size(); ++i)
    EXPECT_LE(result.cost_history[i], result.cost_history[i - 1] + 1e-15);
}

TEST(Solver, StepsOneIterationAtATimeAndReportsEachOne) {
  const auto pairs = MakePairs(6, 0.5, 0, 0, 3);
  std::string why;
  PlaneAlignmentSolver solver(pairs, SolverOptions{},
                              *InitialGuessFromPlanes(pairs, &why) * ExpSE3(Vec6::Constant(0.05)));
  int reports = 0;
  solver.Run([&](const IterationReport& it) {
    EXPECT_EQ(it.iteration, static_cast<int>(solver.History().size()) - 1);
    ++reports;
  });
  EXPECT_GE(reports, 3);
  EXPECT_TRUE(solver.Done());
}

TEST(Solver, NoisyPlanesGiveSmallErrorAndAnHonestCovariance) {
  const auto pairs = MakePairs(20, 0.6, 0.002, 0.003, 4);
  std::string why;
  PlaneAlignmentSolver solver(pairs, SolverOptions{}, *InitialGuessFromPlanes(pairs, &why));
  const SolverResult result = solver.Run();
  const double t_err = (result.cam_from_lidar.translation() - GroundTruth().translation()).norm();
  EXPECT_LT(t_err, 0.01);
  EXPECT_LT(RotationAngle(result.cam_from_lidar.linear(), GroundTruth().linear()),
            0.2 * M_PI / 180);
  // The standard deviations are of the same order as the noise, not zero and not huge.
  const double sigma_t = std::sqrt(result.covariance.topLeftCorner<3, 3>().trace());
  EXPECT_GT(sigma_t, 1e-4);
  EXPECT_LT(sigma_t, 0.02);
}

TEST(Solver, HuberKernelDownWeightsAnOutlierPair) {
  auto pairs = MakePairs(12, 0.6, 0.0005, 0.001, 5);
  pairs[3].lidar_plane.distance += 0.5;  // a wrong plane
  std::string why;
  const Pose guess = *InitialGuessFromPlanes(pairs, &why);
  SolverOptions options;
  options.method = SolverMethod::kCa2libGn;  // the paper's Huber on |e|
  options.huber_delta = 0.02;
  const SolverResult robust = PlaneAlignmentSolver(pairs, options, guess).Run();
  options.huber_delta = 1e3;  // effectively least squares
  const SolverResult plain = PlaneAlignmentSolver(pairs, options, guess).Run();
  const double robust_err =
      (robust.cam_from_lidar.translation() - GroundTruth().translation()).norm();
  const double plain_err =
      (plain.cam_from_lidar.translation() - GroundTruth().translation()).norm();
  EXPECT_LT(robust_err, 0.5 * plain_err);
  EXPECT_LT(robust.robust_weights[3], 0.2);
  EXPECT_NEAR(robust.robust_weights[0], 1.0, 1e-12);
}

TEST(Solver, ParallelNormalsAreReportedNotGuessed) {
  auto pairs = MakePairs(5, 0.0, 0, 0, 6);  // every board faces the camera squarely
  std::string why;
  EXPECT_FALSE(InitialGuessFromPlanes(pairs, &why));
  EXPECT_NE(why.find("parallel"), std::string::npos);
  // From a user guess, the solver runs but says which directions the data cannot fix.
  const SolverResult result = PlaneAlignmentSolver(pairs, SolverOptions{}, GroundTruth()).Run();
  EXPECT_FALSE(result.observability.well_constrained);
  ASSERT_FALSE(result.observability.weak_directions.empty());
  bool names_translation = false;
  for (const auto& d : result.observability.weak_directions)
    names_translation |= d.find("translation along camera") != std::string::npos;
  EXPECT_TRUE(names_translation);
}

TEST(Solver, NearlyParallelNormalsAreWeak) {
  const auto pairs = MakePairs(6, 0.5 * M_PI / 180, 0, 0, 7);
  const SolverResult result = PlaneAlignmentSolver(pairs, SolverOptions{}, GroundTruth()).Run();
  EXPECT_FALSE(result.observability.well_constrained);
  const auto good = MakePairs(6, 0.5, 0, 0, 7);
  EXPECT_TRUE(PlaneAlignmentSolver(good, SolverOptions{}, GroundTruth())
                  .Run()
                  .observability.well_constrained);
}

TEST(Solver, OptionsCheckNamesTheBadField) {
  SolverOptions options;
  options.huber_delta = -1;
  std::string why;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("huber_delta"), std::string::npos);
}

}  // namespace
}  // namespace calibench

namespace calibench {
namespace {

// A plane perturbed by Gaussian noise of the given tangent-normal and distance sigmas, with the
// matching (n, d) covariance.
void Perturb(Plane* plane, Mat4* covariance, double sigma_n, double sigma_d, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  const Vec3 u = plane->normal.unitOrthogonal(), v = plane->normal.cross(u);
  plane->normal = (plane->normal + sigma_n * (normal(rng) * u + normal(rng) * v)).normalized();
  plane->distance += sigma_d * normal(rng);
  covariance->setZero();
  covariance->topLeftCorner<3, 3>() = sigma_n * sigma_n * (u * u.transpose() + v * v.transpose());
  (*covariance)(3, 3) = sigma_d * sigma_d;
}

// Pairs whose LiDAR planes are noisy to very different degrees (near, well-sampled boards and
// far ones seen by two rings), with the camera planes nearly exact.
std::vector<PlanePair> HeteroscedasticPairs(int n, std::uint64_t seed) {
  auto pairs = MakePairs(n, 0.6, 0, 0, seed);
  std::mt19937_64 rng(seed + 1000);
  for (size_t i = 0; i < pairs.size(); ++i) {
    const double scale = i % 3 == 0 ? 10.0 : 1.0;
    Perturb(&pairs[i].lidar_plane, &pairs[i].lidar_covariance, 0.002 * scale, 0.003 * scale, rng);
    Perturb(&pairs[i].camera_plane, &pairs[i].camera_covariance, 0.0005, 0.001, rng);
  }
  return pairs;
}

TEST(WeightedSolver, RecoversNoiseFreePlanesExactlyFromAPerturbedStart) {
  auto pairs = MakePairs(5, 0.6, 0, 0, 11);
  for (PlanePair& p : pairs) {
    p.lidar_covariance = Mat4::Identity() * 1e-6;
    p.camera_covariance = Mat4::Identity() * 1e-6;
  }
  SolverOptions options;
  options.method = SolverMethod::kWeightedMl;
  const Pose start =
      GroundTruth() * ExpSE3((Vec6() << 0.05, -0.04, 0.03, 0.03, -0.02, 0.04).finished());
  const SolverResult result = PlaneAlignmentSolver(pairs, options, start).Run();
  EXPECT_TRUE(result.converged);
  EXPECT_LT((result.cam_from_lidar.translation() - GroundTruth().translation()).norm(), 1e-8);
  EXPECT_LT(RotationAngle(result.cam_from_lidar.linear(), GroundTruth().linear()), 1e-8);
}

TEST(WeightedSolver, BeatsTheUnweightedSolverWhenNoiseDiffersBetweenPairs) {
  double weighted_sq = 0, plain_sq = 0, normalized_sum = 0;
  const int trials = 200;
  for (int trial = 0; trial < trials; ++trial) {
    const auto pairs = HeteroscedasticPairs(12, 100 + trial);
    std::string why;
    const Pose guess = *InitialGuessFromPlanes(pairs, &why);
    SolverOptions options;
    options.method = SolverMethod::kWeightedMl;
    options.whitened_huber_delta = 1e3;  // Gaussian data: plain weighted least squares
    const SolverResult weighted = PlaneAlignmentSolver(pairs, options, guess).Run();
    SolverOptions paper;
    paper.method = SolverMethod::kCa2libGn;
    const SolverResult plain = PlaneAlignmentSolver(pairs, paper, guess).Run();
    weighted_sq +=
        (weighted.cam_from_lidar.translation() - GroundTruth().translation()).squaredNorm();
    plain_sq += (plain.cam_from_lidar.translation() - GroundTruth().translation()).squaredNorm();
    // Normalised error of the weighted estimate against its own covariance (6 dof).
    const Vec6 error = LogSE3(GroundTruth().inverse() * weighted.cam_from_lidar);
    normalized_sum += error.dot(weighted.covariance.inverse() * error);
  }
  const double weighted_rmse = std::sqrt(weighted_sq / trials),
               plain_rmse = std::sqrt(plain_sq / trials);
  std::printf(
      "translation RMSE over %d trials: weighted %.2f mm, unweighted %.2f mm; mean "
      "normalised error %.2f (chi2(6): 6)\n",
      trials, weighted_rmse * 1e3, plain_rmse * 1e3, normalized_sum / trials);
  EXPECT_LT(weighted_rmse, 0.7 * plain_rmse);
  // The reported covariance matches the actual scatter: chi2(6) has mean 6.
  EXPECT_NEAR(normalized_sum / trials, 6.0, 1.5);
}

TEST(WeightedSolver, MethodNamesRoundTrip) {
  for (SolverMethod m : {SolverMethod::kCa2libGn, SolverMethod::kWeightedMl, SolverMethod::kKim})
    EXPECT_EQ(ParseSolverMethod(SolverMethodName(m)), m);
  EXPECT_FALSE(ParseSolverMethod("levenberg"));
  // The weighted estimator is the default (issue 5).
  EXPECT_EQ(SolverOptions{}.method, SolverMethod::kWeightedMl);
}

TEST(WeightedSolver, GatesAGrossOutlierAndKeepsTheOthers) {
  auto pairs = HeteroscedasticPairs(12, 7);
  pairs[4].lidar_plane.distance += 0.3;  // a wrong plane, far beyond its covariance
  std::string why;
  const Pose guess = *InitialGuessFromPlanes(pairs, &why);
  const SolverResult gated = PlaneAlignmentSolver(pairs, SolverOptions{}, guess).Run();
  EXPECT_EQ(gated.robust_weights[4], 0.0);
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (i == 4) continue;
    EXPECT_GT(gated.robust_weights[i], 0.0) << i;
  }
  SolverOptions no_gate;
  no_gate.outlier_gate = 0.0;
  const SolverResult huber_only = PlaneAlignmentSolver(pairs, no_gate, guess).Run();
  const double gated_err =
      (gated.cam_from_lidar.translation() - GroundTruth().translation()).norm();
  const double huber_err =
      (huber_only.cam_from_lidar.translation() - GroundTruth().translation()).norm();
  EXPECT_LT(gated_err, huber_err);
}

TEST(KimBaseline, IsTheClosedFormWithoutIterations) {
  const auto pairs = MakePairs(10, 0.6, 0.0005, 0.001, 9);
  std::string why;
  const Pose guess = *InitialGuessFromPlanes(pairs, &why);
  SolverOptions options;
  options.method = SolverMethod::kKim;
  PlaneAlignmentSolver solver(pairs, options, guess);
  const SolverResult result = solver.Run();
  EXPECT_EQ(result.iterations, 0);
  EXPECT_TRUE(test::MatrixNear(result.cam_from_lidar.matrix(), guess.matrix(), 0.0));
  EXPECT_GT(result.covariance.trace(), 0.0);
}

}  // namespace
}  // namespace calibench
