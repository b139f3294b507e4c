// The workbench controller on the real VLP-16 + fisheye recording: it opens, a brush stroke on the
// LiDAR image finds the board, the solve lands near the authors' reference, and the selected pair
// is reprojected with hidden points removed.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "tests/acfr_manifest.h"
#include "tests/test_support.h"
#include "ui/lidar_camera/controller.h"

namespace calibench::ui {
namespace {

TEST(RealWorkbench, OpensBrushesSolvesAndReprojects) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const auto dir = test::TempDir("real_workbench");
  const auto manifest = test::WriteAcfrManifest(shared / "datasets/acfr-vlp16-chessboard", dir);
  Controller controller;
  controller.OpenDataset(manifest, dir / "session.json");
  controller.WaitIdle();
  Snapshot s = controller.GetSnapshot();
  ASSERT_EQ(s.pairs.size(), 40u);
  int index = -1;
  for (size_t i = 0; i < s.pairs.size(); ++i)
    if (s.pairs[i].id == "pose16") index = static_cast<int>(i);
  ASSERT_GE(index, 0);
  const PairView seeded = s.pairs[index];
  ASSERT_TRUE(seeded.lidar) << seeded.lidar_failure;
  ASSERT_TRUE(seeded.camera) << seeded.camera_failure;

  // Brush the board by hand: clear the seeded region, paint a disc on the board.
  const int board_pixel =
      seeded.lidar_image->pixel_of_point[seeded.lidar->inliers[seeded.lidar->inliers.size() / 2]];
  const int columns = seeded.lidar_image->columns;
  controller.Apply(SelectPair{index});
  controller.Apply(ClearBrush{index});
  // A VLP-16 image row is 2 degrees, a column 0.2: a user drags a small brush sideways across the
  // board rather than stamping one disc that would reach rings above and below it.
  for (int dc = -20; dc <= 20; dc += 4)
    controller.Apply(BrushStroke{index, board_pixel / columns,
                                 (board_pixel % columns + dc + columns) % columns, 2.0f, false});
  controller.WaitIdle();
  s = controller.GetSnapshot();
  ASSERT_TRUE(s.pairs[index].lidar) << s.pairs[index].lidar_failure;
  EXPECT_LT(
      std::acos(std::min(1.0, s.pairs[index].lidar->plane.normal.dot(seeded.lidar->plane.normal))),
      3.0 * M_PI / 180);
  EXPECT_NEAR(s.pairs[index].lidar->plane.distance, seeded.lidar->plane.distance, 0.05);

  controller.Apply(RunSolver{});
  controller.WaitIdle();
  s = controller.GetSnapshot();
  ASSERT_TRUE(s.solver.result) << s.solver.failure;
  test::ExpectNearAcfrReference(s.solver.result->cam_from_lidar, "workbench on the real set");
  ASSERT_TRUE(s.reprojection);
  EXPECT_EQ(s.reprojection->pair_id, "pose16");
  size_t visible = 0;
  for (bool v : s.reprojection->visible) visible += v;
  EXPECT_GT(visible, 1000u);
  EXPECT_LT(visible, s.reprojection->points.size());  // HPR hides something in a cluttered lab
}

// A new user on the real set, with the window's auto-solve: a pair rejected with `r` and ctrl+z
// pressed while the rejection's own solve runs, and again with ctrl+z right behind the `r`. Both
// times the workbench ends where it started: the pair accepted, the solve over every usable pair
// standing bit for bit, the session file saying the same.
TEST(RealWorkbench, AnUndoWhileTheRejectionsSolveRunsEndsWhereItStarted) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const auto dir = test::TempDir("real_workbench_undo_race");
  const auto manifest = test::WriteAcfrManifest(shared / "datasets/acfr-vlp16-chessboard", dir);
  Controller controller;
  controller.SetAutoSolve(true);
  controller.OpenDataset(manifest, dir / "session.json");
  controller.WaitIdle();
  const Snapshot start = controller.GetSnapshot();
  ASSERT_TRUE(start.solver.result) << start.solver.failure;
  const size_t usable = start.solver.solved_pair_ids.size();
  ASSERT_GE(usable, 20u);
  const std::string& rejected_id = start.solver.solved_pair_ids[usable / 2];
  int index = -1;
  for (size_t i = 0; i < start.pairs.size(); ++i)
    if (start.pairs[i].id == rejected_id) index = static_cast<int>(i);
  ASSERT_GE(index, 0);

  for (const bool wait_for_the_solve : {true, false}) {
    SCOPED_TRACE(wait_for_the_solve ? "ctrl+z while the solve runs" : "ctrl+z right after r");
    controller.Apply(SetPairStatus{index, PairStatus::kRejected});
    bool saw_it_running = false;
    if (wait_for_the_solve) {
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
      while (!saw_it_running && std::chrono::steady_clock::now() < deadline) {
        saw_it_running = controller.GetSnapshot().solver.running;
        if (!saw_it_running) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
      ASSERT_TRUE(saw_it_running) << "the rejection's solve never started";
    }
    controller.Apply(Undo{});
    controller.WaitIdle();
    const Snapshot s = controller.GetSnapshot();
    EXPECT_EQ(s.pairs[index].status, PairStatus::kAccepted);
    ASSERT_TRUE(s.solver.result) << s.solver.failure;
    // Every usable pair has its residual at the solution shown (a restored solve's are computed
    // at it, over the pairs accepted now).
    size_t with_residual = 0;
    for (const PairView& pair : s.pairs) with_residual += pair.residual.has_value();
    EXPECT_EQ(with_residual, usable);
    EXPECT_EQ(s.solver.result->cam_from_lidar.matrix(),
              start.solver.result->cam_from_lidar.matrix());
    EXPECT_FALSE(s.solver.running);
    const Session saved = LoadSession(dir / "session.json");
    EXPECT_EQ(saved.pairs[index].status, PairStatus::kAccepted);
    ASSERT_TRUE(saved.result);
    EXPECT_EQ(saved.result->cam_from_lidar.matrix(), start.solver.result->cam_from_lidar.matrix());
    // Redo brings the rejection back, with a solve of its own over one pair fewer.
    controller.Apply(Redo{});
    controller.WaitIdle();
    const Snapshot redone = controller.GetSnapshot();
    EXPECT_EQ(redone.pairs[index].status, PairStatus::kRejected);
    controller.Apply(Undo{});
    controller.WaitIdle();
    EXPECT_EQ(controller.GetSnapshot().pairs[index].status, PairStatus::kAccepted);
  }
}

}  // namespace
}  // namespace calibench::ui
