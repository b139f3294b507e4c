// Rings found again in a board's returns without a ring field (core/target/ring_bias.h), and the
// plane covariance their range biases give: a strip crossed by few rings tilts far more about the
// rings' direction than a board crossed by many.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/target/ring_bias.h"

namespace calibench {
namespace {

// Returns on the plane x = distance facing the LiDAR: `rings` rows of elevation `spacing_deg`
// apart (centred on 0), each `per_ring` returns over ±10° of azimuth; no ring field.
LidarCloud BoardRows(int rings, double spacing_deg, int per_ring, double distance_m) {
  LidarCloud cloud;
  for (int r = 0; r < rings; ++r) {
    const double elevation = (r - 0.5 * (rings - 1)) * spacing_deg * kDegToRad;
    for (int k = 0; k < per_ring; ++k) {
      const double azimuth = (-10.0 + 20.0 * k / (per_ring - 1)) * kDegToRad;
      const Vec3 ray(std::cos(elevation) * std::cos(azimuth),
                     std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
      cloud.points.push_back((ray * (distance_m / ray.x())).cast<float>());
    }
  }
  return cloud;
}

std::vector<int> All(const LidarCloud& cloud) {
  std::vector<int> indices(cloud.size());
  for (size_t i = 0; i < indices.size(); ++i) indices[i] = static_cast<int>(i);
  return indices;
}

TEST(RingBias, ElevationsShowTheRingsOfACloudWithoutItsRingField) {
  const LidarCloud vlp16_board = BoardRows(8, 2.0, 40, 3.0);  // 8 of a VLP-16's 2° rings
  EXPECT_EQ(ElevationRings(vlp16_board, All(vlp16_board)), 8);
  // A rosette's returns: elevations everywhere, no gaps of rings.
  LidarCloud rosette;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> angle(-8.0 * kDegToRad, 8.0 * kDegToRad);
  for (int i = 0; i < 2000; ++i) {
    const double azimuth = angle(rng), elevation = angle(rng);
    const Vec3 ray(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                   std::sin(elevation));
    rosette.points.push_back((ray * (3.0 / ray.x())).cast<float>());
  }
  EXPECT_LE(ElevationRings(rosette, All(rosette)), 1);
}

TEST(RingBias, AStripOfFewRingsTiltsMoreThanABoardOfMany) {
  const LidarCloud strip = BoardRows(2, 2.0, 80, 3.0);
  const LidarCloud board = BoardRows(8, 2.0, 20, 3.0);
  const Plane facing{Vec3(-1.0, 0.0, 0.0), 3.0};
  const double sigma_m = 0.005;
  const Mat4 strip_covariance = RingBiasCovariance(strip, All(strip), facing, sigma_m);
  const Mat4 board_covariance = RingBiasCovariance(board, All(board), facing, sigma_m);
  // The normal's z component: the tilt about the rings' direction (y).
  EXPECT_GT(strip_covariance(2, 2), 4.0 * board_covariance(2, 2));
  // The offset of the plane: a common bias of 5 mm over a few rings moves it by millimetres.
  EXPECT_GT(std::sqrt(board_covariance(3, 3)), 0.001);
  EXPECT_LT(std::sqrt(board_covariance(3, 3)), 0.005);
  // Without ring biases nothing.
  EXPECT_EQ(RingBiasCovariance(board, All(board), facing, 0.0), Mat4::Zero());
}

}  // namespace
}  // namespace calibench
