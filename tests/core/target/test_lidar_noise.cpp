// The LiDAR's noise learned from the boards' returns (core/target/lidar_noise.h): boards drawn
// with a known range noise and a known angular jitter, fitted along their rays, and the two terms
// recovered from the fits' residuals.
#include <gtest/gtest.h>

#include <numeric>
#include <random>

#include "core/estimation/fisher_information.h"
#include "core/geometry/geometry.h"
#include "core/guidance/next_pose.h"
#include "core/lidar/beam_table.h"
#include "core/lidar_camera/pipeline.h"
#include "core/target/lidar_noise.h"
#include "core/target/lidar_plane.h"
#include "tests/core/target/board_test_scenes.h"

namespace calibench {
namespace {

// An A3 sheet `range_m` ahead, turned `tilt_deg` away from facing the LiDAR, sampled by 600 rays;
// each ray is jittered by `angular_sigma_rad` per axis before it meets the sheet and its range
// gets `range_sigma_m` of noise, and the return is stored along the nominal ray, as a sensor does.
LidarCloud JitteredBoard(double range_m, double tilt_deg, double range_sigma_m,
                         double angular_sigma_rad, std::mt19937_64* rng, Plane* truth) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const Vec3 centre = range_m * Vec3(1.0, 0.1, -0.05).normalized();
  const Mat3 axes = ExpSO3(Vec3(0.0, 0.0, tilt_deg * kDegToRad)) *
                    ExpSO3(Vec3(0.3 * uniform(*rng), 0.0, 0.0));  // turned, then rolled
  const Vec3 normal_axis = axes.col(0), across = axes.col(1), up = axes.col(2);
  *truth = OrientTowardsOrigin(Plane{normal_axis, -normal_axis.dot(centre)});
  LidarCloud cloud;
  for (int i = 0; i < 600; ++i) {
    const Vec3 nominal =
        (centre + 0.21 * uniform(*rng) * across + 0.15 * uniform(*rng) * up).normalized();
    const Vec3 a = nominal.unitOrthogonal(), b = nominal.cross(a);
    const Vec3 cast =
        (nominal + angular_sigma_rad * (normal(*rng) * a + normal(*rng) * b)).normalized();
    const double hit = -truth->distance / truth->normal.dot(cast);
    cloud.points.push_back(((hit + range_sigma_m * normal(*rng)) * nominal).cast<float>());
  }
  return cloud;
}

// Twenty boards at 1.5-5 m turned 0-60°, each fitted along its rays; their moments estimated.
LidarNoiseEstimate LearnFromBoards(double range_sigma_m, double angular_sigma_rad,
                                   std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<RangeResidualMoments> moments;
  for (int k = 0; k < 20; ++k) {
    Plane truth;
    const LidarCloud cloud =
        JitteredBoard(1.5 + 3.5 * (k % 5) / 4.0, 15.0 * (k % 4) + 3.0 * (k / 5), range_sigma_m,
                      angular_sigma_rad, &rng, &truth);
    std::vector<int> all(cloud.size());
    std::iota(all.begin(), all.end(), 0);
    const auto fit = FitPlaneRangeMl(cloud, all, truth);
    EXPECT_TRUE(fit);
    if (!fit) continue;
    EXPECT_EQ(fit->range_moments.count, 600);
    moments.push_back(fit->range_moments);
  }
  return EstimateLidarNoise(moments);
}

TEST(LidarNoise, AnAngularJitterIsLearnedFromTheBoardsResiduals) {
  const double angular = 0.25 * kDegToRad;
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const LidarNoiseEstimate e = LearnFromBoards(0.008, angular, seed);
    EXPECT_EQ(e.boards, 20);
    EXPECT_EQ(e.returns, 12000);
    EXPECT_TRUE(e.angular_resolved) << seed;
    EXPECT_NEAR(e.angular_sigma_rad, angular, 0.15 * angular) << seed;
    EXPECT_GE(e.angular_sigma_upper_rad, e.angular_sigma_rad);
    EXPECT_NEAR(e.range_sigma_median_m, 0.008, 0.0012) << seed;
    // Boards turned 60° at 5 m: their returns' variances differ, equal weights lose a little.
    EXPECT_LT(e.equal_weight_efficiency_min, 1.0);
    EXPECT_GT(e.equal_weight_efficiency_min, 0.5);
    EXPECT_NE(DescribeLidarNoise(e).find("angular sigma"), std::string::npos);
  }
}

TEST(LidarNoise, RangeNoiseAloneShowsNoAngularTermAndBoundsIt) {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const LidarNoiseEstimate e = LearnFromBoards(0.008, 0.0, seed);
    EXPECT_FALSE(e.angular_resolved) << seed;
    EXPECT_LT(e.angular_sigma_upper_rad, 0.08 * kDegToRad) << seed;
    EXPECT_NEAR(e.range_sigma_median_m, 0.008, 0.0008) << seed;
    EXPECT_NEAR(e.range_sigma_min_m, 0.008, 0.0015);
    EXPECT_NEAR(e.range_sigma_max_m, 0.008, 0.0015);
    EXPECT_NE(DescribeLidarNoise(e).find("no angular term resolved"), std::string::npos);
  }
}

