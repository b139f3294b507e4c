// The 3D view frames the selected pair (ViewTask::Frame, ui/lidar_camera/view_task.h): on open,
// on another pair, with F; a view the user turned stays. Also with a LiDAR whose x axis points
// away from the boards (returns behind it), where a view fixed along +x shows nothing.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>

#include "core/sim/sim.h"
#include "tests/test_support.h"
#include "tests/ui/ui_fixture.h"
#include "ui/lidar_camera/controller.h"

namespace calibench::ui {
namespace {

// A LiDAR mounted facing backwards: the default mount turned 180 degrees about its z axis, so
// that every board lies at x < 0 in the LiDAR frame.
std::filesystem::path BackwardsLidarDataset() {
  static const std::filesystem::path manifest = [] {
    SimOptions sim = SimPreset("demo");
    sim.num_pairs = 4;
    sim.seed = 3;
    sim.cam_from_lidar =
        DefaultCamFromLidar() * Pose(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()));
    const auto dir = test::TempDir("framing_backwards_" + std::to_string(getpid()));
    return SimulateDataset(sim, dir).manifest;
  }();
  return manifest;
}

Vec3 Target(const ViewState& view) {
  return Vec3(view.orbit_target[0], view.orbit_target[1], view.orbit_target[2]);
}

// The eye of the orbit camera (ui/widgets/orbit_camera.h: kZUp, the eye `distance` before the
// target along its forward direction).
Vec3 Eye(const ViewState& view) {
  const double c = std::cos(view.orbit_pitch_rad);
  const Vec3 forward(c * std::cos(view.orbit_yaw_rad), c * std::sin(view.orbit_yaw_rad),
                     -std::sin(view.orbit_pitch_rad));
  return Target(view) - view.orbit_distance_m * forward;
}

// Every inlier of the selected pair's board within the view's vertical field of view (0.9 rad:
// half-angle 0.45 about the line of sight), in front of the eye.
void ExpectBoardInView(const Snapshot& s) {
  ASSERT_TRUE(s.HasPair(s.selected));
  const PairView& pair = s.pairs.at(s.selected);
  ASSERT_TRUE(pair.lidar) << pair.lidar_failure;
  ASSERT_TRUE(pair.cloud);
  const Vec3 eye = Eye(s.view), sight = (Target(s.view) - eye).normalized();
  // The target is the board's centre (within a centimetre: the inliers' mean).
  EXPECT_LT((Target(s.view) - pair.lidar->inlier_centroid).norm(), 0.01);
  for (int i : pair.lidar->inliers) {
    const Vec3 to_point = pair.cloud->points[i].cast<double>() - eye;
    ASSERT_GT(to_point.dot(sight), 0.1) << "inlier " << i << " behind the eye";
    EXPECT_LT(std::acos(std::clamp(to_point.normalized().dot(sight), -1.0, 1.0)), 0.45)
        << "inlier " << i << " outside the view";
  }
}

TEST(ViewFraming, ALidarFacingAwayFromTheBoardsIsFramedOnTheSelectedBoard) {
  Controller controller;
  controller.OpenDataset(BackwardsLidarDataset(), test::TempDir("framing_open") / "s.json");
  const Snapshot s = Loaded(controller);
  ASSERT_EQ(s.pairs.size(), 4u);
  ASSERT_TRUE(s.pairs.at(0).lidar);
  EXPECT_LT(s.pairs.at(0).lidar->inlier_centroid.x(), -0.5);  // behind the LiDAR's x axis
  // The default view looks along +x about (1.5, 0, 0): the board is not in it.
  const ViewState fixed;
  EXPECT_GT(std::acos((s.pairs.at(0).lidar->inlier_centroid - Eye(fixed))
                          .normalized()
                          .dot((Target(fixed) - Eye(fixed)).normalized())),
            0.45);
  ExpectBoardInView(s);
  // Another pair: the view moves onto its board.
  controller.Apply(SelectPair{2});
  ExpectBoardInView(Loaded(controller));
}

TEST(ViewFraming, AViewTheUserTurnedStaysUntilFOrAnotherPair) {
  Controller controller;
  controller.OpenDataset(test::UiDataset(), test::TempDir("framing_turned") / "s.json");
  const Snapshot framed = Loaded(controller);
  ExpectBoardInView(framed);
  ViewState turned = framed.view;
  turned.orbit_yaw_rad += 1.0;
  turned.orbit_distance_m *= 3;
  controller.Apply(SetView{turned});
  controller.Apply(RunSolver{});  // publishes the pairs again: no reframing over the user's turn
  Snapshot s = Loaded(controller);
  ASSERT_TRUE(s.solver.result) << s.solver.failure;
  EXPECT_EQ(s.view.orbit_yaw_rad, turned.orbit_yaw_rad);
  EXPECT_EQ(s.view.orbit_distance_m, turned.orbit_distance_m);
  controller.Apply(FrameView{});
  s = Loaded(controller);
  ExpectBoardInView(s);
  EXPECT_NEAR(s.view.orbit_yaw_rad, framed.view.orbit_yaw_rad, 1e-12);
  EXPECT_NEAR(s.view.orbit_distance_m, framed.view.orbit_distance_m, 1e-12);
  // F recorded the view (no undo step); the reopened session shows it as it was.
  Controller reopened;
  reopened.OpenSession(s.session_path, /*save=*/false);
  const Snapshot again = Loaded(reopened);
  EXPECT_EQ(again.view.orbit_target, s.view.orbit_target);
  EXPECT_EQ(again.view.orbit_distance_m, s.view.orbit_distance_m);
  EXPECT_FALSE(again.can_undo);
}

}  // namespace
}  // namespace calibench::ui
