// Camera side of a pair: planar PnP through the camera model (exact and noisy synthetic corners,
// covariance calibration, plane Jacobian), detection accuracy on rendered boards (checkerboard and
// ChArUco, against the projected truth), and real images from ../shared.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "core/board_camera.h"
#include "core/geometry.h"
#include "core/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

using test::MatrixNear;

constexpr double kDeg = M_PI / 180.0;

CameraModel PinholeCamera() {
  CameraModel c;
  c.type = CameraModelType::kPinholeRadTan;
  c.width = 1440;
  c.height = 1080;
  c.fx = c.fy = 1000.0;
  c.cx = 719.5;
  c.cy = 539.5;
  c.distortion = {-0.1, 0.05, 0.0005, -0.0003, 0.0};
  return c;
}

CameraModel FisheyeCamera() {
  CameraModel c;
  c.type = CameraModelType::kKannalaBrandt;
  c.width = 1440;
  c.height = 1080;
  c.fx = c.fy = 450.0;
  c.cx = 719.5;
  c.cy = 539.5;
  c.distortion = {-0.01, 0.005, -0.002, 0.0005};
  return c;
}

// A3 sheet, 7x5 inner corners, 40 mm squares.
BoardSpec A3Checkerboard() {
  BoardSpec b;
  b.type = BoardType::kCheckerboard;
  b.cols = 7;
  b.rows = 5;
  b.square_size = 0.04;
  b.board_width = 0.42;
  b.board_height = 0.297;
  return b;
}

BoardSpec A3Charuco(const std::string& dictionary) {
  BoardSpec b;
  b.type = BoardType::kCharuco;
  b.cols = 5;
  b.rows = 7;
  b.square_size = 0.04;
  b.marker_size = 0.03;
  b.dictionary = dictionary;
  b.board_width = 0.297;
  b.board_height = 0.42;
  return b;
}

// Board centre at `centre` (camera frame), print facing the camera (board z along +z_cam before
// the tilt), tilted by `tilt` about an oblique in-plane axis.
Pose BoardPose(const Vec3& centre, double tilt_rad) {
  Pose pose = Pose::Identity();
  pose.linear() = ExpSO3(tilt_rad * Vec3(0.8, 0.6, 0.0)) * ExpSO3(Vec3(0, 0, 0.1));
  pose.translation() = centre;
  return pose;
}

BoardDetection ProjectCorners(const CameraModel& camera, const BoardSpec& board, const Pose& pose) {
  BoardDetection detection;
  const std::vector<Vec3> points = BoardCornerPoints(board);
  for (size_t i = 0; i < points.size(); ++i) {
    const auto pixel = camera.Project(pose * points[i]);
    CALIBENCH_CHECK(pixel.has_value());
    detection.pixels.push_back(*pixel);
    detection.board_points.push_back(points[i]);
    detection.ids.push_back(static_cast<int>(i));
  }
  return detection;
}

Vec4 PlaneOf(const Pose& cam_from_board) {
  return OrientTowardsOrigin(TransformPlane(cam_from_board, Plane{Vec3::UnitZ(), 0.0}))
      .Coefficients();
}

TEST(BoardCamera, OptionsCheck) {
  std::string why;
  EXPECT_TRUE(BoardDetectionOptions{}.Check(&why));
  EXPECT_TRUE(PnpOptions{}.Check(&why));
  BoardDetectionOptions detect;
  detect.min_corners = 3;
  EXPECT_FALSE(detect.Check(&why));
  EXPECT_NE(why.find("min_corners"), std::string::npos);
  detect = {};
  detect.subpix_half_window_px = -1;
  EXPECT_FALSE(detect.Check(&why));
  PnpOptions pnp;
  pnp.min_corner_sigma_px = 0.0;
  EXPECT_FALSE(pnp.Check(&why));
  pnp = {};
  pnp.max_iterations = 0;
  EXPECT_FALSE(pnp.Check(&why));
  pnp = {};
  pnp.max_rms_px = -1.0;
  EXPECT_FALSE(pnp.Check(&why));
}

class PnpSynthetic : public ::testing::TestWithParam<bool> {
 protected:
  CameraModel Camera() const { return GetParam() ? FisheyeCamera() : PinholeCamera(); }
};