TEST(LidarNoise, BoardsThatTellNothingGiveNoEstimate) {
  EXPECT_EQ(EstimateLidarNoise({}).boards, 0);
  EXPECT_EQ(DescribeLidarNoise(EstimateLidarNoise({})), "");
  // Every return at one incidence and range: no slope can be told, none is claimed.
  RangeResidualMoments flat;
  for (int i = 0; i < 50; ++i) flat.Add(1.0, i % 2 ? 0.01 : -0.01);
  const LidarNoiseEstimate e = EstimateLidarNoise({flat, flat});
  EXPECT_EQ(e.boards, 2);
  EXPECT_FALSE(e.angular_resolved);
  EXPECT_NEAR(e.range_sigma_median_m, 0.01, 1e-12);
  EXPECT_NE(DescribeLidarNoise(e).find("do not vary enough"), std::string::npos);
  RangeResidualMoments few;
  for (int i = 0; i < 5; ++i) few.Add(i, 0.01);
  EXPECT_EQ(EstimateLidarNoise({few}).boards, 0);  // fewer than 10 returns
}

// The bound with the angular term is the scatter of the range fit under jittered beams: a board
// 4 m away turned 60°, 5 mm of range noise and 0.3° of jitter (the jitter's share of a return's
// range σ reaches 3.6 cm there). Without the term the bound is far too confident.
TEST(LidarNoise, TheBoundWithTheAngularTermIsTheFitsScatter) {
  const double range_sigma = 0.005, angular_sigma = 0.3 * kDegToRad;
  std::mt19937_64 rng(7);
  Plane truth;
  const LidarCloud layout = JitteredBoard(4.0, 60.0, 0.0, 0.0, &rng, &truth);  // the nominal rays
  std::vector<Vec3> nominal;
  for (const auto& p : layout.points) nominal.push_back(p.cast<double>());
  std::normal_distribution<double> normal(0.0, 1.0);
  double sum_d2 = 0.0;
  const int trials = 300;
  for (int t = 0; t < trials; ++t) {
    LidarCloud cloud;
    for (const Vec3& x : nominal) {
      const Vec3 u = x.normalized(), a = u.unitOrthogonal(), b = u.cross(a);
      const Vec3 cast = (u + angular_sigma * (normal(rng) * a + normal(rng) * b)).normalized();
      const double hit = -truth.distance / truth.normal.dot(cast);
      cloud.points.push_back(((hit + range_sigma * normal(rng)) * u).cast<float>());
    }
    std::vector<int> all(cloud.size());
    std::iota(all.begin(), all.end(), 0);
    const auto fit = FitPlaneRangeMl(cloud, all, truth);
    ASSERT_TRUE(fit);
    const double dd = fit->plane.distance - truth.distance;
    sum_d2 += dd * dd;
  }
  const double scatter_d = std::sqrt(sum_d2 / trials);
  const double with_term =
      std::sqrt(LidarPlaneBoundCovariance(nominal, truth, range_sigma, angular_sigma)(3, 3));
  const double range_only = std::sqrt(LidarPlaneBoundCovariance(nominal, truth, range_sigma)(3, 3));
  std::printf("d scatter %.2f mm, bound with the angular term %.2f mm, range only %.2f mm\n",
              scatter_d * 1e3, with_term * 1e3, range_only * 1e3);
  EXPECT_NEAR(scatter_d / with_term, 1.0, 0.2);
  EXPECT_GT(scatter_d / range_only, 2.0);
}

// Guidance takes the learned term: boards whose residuals resolve a jitter give the sensors an
// angular σ (and the range σ without it); boards that do not keep the median RMS as before.
TEST(LidarNoise, GuidanceLearnsTheAngularTermWhereTheBoardsResolveIt) {
  for (const double jitter_deg : {0.25, 0.0}) {
    std::mt19937_64 rng(11);
    std::vector<PairFeatures> pairs;
    for (int k = 0; k < 20; ++k) {
      Plane truth;
      const LidarCloud cloud = JitteredBoard(1.5 + 3.5 * (k % 5) / 4.0, 15.0 * (k % 4), 0.008,
                                             jitter_deg * kDegToRad, &rng, &truth);
      std::vector<int> all(cloud.size());
      std::iota(all.begin(), all.end(), 0);
      PairFeatures pair;
      pair.id = "pose" + std::to_string(k);
      pair.status = PairStatus::kAccepted;
      pair.lidar = FitPlaneRangeMl(cloud, all, truth);
      ASSERT_TRUE(pair.lidar);
      pair.camera = CameraBoardObservation{};
      pair.camera->cam_from_board = Pose(Eigen::Translation3d(0.0, 0.0, 1.5 + 3.5 * (k % 5) / 4.0));
      pair.camera->corner_sigma_px = 0.2;
      pairs.push_back(std::move(pair));
    }
    std::string why;
    const auto sensors = LearnSensorGeometry(test::PinholeCamera(), BoardSpec{},
                                             MakeBeamTable(LidarModel::kVlp16), pairs, &why);
    ASSERT_TRUE(sensors) << why;
    if (jitter_deg > 0) {
      EXPECT_NEAR(sensors->angular_sigma_rad, jitter_deg * kDegToRad, 0.2 * jitter_deg * kDegToRad);
      EXPECT_NEAR(sensors->range_sigma_m, 0.008, 0.0015);
    } else {
      EXPECT_EQ(sensors->angular_sigma_rad, 0.0);
      EXPECT_NEAR(sensors->range_sigma_m, 0.008, 0.001);
    }
  }
}

}  // namespace
}  // namespace calibench
