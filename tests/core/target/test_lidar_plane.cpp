#include <gtest/gtest.h>

#include <numeric>
#include <random>

#include "core/target/lidar_plane.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

// A 0.42 x 0.3 m board 3 m ahead, tilted, sampled on rings, plus clutter behind it.
LidarCloud BoardCloud(double noise_m, std::uint64_t seed, Plane* truth) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, noise_m);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const Vec3 centre(3.0, 0.2, -0.1);
  const Mat3 board_axes = ExpSO3(Vec3(0.2, -0.4, 0.3));
  const Vec3 u = board_axes.col(1), v = board_axes.col(2);
  *truth = OrientTowardsOrigin(Plane{board_axes.col(0), -board_axes.col(0).dot(centre)});
  LidarCloud cloud;
  for (int i = 0; i < 400; ++i) {
    const Vec3 p = centre + 0.21 * uniform(rng) * u + 0.15 * uniform(rng) * v;
    const Vec3 ray = p.normalized();
    cloud.points.push_back((p + normal(rng) * ray).cast<float>());  // noise along the ray
  }
  for (int i = 0; i < 150; ++i)  // a wall 2 m behind the board
    cloud.points.push_back(
        Eigen::Vector3f(5.0f, 0.2f + 0.3f * uniform(rng), -0.1f + 0.3f * uniform(rng)));
  return cloud;
}

TEST(LidarPlane, RansacAndRefitRecoverTheBoardPlane) {
  Plane truth;
  const LidarCloud cloud = BoardCloud(0.005, 1, &truth);
  const auto region = SelectSeedRegion(cloud, LidarSeed{Vec3(3.0, 0.2, -0.1), 0.5});
  std::string why;
  const auto fit = FitBoardPlane(cloud, region, LidarPlaneOptions{}, &why);
  ASSERT_TRUE(fit) << why;
  EXPECT_GT(fit->plane.distance, 0.0);  // oriented towards the LiDAR
  EXPECT_LT(std::acos(std::min(1.0, fit->plane.normal.dot(truth.normal))), 0.02);
  EXPECT_NEAR(fit->plane.distance, truth.distance, 0.003);
  EXPECT_NEAR(fit->rms_m, 0.005, 0.0025);
  EXPECT_GE(fit->inliers.size(), 380u);
  EXPECT_LE(fit->inliers.size(), 400u);  // no wall point
}

TEST(LidarPlane, CovarianceMatchesTheScatterOfRepeatedFits) {
  Plane truth;
  std::vector<Vec4> errors;
  Mat4 mean_cov = Mat4::Zero();
  const int trials = 200;
  for (int t = 0; t < trials; ++t) {
    const LidarCloud cloud = BoardCloud(0.01, 100 + t, &truth);
    std::vector<int> board(400);
    std::iota(board.begin(), board.end(), 0);
    const auto fit = FitPlaneLeastSquares(cloud, board);
    ASSERT_TRUE(fit);
    errors.push_back(fit->plane.Coefficients() - truth.Coefficients());
    mean_cov += fit->covariance / trials;
  }
  Vec4 mean = Vec4::Zero();
  for (const Vec4& e : errors) mean += e / trials;
  Mat4 empirical = Mat4::Zero();
  for (const Vec4& e : errors) empirical += (e - mean) * (e - mean).transpose() / (trials - 1);
  // Compare the distance variance and the normal variance (trace) within 25 %.
  EXPECT_NEAR(empirical(3, 3) / mean_cov(3, 3), 1.0, 0.25);
  const double normal_ratio =
      empirical.topLeftCorner<3, 3>().trace() / mean_cov.topLeftCorner<3, 3>().trace();
  EXPECT_NEAR(normal_ratio, 1.0, 0.25);
}

TEST(LidarPlane, SameSeedSamePlane) {
  Plane truth;
  const LidarCloud cloud = BoardCloud(0.01, 3, &truth);
  const auto region = SelectSeedRegion(cloud, LidarSeed{Vec3(3.0, 0.2, -0.1), 0.5});
  std::string why;
  const auto a = FitBoardPlane(cloud, region, LidarPlaneOptions{}, &why);
  const auto b = FitBoardPlane(cloud, region, LidarPlaneOptions{}, &why);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->plane.Coefficients(), b->plane.Coefficients());
  EXPECT_EQ(a->inliers, b->inliers);
}