TEST_P(PnpSynthetic, ExactCornersGiveTheExactPose) {
  const CameraModel camera = Camera();
  for (const Vec3& centre : {Vec3(0.1, -0.05, 1.5), Vec3(-0.6, 0.4, 3.0), Vec3(0.8, 0.5, 1.2)}) {
    for (double tilt : {0.0, 30.0, 55.0}) {
      const Pose truth = BoardPose(centre, tilt * kDeg);
      std::string why;
      const auto obs = EstimateBoardPose(camera, ProjectCorners(camera, A3Checkerboard(), truth),
                                         PnpOptions{}, &why);
      ASSERT_TRUE(obs) << why;
      EXPECT_TRUE(MatrixNear(obs->cam_from_board.matrix(), truth.matrix(), 1e-8));
      EXPECT_LT(obs->reprojection_rms_px, 1e-6);
      EXPECT_DOUBLE_EQ(obs->corner_sigma_px, PnpOptions{}.min_corner_sigma_px);
      EXPECT_EQ(obs->num_corners, 35);
      // Oriented towards the camera: the print side faces it, so n = -R e_z.
      EXPECT_GT(obs->plane.distance, 0.0);
      EXPECT_TRUE(MatrixNear(obs->plane.normal, -(truth.linear() * Vec3::UnitZ()), 1e-8));
      EXPECT_NEAR(obs->plane.SignedDistance(truth.translation()), 0.0, 1e-8);
    }
  }
}

TEST_P(PnpSynthetic, PlaneCovarianceUsesTheNumericPlaneJacobian) {
  const CameraModel camera = Camera();
  const Pose truth = BoardPose(Vec3(0.3, -0.2, 2.5), 35 * kDeg);
  BoardDetection detection = ProjectCorners(camera, A3Checkerboard(), truth);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.3);
  for (Vec2& p : detection.pixels) p += Vec2(noise(rng), noise(rng));
  std::string why;
  const auto obs = EstimateBoardPose(camera, detection, PnpOptions{}, &why);
  ASSERT_TRUE(obs) << why;
  Eigen::Matrix<double, 4, 6> numeric;
  const double h = 1e-6;
  for (int k = 0; k < 6; ++k) {
    const Vec6 step = h * Vec6::Unit(k);
    numeric.col(k) = (PlaneOf(obs->cam_from_board * ExpSE3(step)) -
                      PlaneOf(obs->cam_from_board * ExpSE3(-step))) /
                     (2 * h);
  }
  const Mat4 expected = numeric * obs->pose_covariance * numeric.transpose();
  EXPECT_TRUE(MatrixNear(obs->plane_covariance, expected, 1e-6 * expected.cwiseAbs().maxCoeff()));
  EXPECT_TRUE(MatrixNear(obs->plane.Coefficients(), PlaneOf(obs->cam_from_board), 1e-12));
  // n is unit: the covariance is rank 3, with the null direction (n, 0).
  EXPECT_LT((obs->plane_covariance * Vec4(obs->plane.normal.x(), obs->plane.normal.y(),
                                          obs->plane.normal.z(), 0.0))
                .norm(),
            1e-9 * obs->plane_covariance.norm());
}

