#include <gtest/gtest.h>

#include "core/camera/undistort.h"
#include "core/sim/sim.h"

namespace calibench {
namespace {

// A board rendered through a distorting lens, undistorted, must show its corners where the
// distortion-free pinhole puts them.
void CheckCornersLandOnThePinholeProjection(const CameraModel& camera) {
  BoardSpec board;
  board.cols = 7;
  board.rows = 5;
  board.square_size = 0.06;
  Pose cam_from_board = Pose::Identity();
  cam_from_board.translation() = Vec3(0.15, -0.1, 1.2);
  const ImageU8 image = RenderBoardImage(camera, board, cam_from_board, RenderOptions{});
  const UndistortedView view = Undistort(camera, image);
  ASSERT_EQ(view.image.width, camera.width);
  ASSERT_EQ(view.image.height, camera.height);
  for (const Vec3& corner : BoardCornerPoints(board)) {
    const auto in_pinhole = view.pinhole.Project(cam_from_board * corner);
    const auto in_lens = camera.Project(cam_from_board * corner);
    ASSERT_TRUE(in_pinhole && in_lens);
    // The undistorted image at the pinhole pixel looks like the source at the lens pixel.
    const int u = static_cast<int>(std::lround(in_pinhole->x())),
              v = static_cast<int>(std::lround(in_pinhole->y()));
    const int su = static_cast<int>(std::lround(in_lens->x())),
              sv = static_cast<int>(std::lround(in_lens->y()));
    for (int du = -3; du <= 3; du += 3)
      for (int dv = -3; dv <= 3; dv += 3) {
        // Away from the corner itself, the colour (black or white square) must agree.
        if (du == 0 || dv == 0) continue;
        const auto a = view.image.Row(v + dv)[3 * (u + du)];
        const auto b = image.Row(sv + dv)[3 * (su + du)];
        EXPECT_NEAR(a, b, 90) << "corner at " << in_pinhole->transpose();
      }
  }
}

TEST(Undistort, RadTanKeepsTheIntrinsicsAndStraightensTheBoard) {
  CameraModel camera;
  camera.width = 640;
  camera.height = 480;
  camera.fx = camera.fy = 500;
  camera.cx = 319.5;
  camera.cy = 239.5;
  camera.distortion = {-0.25, 0.08, 0.001, -0.001, 0.0};
  const UndistortedView view =
      Undistort(camera, ImageU8{640, 480, 3, std::vector<std::uint8_t>(640 * 480 * 3, 128)});
  EXPECT_EQ(view.pinhole.fx, camera.fx);
  EXPECT_EQ(view.pinhole.distortion, std::vector<double>(5, 0.0));
  CheckCornersLandOnThePinholeProjection(camera);
}

TEST(Undistort, FisheyeGetsAWideButFinitePinhole) {
  CameraModel camera;
  camera.type = CameraModelType::kKannalaBrandt;
  camera.width = 640;
  camera.height = 480;
  camera.fx = camera.fy = 220;
  camera.cx = 319.5;
  camera.cy = 239.5;
  camera.distortion = {-0.01, 0.005, -0.002, 0.0005};
  const UndistortedView view =
      Undistort(camera, ImageU8{640, 480, 3, std::vector<std::uint8_t>(640 * 480 * 3, 128)});
  EXPECT_NEAR(std::atan2(0.5 * camera.width, view.pinhole.fx), 60.0 * M_PI / 180.0, 1e-9);
  CheckCornersLandOnThePinholeProjection(camera);
}

}  // namespace
}  // namespace calibench