TEST(LidarPlane, EmptyOrDegenerateRegionsFailWithAReason) {
  Plane truth;
  const LidarCloud cloud = BoardCloud(0.005, 4, &truth);
  std::string why;
  EXPECT_FALSE(FitBoardPlane(cloud, SelectSeedRegion(cloud, LidarSeed{Vec3(0, 10, 0), 0.3}),
                             LidarPlaneOptions{}, &why));
  EXPECT_NE(why.find("holds no points"), std::string::npos) << why;
  // Points on a single line (one ring crossing the board) define no plane.
  LidarCloud line;
  for (int i = 0; i < 50; ++i) line.points.push_back(Eigen::Vector3f(3.0f, 0.01f * i, 0.0f));
  std::vector<int> all(50);
  std::iota(all.begin(), all.end(), 0);
  EXPECT_FALSE(FitBoardPlane(line, all, LidarPlaneOptions{}, &why));
  EXPECT_FALSE(why.empty());
}

TEST(LidarPlane, BrushSelectsThePointsUnderThePixels) {
  LidarImage image;
  image.rows = 2;
  image.columns = 3;
  image.point_index = {5, -1, 7, 7, 2, -1};
  EXPECT_EQ(SelectBrushRegion(image, {0, 1, 2, 3, 4, 99}), (std::vector<int>{2, 5, 7}));
}

TEST(LidarPlane, OptionsCheck) {
  LidarPlaneOptions options;
  std::string why;
  EXPECT_TRUE(options.Check(&why));
  options.ransac_threshold_m = 0;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("ransac_threshold_m"), std::string::npos);
}

}  // namespace
}  // namespace calibench

namespace calibench {
namespace {

// A steeply tilted board far away with heavy range noise: the regime where noise along the rays
// biases a total-least-squares plane (points spread along the rays, not along the normal).
// origin_spread_m > 0: each ray starts at its own viewpoint, uniform in a cube of that half-size
// around (0, 0.3, 0.2) m (a swept scanner's mirror off the axis), kept in the cloud.
LidarCloud TiltedBoardCloud(double noise_m, std::uint64_t seed, Plane* truth,
                            double origin_spread_m = 0.0) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, noise_m);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const Vec3 centre(5.0, 0.5, 0.0);
  // Board normal 60° away from the ray to its centre.
  const Mat3 board_axes = ExpSO3(Vec3(0.0, 0.0, 60.0 * M_PI / 180.0));
  const Vec3 u = board_axes.col(1), v = board_axes.col(2);
  *truth = OrientTowardsOrigin(Plane{board_axes.col(0), -board_axes.col(0).dot(centre)});
  LidarCloud cloud;
  for (int i = 0; i < 300; ++i) {
    const Vec3 p = centre + 0.21 * uniform(rng) * u + 0.15 * uniform(rng) * v;
    if (origin_spread_m > 0) {
      const Vec3 origin =
          Vec3(0.0, 0.3, 0.2) + origin_spread_m * Vec3(uniform(rng), uniform(rng), uniform(rng));
      cloud.points.push_back((p + normal(rng) * (p - origin).normalized()).cast<float>());
      cloud.viewpoint.push_back(origin.cast<float>());
    } else {
      cloud.points.push_back((p + normal(rng) * p.normalized()).cast<float>());
    }
  }
  return cloud;
}

struct FitStats {
  Vec4 mean_error = Vec4::Zero();
  Vec4 rms_error = Vec4::Zero();
  double mean_normalised = 0.0;  // mean of eᵀ Σ⁺ e over trials (3 dof: expect ~3)
};

