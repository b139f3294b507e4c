// The one ray caster for board returns (core/lidar/board_returns.h): what guidance predicts is
// what the simulator scans, ray for ray, for every LiDAR model and firing phase.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/base/types.h"
#include "core/board/board.h"
#include "core/lidar/board_returns.h"
#include "core/sim/sim.h"
#include "core/target/board_print.h"

namespace calibench {
namespace {

// A board facing the LiDAR from `centre` (LiDAR frame; x forward), turned by yaw about its
// vertical axis.
Pose FacingLidar(const Vec3& centre, double yaw_deg) {
  const Vec3 z = centre.normalized();
  const Vec3 x = Vec3::UnitZ().cross(z).normalized();
  Mat3 axes;
  axes << x, z.cross(x), z;
  Pose pose = Pose::Identity();
  pose.linear() = axes * Eigen::AngleAxisd(yaw_deg * kDegToRad, Vec3::UnitY()).toRotationMatrix();
  pose.translation() = centre;
  return pose;
}

std::vector<Vec3> Sorted(std::vector<Vec3> points) {
  std::sort(points.begin(), points.end(), [](const Vec3& a, const Vec3& b) {
    return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
  });
  return points;
}

TEST(BoardReturns, TheSimulatorScansWhatTheRayCasterPredicts) {
  const BoardSpec board = BoardPreset("a3");
  const BoardPrint print(board);
  const Vec2 half(0.5 * board.SheetWidth(), 0.5 * board.SheetHeight());
  int compared = 0;
  for (const LidarModel model : {LidarModel::kVlp16, LidarModel::kOs0_128, LidarModel::kSwept2d}) {
    const BeamTable beams = MakeBeamTable(model);
    for (const auto& [centre, yaw] :
         {std::pair{Vec3(2.0, 0.1, 0.0), 0.0}, std::pair{Vec3(1.2, -0.8, 0.1), 35.0},
          std::pair{Vec3(-2.5, 1.0, -0.2), -40.0}, std::pair{Vec3(-1.5, -0.02, 0.05), 10.0}}) {
      for (const double phase_steps : {0.0, 0.37}) {
        const double azimuth_offset = phase_steps * 2.0 * M_PI / beams.azimuth_steps;
        LidarScene scene;
        scene.lidar_from_board = FacingLidar(centre, yaw);
        scene.clutter = false;
        LidarScanOptions options;
        options.azimuth_offset_rad = azimuth_offset;
        const LidarScan scan = SimulateLidarScan(beams, print, scene, options);
        const BoardReturns cast =
            CastBoardReturns(beams, {scene.lidar_from_board, half}, azimuth_offset);
        SCOPED_TRACE(LidarModelName(model) + " at " + std::to_string(centre.x()) + ", " +
                     std::to_string(centre.y()) + " m, phase " + std::to_string(phase_steps));
        ASSERT_GT(scan.size(), 20u);
        ASSERT_EQ(cast.points.size(), scan.size());
        const std::vector<Vec3> a = Sorted(scan.points), b = Sorted(cast.points);
        for (size_t i = 0; i < a.size(); ++i) ASSERT_LT((a[i] - b[i]).norm(), 1e-12);
        // Every ring that crosses the sheet well inside the sweep leaves it twice.
        const int covered = BoardReturnsRule{}.RingsCovered(cast);
        EXPECT_GE(static_cast<int>(cast.edges.size()), 2 * covered);
        for (const LidarEdgePoint& edge : cast.edges) {
          const Vec3 local = scene.lidar_from_board.inverse() * edge.point;
          EXPECT_NEAR(local.z(), 0.0, 1e-9);  // on the plane
          // Within one gap of the sheet's border.
          const double outside =
              std::max(std::abs(local.x()) - half.x(), std::abs(local.y()) - half.y());
          EXPECT_LT(std::abs(outside), std::sqrt(12.0) * edge.sigma_along_m + 1e-9);
        }
        ++compared;
      }
    }
  }
  EXPECT_EQ(compared, 24);
}

TEST(BoardReturns, TheRuleSaysWhatIsMissing) {
  const BeamTable beams = MakeBeamTable(LidarModel::kVlp16);
  const Vec2 half(0.21, 0.15);
  const BoardReturns near = CastBoardReturns(beams, {FacingLidar(Vec3(1.5, 0, 0), 0), half});
  const BoardReturns far = CastBoardReturns(beams, {FacingLidar(Vec3(9.0, 0, 0), 0), half});
  const BoardReturnsRule rule;
  std::string why;
  EXPECT_TRUE(rule.Met(near, &why)) << why;
  EXPECT_GE(rule.RingsCovered(near), 5);  // VLP-16: 2° between rings; the sheet spans 11° at 1.5 m
  EXPECT_FALSE(rule.Met(far, &why));
  EXPECT_LT(rule.RingsCovered(far), 4);
  EXPECT_NE(why.find("under the 4 rings (of 3+ returns each) and 40 returns"), std::string::npos)
      << why;
  EXPECT_FALSE((BoardReturnsRule{0, 3, 40}.Check(&why)));
  EXPECT_NE(why.find("min_rings >= 1"), std::string::npos);
  // Behind the LiDAR's minimum range: nothing.
  EXPECT_TRUE(CastBoardReturns(beams, {FacingLidar(Vec3(0.2, 0, 0), 0), half}).points.empty());
}

}  // namespace
}  // namespace calibench
