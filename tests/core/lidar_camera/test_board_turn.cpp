// A checkerboard's two corner orders (core/lidar_camera/pipeline.h TurnCheckerboardObservation):
// the turned observation is what PnP gives on the turned corners, pose and covariance, and two
// turns are none; the plane is the same either way.
#include <gtest/gtest.h>

#include "core/geometry/geometry.h"
#include "core/lidar_camera/pipeline.h"
#include "core/sim/sim.h"
#include "core/target/board_camera.h"

namespace calibench {
namespace {

TEST(BoardTurn, TheTurnedObservationIsPnpOnTheTurnedCorners) {
  const CameraModel camera = DefaultSimCamera(false);
  const BoardSpec board = BoardPreset("a3");
  Pose cam_from_board = Pose::Identity();
  cam_from_board.linear() =
      (Eigen::AngleAxisd(0.3, Vec3::UnitX()) * Eigen::AngleAxisd(-0.2, Vec3::UnitY()))
          .toRotationMatrix();
  cam_from_board.translation() = Vec3(0.1, -0.05, 1.8);
  std::string why;
  const auto detection =
      DetectBoard(RenderBoardImage(camera, board, cam_from_board, {}), board, {}, &why);
  ASSERT_TRUE(detection) << why;
  const auto seen = EstimateBoardPose(camera, *detection, {}, &why);
  ASSERT_TRUE(seen) << why;

  CameraBoardObservation turned = *seen;
  TurnCheckerboardObservation(board, &turned);
  const double turn = Eigen::AngleAxisd(seen->cam_from_board.rotation().transpose() *
                                        turned.cam_from_board.rotation())
                          .angle();
  EXPECT_NEAR(turn, M_PI, 1e-9);
  EXPECT_LT((turned.cam_from_board.translation() - seen->cam_from_board.translation()).norm(),
            1e-12);
  // PnP on the turned corners lands on the turned pose, with the turned covariance.
  const auto again = EstimateBoardPose(camera, turned.corners, {}, &why);
  ASSERT_TRUE(again) << why;
  const PoseError apart = ComputePoseError(again->cam_from_board, turned.cam_from_board);
  EXPECT_LT(apart.translation_m, 1e-6);
  EXPECT_LT(apart.rotation_rad, 1e-6);
  EXPECT_LT((again->pose_covariance - turned.pose_covariance).norm(),
            1e-6 * turned.pose_covariance.norm());
  // Each corner's id names its board point, as the detector's do.
  const std::vector<Vec3> corners = BoardCornerPoints(board);
  for (std::size_t k = 0; k < turned.corners.ids.size(); ++k)
    EXPECT_LT((corners[turned.corners.ids[k]] - turned.corners.board_points[k]).norm(), 1e-9);
  // Two turns are none.
  TurnCheckerboardObservation(board, &turned);
  EXPECT_LT(ComputePoseError(turned.cam_from_board, seen->cam_from_board).rotation_rad, 1e-9);
  EXPECT_EQ(turned.corners.ids, seen->corners.ids);
}

}  // namespace
}  // namespace calibench