template <typename FitFn>
FitStats RepeatFits(int trials, double noise_m, FitFn fit_fn, double origin_spread_m = 0.0) {
  FitStats stats;
  for (int t = 0; t < trials; ++t) {
    Plane truth;
    const LidarCloud cloud = TiltedBoardCloud(noise_m, 500 + t, &truth, origin_spread_m);
    std::vector<int> all(cloud.size());
    std::iota(all.begin(), all.end(), 0);
    const std::optional<LidarPlaneFit> fit = fit_fn(cloud, all);
    EXPECT_TRUE(fit);
    if (!fit) continue;
    const Vec4 e = fit->plane.Coefficients() - truth.Coefficients();
    stats.mean_error += e / trials;
    stats.rms_error += e.cwiseAbs2() / trials;
    Eigen::JacobiSVD<Mat4> svd(fit->covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Vec4 inv_s = Vec4::Zero();
    for (int k = 0; k < 3; ++k) inv_s(k) = 1.0 / svd.singularValues()(k);
    const Mat4 pinv = svd.matrixV() * inv_s.asDiagonal() * svd.matrixU().transpose();
    stats.mean_normalised += e.dot(pinv * e) / trials;
  }
  stats.rms_error = stats.rms_error.cwiseSqrt();
  return stats;
}

TEST(LidarPlane, RangeMaximumLikelihoodRemovesTheTiltBiasOfLeastSquares) {
  const int trials = 300;
  const double noise_m = 0.03;
  const FitStats tls = RepeatFits(trials, noise_m, [](const LidarCloud& c, const auto& idx) {
    return FitPlaneLeastSquares(c, idx);
  });
  const FitStats ml = RepeatFits(trials, noise_m, [](const LidarCloud& c, const auto& idx) {
    auto start = FitPlaneLeastSquares(c, idx);
    return start ? FitPlaneRangeMl(c, idx, start->plane) : std::nullopt;
  });
  // Bias relative to the per-fit scatter: the mean over `trials` fits has std rms/sqrt(trials).
  const double standard_error_d = ml.rms_error(3) / std::sqrt(trials);
  std::printf("d bias: TLS %.2f mm, ML %.2f mm (standard error %.2f mm); rms TLS %.2f, ML %.2f\n",
              tls.mean_error(3) * 1e3, ml.mean_error(3) * 1e3, standard_error_d * 1e3,
              tls.rms_error(3) * 1e3, ml.rms_error(3) * 1e3);
  std::printf("normal bias: TLS %.4f, ML %.4f; normalised error TLS %.2f ML %.2f (3 dof)\n",
              tls.mean_error.head<3>().norm(), ml.mean_error.head<3>().norm(), tls.mean_normalised,
              ml.mean_normalised);
  EXPECT_LT(std::abs(ml.mean_error(3)), 3.0 * standard_error_d);
  EXPECT_GT(std::abs(tls.mean_error(3)), 5.0 * std::abs(ml.mean_error(3)));
  // The ML covariance describes its scatter: mean normalised error ≈ 3 (χ²(3)).
  EXPECT_NEAR(ml.mean_normalised, 3.0, 0.6);
}

// Rays that start at each return's own viewpoint (a swept scanner's mirror, the cloud's vp_x,
// vp_y, vp_z): the fit along those rays is unbiased and its covariance describes its scatter, as
// from one origin; its range RMS is the noise along them.
TEST(LidarPlane, RangeMaximumLikelihoodAlongEachReturnsOwnRay) {
  const int trials = 300;
  const double noise_m = 0.03;
  double rms_sum = 0.0;
  const FitStats ml = RepeatFits(
      trials, noise_m,
      [&](const LidarCloud& c, const auto& idx) {
        auto start = FitPlaneLeastSquares(c, idx);
        auto fit = start ? FitPlaneRangeMl(c, idx, start->plane) : std::nullopt;
        if (fit) rms_sum += fit->rms_m;
        return fit;
      },
      /*origin_spread_m=*/0.1);
  const FitStats tls = RepeatFits(
      trials, noise_m,
      [](const LidarCloud& c, const auto& idx) { return FitPlaneLeastSquares(c, idx); }, 0.1);
  const double standard_error_d = ml.rms_error(3) / std::sqrt(trials);
  std::printf(
      "own rays: d bias ML %.2f mm (standard error %.2f), TLS %.2f mm; normalised %.2f; "
      "range rms %.1f mm\n",
      ml.mean_error(3) * 1e3, standard_error_d * 1e3, tls.mean_error(3) * 1e3, ml.mean_normalised,
      rms_sum / trials * 1e3);
  EXPECT_LT(std::abs(ml.mean_error(3)), 3.0 * standard_error_d);
  EXPECT_GT(std::abs(tls.mean_error(3)), 5.0 * std::abs(ml.mean_error(3)));
  EXPECT_NEAR(ml.mean_normalised, 3.0, 0.6);
  EXPECT_NEAR(rms_sum / trials, noise_m, 0.05 * noise_m);
}

}  // namespace
}  // namespace calibench
