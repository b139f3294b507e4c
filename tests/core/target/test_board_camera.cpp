// Camera side of a pair: planar PnP through the camera model on synthetic corners (exact pose,
// covariance against Monte Carlo, plane Jacobian against numeric differences, failures) and the
// whole camera side (detection + pose) on real images from ../shared.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "core/base/image.h"
#include "core/geometry/geometry.h"
#include "core/io/camera_file.h"
#include "core/io/image_io.h"
#include "core/sim/sim.h"
#include "core/target/board_camera.h"
#include "tests/core/target/board_test_scenes.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

using test::A3Checkerboard;
using test::BoardPose;
using test::FisheyeCamera;
using test::kDeg;
using test::MatrixNear;
using test::PinholeCamera;
using test::PlaneOf;
using test::ProjectCorners;

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
  EXPECT_LT((obs->plane_covariance *
             Vec4(obs->plane.normal.x(), obs->plane.normal.y(), obs->plane.normal.z(), 0.0))
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

  // A fisheye sees past 90 degrees: a board beside the camera, its centre slightly behind it,
  // still has pixels, and the pose is found but must be refused.
  const CameraModel fisheye = FisheyeCamera();
  Pose behind = Pose::Identity();
  behind.linear() = ExpSO3(Vec3(0.0, M_PI / 2, 0.0));  // print facing the camera, board z = +x
  behind.translation() = Vec3(1.0, 0.0, -0.02);
  const BoardDetection back = ProjectCorners(fisheye, A3Checkerboard(), behind);
  why.clear();
  EXPECT_FALSE(EstimateBoardPose(fisheye, back, PnpOptions{}, &why));
  EXPECT_EQ(why, "the board is behind the camera");
}

// ---- Real images (../shared) -------------------------------------------------------------------

// ACFR VLP-16 dataset, pose16: a 7x5 chessboard with 95 mm squares, fisheye camera.
TEST(BoardCamera, RealFisheyeChessboard) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const ImageU8 image = LoadImage(shared / "datasets/acfr-vlp16-chessboard/images/pose16.png");
  const CameraModel camera =
      LoadCameraFile(shared / "datasets/acfr-vlp16-chessboard/camera_info.yaml");
  ASSERT_EQ(camera.type, CameraModelType::kKannalaBrandt);
  BoardSpec board;
  board.cols = 7;
  board.rows = 5;
  board.square_size = 0.095;
  std::string why;
  const auto detection = DetectBoard(image, board, BoardDetectionOptions{}, &why);
  ASSERT_TRUE(detection) << why;
  EXPECT_EQ(detection->pixels.size(), 35u);
  const auto obs = EstimateBoardPose(camera, *detection, PnpOptions{}, &why);
  ASSERT_TRUE(obs) << why;
  const Vec3 centre = obs->cam_from_board.translation();
  std::printf(
      "[ acfr pose16 ] rms %.3f px, sigma %.3f px, centre %.3f %.3f %.3f m, normal %.3f "
      "%.3f %.3f, d %.3f m\n",
      obs->reprojection_rms_px, obs->corner_sigma_px, centre.x(), centre.y(), centre.z(),
      obs->plane.normal.x(), obs->plane.normal.y(), obs->plane.normal.z(), obs->plane.distance);
  EXPECT_LT(obs->reprojection_rms_px, 1.0);
  // poses.csv, sample 16 (the ACFR tool's own camera-side estimate): centre (-334.6, -399.5,
  // 2347.0) mm, normal (0.2426, 0.3148, -0.9176), which also points towards the camera.
  EXPECT_TRUE(MatrixNear(centre, Vec3(-0.3346, -0.3995, 2.3470), 0.02));
  EXPECT_GT(obs->plane.normal.dot(Vec3(0.2426, 0.3148, -0.9176).normalized()),
            std::cos(1.0 * kDeg));
  EXPECT_GT(obs->plane.distance, 0.0);
}

// OpenCV's ChArUco calibration tutorial image with OpenCV's own intrinsics for it.
TEST(BoardCamera, RealCharucoTutorialImage) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const ImageU8 image = LoadImage(shared / "datasets/opencv-charuco-intrinsics/images/img_00.jpg");
  CameraModel camera;
  camera.type = CameraModelType::kPinholeRadTan;
  camera.width = 640;
  camera.height = 480;
  camera.fx = 452.51072219637672;
  camera.fy = 456.76707935146891;
  camera.cx = 317.70297317353277;
  camera.cy = 277.75155919135995;
  camera.distortion = {0.12136925618707872, -1.0854664722560681, 1.1786843796668460e-04,
                       -4.6240686046485508e-04, 2.9542589406810080};
  BoardSpec board;
  board.type = BoardType::kCharuco;
  board.cols = 5;
  board.rows = 7;
  board.square_size = 0.04;
  board.marker_size = 0.02;
  board.dictionary = "DICT_6X6_250";
  std::string why;
  const auto detection = DetectBoard(image, board, BoardDetectionOptions{}, &why);
  ASSERT_TRUE(detection) << why;
  EXPECT_GE(detection->pixels.size(), 15u);
  const auto obs = EstimateBoardPose(camera, *detection, PnpOptions{}, &why);
  ASSERT_TRUE(obs) << why;
  std::printf("[ charuco img_00 ] %zu corners, rms %.3f px, distance %.3f m\n",
              detection->pixels.size(), obs->reprojection_rms_px, obs->plane.distance);
  EXPECT_LT(obs->reprojection_rms_px, 1.0);
  // The OpenCV 4.6 offset on a real image: the corrected corners lie 0.5 px up-left of OpenCV's.
  BoardDetectionOptions uncorrected;
  uncorrected.correct_charuco_offset = false;
  const auto raw = DetectBoard(image, board, uncorrected, &why);
  ASSERT_TRUE(raw) << why;
  ASSERT_EQ(raw->ids, detection->ids);
  Vec2 shift = Vec2::Zero();
  for (size_t i = 0; i < raw->pixels.size(); ++i) shift += detection->pixels[i] - raw->pixels[i];
  shift /= static_cast<double>(raw->pixels.size());
  EXPECT_TRUE(MatrixNear(shift, Vec2(-0.5, -0.5), 0.03)) << shift.transpose();
}

}  // namespace
}  // namespace calibench
