// The LiDAR's noise learned from the boards' returns (core/target/lidar_noise.h): boards drawn
// with a known range noise and a known angular jitter, fitted along their rays, and the two terms
// recovered from the fits' residuals.
#include <gtest/gtest.h>

#include <numeric>
#include <random>

#include "core/geometry/geometry.h"
#include "core/target/lidar_noise.h"
#include "core/target/lidar_plane.h"

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

}  // namespace
}  // namespace calibench