// 500 noisy trials: the predicted plane covariance matches the scatter of the estimates.
TEST_P(PnpSynthetic, PlaneCovarianceMatchesMonteCarlo) {
  const CameraModel camera = Camera();
  const Pose truth = BoardPose(Vec3(-0.2, 0.1, 2.0), 30 * kDeg);
  const BoardDetection exact = ProjectCorners(camera, A3Checkerboard(), truth);
  const Vec4 true_plane = PlaneOf(truth);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, 0.3);
  const int kTrials = 500;
  double mahalanobis_sum = 0.0, sigma_sum = 0.0;
  Mat4 empirical = Mat4::Zero(), predicted = Mat4::Zero();
  for (int trial = 0; trial < kTrials; ++trial) {
    BoardDetection noisy = exact;
    for (Vec2& p : noisy.pixels) p += Vec2(noise(rng), noise(rng));
    std::string why;
    const auto obs = EstimateBoardPose(camera, noisy, PnpOptions{}, &why);
    ASSERT_TRUE(obs) << why;
    const Vec4 e = obs->plane.Coefficients() - true_plane;
    // Pseudo-inverse over the 3 free directions (n is unit).
    const Eigen::SelfAdjointEigenSolver<Mat4> eig(obs->plane_covariance);
    Mat4 pinv = Mat4::Zero();
    for (int k = 1; k < 4; ++k) {
      const Vec4 v = eig.eigenvectors().col(k);
      pinv += v * v.transpose() / eig.eigenvalues()[k];
    }
    mahalanobis_sum += e.dot(pinv * e);
    sigma_sum += obs->corner_sigma_px;
    empirical += e * e.transpose();
    predicted += obs->plane_covariance;
  }
  const double mean_mahalanobis = mahalanobis_sum / kTrials;
  std::printf("[ plane MC ] %s: mean Mahalanobis %.3f (expect ~3), mean corner sigma %.4f px\n",
              GetParam() ? "fisheye" : "pinhole", mean_mahalanobis, sigma_sum / kTrials);
  EXPECT_NEAR(mean_mahalanobis, 3.0, 0.45);
  EXPECT_NEAR(sigma_sum / kTrials, 0.3, 0.02);
  empirical /= kTrials;
  predicted /= kTrials;
  EXPECT_NEAR(empirical.trace() / predicted.trace(), 1.0, 0.15);
  EXPECT_NEAR(empirical(3, 3) / predicted(3, 3), 1.0, 0.15);
}

INSTANTIATE_TEST_SUITE_P(Cameras, PnpSynthetic, ::testing::Bool(),
                         [](const auto& info) { return info.param ? "Fisheye" : "Pinhole"; });

TEST(BoardCamera, PnpFailsWithAReason) {
  const CameraModel camera = PinholeCamera();
  const Pose truth = BoardPose(Vec3(0.0, 0.0, 2.0), 20 * kDeg);
  const BoardDetection full = ProjectCorners(camera, A3Checkerboard(), truth);
  std::string why;

  BoardDetection three = full;
  three.pixels.resize(3);
  three.board_points.resize(3);
  three.ids.resize(3);
  EXPECT_FALSE(EstimateBoardPose(camera, three, PnpOptions{}, &why));
  EXPECT_NE(why.find("3 corners"), std::string::npos) << why;

  // Swapped corner ids: no rigid pose explains the pixels.
  BoardDetection scrambled = full;
  std::swap(scrambled.board_points[0], scrambled.board_points[34]);
  std::swap(scrambled.board_points[5], scrambled.board_points[20]);
  why.clear();
  EXPECT_FALSE(EstimateBoardPose(camera, scrambled, PnpOptions{}, &why));
  EXPECT_NE(why.find("RMS"), std::string::npos) << why;

  CameraModel broken = camera;
  broken.fx = -1.0;
  why.clear();
  EXPECT_FALSE(EstimateBoardPose(broken, full, PnpOptions{}, &why));
  EXPECT_FALSE(why.empty());

  // A fisheye sees past 90 degrees: a board behind the camera still has pixels.
  const CameraModel fisheye = FisheyeCamera();
  Pose behind = Pose::Identity();
  behind.linear() = ExpSO3(Vec3(0, M_PI, 0));  // print facing the camera from behind it
  behind.translation() = Vec3(0.0, 0.0, -0.3);
  BoardDetection back;
  for (const Vec3& x : BoardCornerPoints(A3Checkerboard())) {
    const Vec3 p = behind * x + Vec3(1.0, 0.0, 0.0);  // sideways, so that every corner images
    const auto pixel = fisheye.Project(p);
    if (!pixel) continue;
    back.pixels.push_back(*pixel);
    back.board_points.push_back(x);
    back.ids.push_back(static_cast<int>(back.ids.size()));
  }
  if (back.pixels.size() >= 4) {
    why.clear();
    const auto obs = EstimateBoardPose(fisheye, back, PnpOptions{}, &why);
    EXPECT_FALSE(obs);
    EXPECT_FALSE(why.empty());
  }
}

}  // namespace
}  // namespace calibench
