// The pieces import's pair finder stands on: sweeps compared cell by cell (a still scene agrees
// through range noise and a drifting firing phase, a moved board does not; on real VLP-16
// sweeps too), corners followed by optical flow into the next frame, and a preset told from a
// larger print that contains its grid.
#include <gtest/gtest.h>

#include "core/io/cloud_io.h"
#include "core/lidar/cloud_motion.h"
#include "core/sim/sim.h"
#include "core/target/board_camera.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

LidarCloud Sweep(const Pose& lidar_from_board, double phase_fraction, std::uint64_t seed) {
  const BeamTable beams = MakeBeamTable(LidarModel::kVlp16);
  const BoardPrint print(BoardPreset("a3"));
  LidarScene scene;
  scene.lidar_from_board = lidar_from_board;
  LidarScanOptions scan;
  scan.range_noise_m = 0.01;
  scan.azimuth_offset_rad = phase_fraction * 2 * M_PI / beams.azimuth_steps;
  scan.seed = seed;
  return SimulateLidarScan(beams, print, scene, scan).ToCloud();
}

Pose BoardAt(double x, double y) {
  Pose pose = Pose::Identity();
  // Facing the LiDAR (board z along -x), 2 m ahead.
  pose.linear() << 0, 0, -1, 1, 0, 0, 0, -1, 0;
  pose.translation() = Vec3(x, y, 0.0);
  return pose;
}

TEST(CloudMotion, AStillSceneAgreesThroughNoiseAndPhaseAndAMovedBoardDoesNot) {
  const CloudMotionOptions options;
  const SweepGrid first = MakeSweepGrid(Sweep(BoardAt(2.0, 0.0), 0.1, 1), options);
  const SweepChange still =
      CompareSweeps(first, MakeSweepGrid(Sweep(BoardAt(2.0, 0.0), 0.8, 2), options), options);
  EXPECT_TRUE(still.agree) << still.changed_cells << " of " << still.common_cells;
  EXPECT_LE(still.changed_cells, 3);
  // 5 mm is below the tolerance: a board breathing in a hand is still.
  EXPECT_TRUE(
      CompareSweeps(first, MakeSweepGrid(Sweep(BoardAt(2.005, 0.0), 0.5, 3), options), options)
          .agree);
  for (const Vec2& moved : {Vec2(2.2, 0.0), Vec2(2.0, 0.15)}) {
    const SweepChange change = CompareSweeps(
        first, MakeSweepGrid(Sweep(BoardAt(moved.x(), moved.y()), 0.5, 4), options), options);
    EXPECT_FALSE(change.agree) << moved.transpose() << ": " << change.changed_cells;
  }
  // A grid of another shape (another sensor) never agrees.
  SweepGrid other = first;
  other.rows += 1;
  EXPECT_FALSE(CompareSweeps(first, other, options).agree);
}

// The ACFR sweeps are single sweeps of 40 board poses in one room: between two of them the board
// moved, and so did the person holding it. Every pair of consecutive poses disagrees, and
// cutting the two boards out removes a good part of the change (the rest is the person: 2-4 % of
// the cells, far above a still scene's 0.2 %). The set has no two sweeps of one pose, so the
// still case on real data is not measured here.
TEST(CloudMotion, RealVlp16SweepsOfTwoBoardPosesDisagree) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const auto dir = shared / "datasets/acfr-vlp16-chessboard/pcd";
  const CloudMotionOptions options;
  auto without = [&](const LidarCloud& cloud, const std::vector<LidarCloud>& boards) {
    LidarCloud kept;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      bool near = false;
      for (const LidarCloud& board : boards)
        for (const auto& p : board.points) near = near || (p - cloud.points[i]).norm() < 0.6f;
      if (near) continue;
      kept.points.push_back(cloud.points[i]);
      if (cloud.HasRing()) kept.ring.push_back(cloud.ring[i]);
    }
    return kept;
  };
  int disagreeing = 0;
  for (int n = 1; n < 40; n += 3) {
    const LidarCloud a = LoadCloud(dir / ("pose" + std::to_string(n) + "_full.pcd"));
    const LidarCloud b = LoadCloud(dir / ("pose" + std::to_string(n + 1) + "_full.pcd"));
    const std::vector<LidarCloud> boards = {
        LoadCloud(dir / ("pose" + std::to_string(n) + "_target.pcd")),
        LoadCloud(dir / ("pose" + std::to_string(n + 1) + "_target.pcd"))};
    const SweepChange whole =
        CompareSweeps(MakeSweepGrid(a, options), MakeSweepGrid(b, options), options);
    const SweepChange background =
        CompareSweeps(MakeSweepGrid(without(a, boards), options),
                      MakeSweepGrid(without(b, boards), options), options);
    std::printf("poses %2d-%2d: %4d of %4d cells changed; without the boards %3d of %4d\n", n,
                n + 1, whole.changed_cells, whole.common_cells, background.changed_cells,
                background.common_cells);
    disagreeing += !whole.agree;
    EXPECT_LT(background.changed_cells, whole.changed_cells);
  }
  EXPECT_EQ(disagreeing, 13);
}

