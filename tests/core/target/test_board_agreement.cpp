// Issue 32 item 5: the gate that checks a LiDAR board against the camera's follows the LiDAR
// plane's own covariance, rings' range biases included: a strip that few rings cross may tilt
// more about the rings' direction than a full board, no more about the other axis, and a board
// that moved is still rejected.
#include <gtest/gtest.h>

#include <random>

#include "core/lidar_camera/pipeline.h"
#include "core/target/lidar_plane.h"

namespace calibench {
namespace {

constexpr double kDistanceM = 2.0;  // board plane x = 2 m, facing the LiDAR

// A VLP-16-like sweep (rings 2° apart, 0.2° azimuth) of a 0.8 m wide board at x = 2 m, `height_m`
// tall and centred at z = 0, with 5 mm range noise and, per ring, a range bias of `ring_bias_m`
// (1σ). Only the board's returns: the plane fit gets them all.
LidarCloud BoardSweep(double height_m, double ring_bias_m, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  LidarCloud cloud;
  for (int ring = 0; ring < 16; ++ring) {
    const double elevation = (-15.0 + 2.0 * ring) * kDegToRad;
    const double bias = ring_bias_m * normal(rng);
    for (double azimuth_deg = -15; azimuth_deg <= 15; azimuth_deg += 0.2) {
      const double azimuth = azimuth_deg * kDegToRad;
      const Vec3 ray(std::cos(elevation) * std::cos(azimuth),
                     std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
      const Vec3 hit = ray * (kDistanceM / ray.x());
      if (std::abs(hit.y()) > 0.4 || std::abs(hit.z()) > height_m / 2) continue;
      const double range = hit.norm() + bias + 0.005 * normal(rng);
      cloud.points.push_back((ray * range).cast<float>());
      cloud.ring.push_back(ring);
    }
  }
  cloud.width = static_cast<int>(cloud.size());
  return cloud;
}

LidarPlaneFit Fit(const LidarCloud& cloud) {
  std::vector<int> all(cloud.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  std::string why;
  const auto fit = FitBoardPlane(cloud, all, LidarPlaneOptions{}, &why);
  EXPECT_TRUE(fit) << why;
  return fit.value_or(LidarPlaneFit{});
}

// The camera's board: the true plane turned by `turn` about the board centre and moved by
// `shift_m` along its normal; with cam_from_lidar = identity, camera frame = LiDAR frame.
CameraBoardObservation CameraBoard(const Mat3& turn, double shift_m) {
  CameraBoardObservation camera;
  camera.cam_from_board = Pose::Identity();
  camera.cam_from_board.translation() = Vec3(kDistanceM + shift_m, 0, 0);
  const Vec3 normal = turn * Vec3(-1, 0, 0);
  camera.plane = Plane{normal, -normal.dot(camera.cam_from_board.translation())};
  camera.pose_covariance = Mat6::Identity() * 1e-10;
  camera.plane_covariance = Mat4::Identity() * 1e-10;
  return camera;
}

BoardSpec Sheet() {
  BoardSpec board;
  board.cols = 7;
  board.rows = 5;
  board.square_size = 0.04;
  board.board_width = 0.8;
  board.board_height = 0.6;
  return board;
}

Mat3 Turn(const Vec3& axis, double degrees) {
  return Eigen::AngleAxisd(degrees * kDegToRad, axis.normalized()).toRotationMatrix();
}

TEST(BoardAgreement, RingBiasesMakeAStripsTiltAcrossItsRingsUncertain) {
  const LidarPlaneFit strip = Fit(BoardSweep(0.30, 0.0, 1));  // 4 rings at 2 m
  const LidarPlaneFit board = Fit(BoardSweep(0.60, 0.0, 1));  // 9 rings
  EXPECT_LE(strip.num_rings, 4);
  EXPECT_GE(board.num_rings, 8);
  // The tilt about the LiDAR's y axis (the rings run along y here) moves the normal along z.
  const double strip_sigma = std::sqrt(strip.ring_bias_covariance(2, 2));
  const double board_sigma = std::sqrt(board.ring_bias_covariance(2, 2));
  EXPECT_GT(strip_sigma, 2.5 * board_sigma);
  // About the vertical axis (along each ring) a common ring offset tilts nothing.
  EXPECT_LT(std::sqrt(strip.ring_bias_covariance(1, 1)), 0.2 * strip_sigma);
  // The model against Monte Carlo: per-ring biases of 5 mm scatter a strip's tilt as predicted.
  double sum_sq = 0;
  constexpr int kRuns = 200;
  for (int run = 0; run < kRuns; ++run) {
    const LidarPlaneFit fit = Fit(BoardSweep(0.30, 0.005, 100 + run));
    sum_sq += std::pow(fit.plane.normal.z(), 2);
  }
  const double scatter = std::sqrt(sum_sq / kRuns);
  const double predicted = std::sqrt(strip.ring_bias_covariance(2, 2) + strip.covariance(2, 2));
  EXPECT_NEAR(scatter / predicted, 1.0, 0.2) << scatter << " vs " << predicted;
}

TEST(BoardAgreement, AStripMayTiltMoreAcrossItsRingsThanAFullBoard) {
  const PipelineOptions options;
  const LidarPlaneFit strip = Fit(BoardSweep(0.30, 0.0, 2));
  const LidarPlaneFit board = Fit(BoardSweep(0.60, 0.0, 2));
  const Pose identity = Pose::Identity();
  // Both agree with an exact camera board.
  EXPECT_EQ(BoardDisagreement(strip, CameraBoard(Mat3::Identity(), 0), identity, Sheet(), options),
            "");
  EXPECT_EQ(BoardDisagreement(board, CameraBoard(Mat3::Identity(), 0), identity, Sheet(), options),
            "");
  // 4° about the rings' direction (y): within a 4-ring strip's σ, beyond a full board's. The old
  // fixed gate (2°) rejected both.
  const CameraBoardObservation tilted = CameraBoard(Turn(Vec3::UnitY(), 4.0), 0);
  EXPECT_EQ(BoardDisagreement(strip, tilted, identity, Sheet(), options), "");
  const std::string full = BoardDisagreement(board, tilted, identity, Sheet(), options);
  EXPECT_NE(full.find("LiDAR board disagrees with the camera's by 4."), std::string::npos) << full;
  // The same 4° about the vertical axis: the rings pin that tilt, strip or not.
  const std::string across = BoardDisagreement(strip, CameraBoard(Turn(Vec3::UnitZ(), 4.0), 0),
                                               identity, Sheet(), options);
  EXPECT_NE(across.find("LiDAR board disagrees with the camera's by 4."), std::string::npos)
      << across;
}

TEST(BoardAgreement, AMovedBoardIsStillRejected) {
  const PipelineOptions options;
  const LidarPlaneFit strip = Fit(BoardSweep(0.30, 0.0, 3));
  // Moved 10 cm back between the camera's frame and the LiDAR's sweep.
  const std::string moved = BoardDisagreement(strip, CameraBoard(Mat3::Identity(), 0.10),
                                              Pose::Identity(), Sheet(), options);
  EXPECT_NE(moved.find("100 mm off its plane"), std::string::npos) << moved;
  // Turned by 15° about the rings' direction: more than a strip's tilt can be.
  const std::string turned = BoardDisagreement(strip, CameraBoard(Turn(Vec3::UnitY(), 15.0), 0),
                                               Pose::Identity(), Sheet(), options);
  EXPECT_NE(turned.find("by 15.0 deg"), std::string::npos) << turned;
}

}  // namespace
}  // namespace calibench