// Rendered views of one board, the second moved by `shift` (metres, along the board's x).
struct TwoViews {
  CameraModel camera = DefaultSimCamera(false);
  BoardSpec board = BoardPreset("a3");
  Pose pose = Pose::Identity();
  ImageU8 first, second;
};

TwoViews Render(double shift) {
  TwoViews views;
  views.pose.linear() = Eigen::AngleAxisd(0.3, Vec3::UnitY()).toRotationMatrix();
  views.pose.translation() = Vec3(0.1, -0.05, 2.0);
  Pose moved = views.pose;
  moved.translation() += views.pose.rotation() * Vec3(shift, 0, 0);
  RenderOptions render;
  render.image_noise = 0.01;
  views.first = RenderBoardImage(views.camera, views.board, views.pose, render);
  render.seed = 2;
  views.second = RenderBoardImage(views.camera, views.board, moved, render);
  return views;
}

TEST(TrackBoard, FollowsAStillBoardToItsPoseAndAMovedOneToAnother) {
  for (const double shift : {0.0, 0.002, 0.03}) {
    SCOPED_TRACE(shift);
    const TwoViews views = Render(shift);
    std::string why;
    const auto detection = DetectBoard(views.first, views.board, {}, &why);
    ASSERT_TRUE(detection) << why;
    const auto tracked = TrackBoard(views.first, *detection, views.second, 0.8, &why);
    ASSERT_TRUE(tracked) << why;
    EXPECT_EQ(tracked->pixels.size(), detection->pixels.size());
    const auto observation = EstimateBoardPose(views.camera, *tracked, {}, &why);
    ASSERT_TRUE(observation) << why;
    const double moved =
        (observation->cam_from_board.translation() - views.pose.translation()).norm();
    EXPECT_NEAR(moved, shift, 0.002);
  }
  // Into an image without the board, the corners are not followed.
  const TwoViews views = Render(0.0);
  std::string why;
  const auto detection = DetectBoard(views.first, views.board, {}, &why);
  ASSERT_TRUE(detection);
  ImageU8 blank = views.first;
  std::fill(blank.data.begin(), blank.data.end(), 100);
  EXPECT_FALSE(TrackBoard(views.first, *detection, blank, 0.8, &why));
}

TEST(FitBoard, APresetFoundInsideALargerPrintIsNoFit) {
  const CameraModel camera = DefaultSimCamera(false);
  Pose pose = Pose::Identity();
  pose.translation() = Vec3(0.0, 0.0, 1.2);
  for (const char* printed : {"a3", "a4", "charuco-a3"}) {
    SCOPED_TRACE(printed);
    const ImageU8 image = RenderBoardImage(camera, BoardPreset(printed), pose, {});
    for (const char* preset : {"a3", "a4", "charuco-a3", "charuco-a4"}) {
      SCOPED_TRACE(preset);
      const BoardFit fit = FitBoard(image, BoardPreset(preset));
      if (std::string(preset) == printed) {
        EXPECT_EQ(fit, BoardFit::kFits);
      } else {
        EXPECT_NE(fit, BoardFit::kFits);
      }
    }
  }
}

}  // namespace
}  // namespace calibench
