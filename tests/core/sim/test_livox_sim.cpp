// Issue 46 item 3: the simulator's Livox-class scanners (Risley-prism rosettes and the 360° kind)
// against their own patterns: where the rays go, how many returns a frame or a hold gives, that
// the clouds carry no rings, the sheet's border crossed by the rosette, and how the classifier
// reads their clouds (a scan from one centre, not a segment; a board crop still a segment).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/io/cloud_io.h"
#include "core/lidar/board_returns.h"
#include "core/lidar/lidar_geometry.h"
#include "core/lidar/risley_pattern.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

TEST(LivoxSim, RaysStayInTheirFieldAndFillIt) {
  for (const std::string name : {"mid40", "avia", "mid360"}) {
    SCOPED_TRACE(name);
    const RisleyPattern pattern = MakeRisleyPattern(name);
    const RisleyRays rays = FireRisleyPattern(pattern, 0.3, 0.1);
    ASSERT_EQ(rays.directions.size(), static_cast<size_t>(std::lround(0.1 * pattern.points_per_s)));
    int inside = 0;
    for (const Vec3& d : rays.directions) inside += InRisleyField(pattern, d);
    EXPECT_EQ(inside, static_cast<int>(rays.directions.size()));
    // Laser by laser (Avia 6, Mid-360 4), each in firing order, together the whole 0.1 s.
    ASSERT_EQ(rays.laser.size(), rays.directions.size());
    std::vector<int> per_laser(pattern.lasers, 0);
    for (size_t i = 0; i < rays.laser.size(); ++i) {
      ++per_laser.at(rays.laser[i]);
      if (i > 0 && rays.laser[i] == rays.laser[i - 1]) {
        EXPECT_GT(rays.time_offsets_s[i], rays.time_offsets_s[i - 1]);
      }
      if (i > 0) {
        EXPECT_GE(rays.laser[i], rays.laser[i - 1]);
      }
    }
    for (int count : per_laser) EXPECT_NEAR(count, rays.directions.size() / pattern.lasers, 1);
    EXPECT_NEAR(*std::max_element(rays.time_offsets_s.begin(), rays.time_offsets_s.end()), 0.1,
                2.0 / pattern.points_per_s);
  }
  EXPECT_EQ(MakeRisleyPattern("mid40").lasers, 1);
  EXPECT_EQ(MakeRisleyPattern("avia").lasers, 6);
  EXPECT_EQ(MakeRisleyPattern("mid360").lasers, 4);
  // Mid-40: a 38.4° circle; a direction 20° off the axis lies outside, 18° inside.
  const RisleyPattern mid40 = MakeRisleyPattern("mid40");
  EXPECT_FALSE(InRisleyField(mid40, Vec3(std::cos(20 * kDegToRad), std::sin(20 * kDegToRad), 0)));
  EXPECT_TRUE(InRisleyField(mid40, Vec3(std::cos(18 * kDegToRad), 0, std::sin(18 * kDegToRad))));
  EXPECT_FALSE(InRisleyField(mid40, Vec3(-1, 0, 0)));
  // Mid-360: everything around, elevations -7° to 52°.
  const RisleyPattern mid360 = MakeRisleyPattern("mid360");
  EXPECT_TRUE(InRisleyField(mid360, Vec3(-1, 0.2, 0)));
  EXPECT_FALSE(InRisleyField(mid360, Vec3(1, 0, -0.2)));  // -11°
  EXPECT_THROW(MakeRisleyPattern("hap"), std::invalid_argument);
}

// The rosette does not repeat: a tenth of a second later the rays fall elsewhere.
TEST(LivoxSim, FramesDoNotRepeat) {
  const RisleyPattern mid40 = MakeRisleyPattern("mid40");
  const RisleyRays first = FireRisleyPattern(mid40, 0.0, 0.1);
  const RisleyRays second = FireRisleyPattern(mid40, 0.1, 0.1);
  double apart = 0;
  for (size_t i = 0; i < first.directions.size(); ++i)
    apart += (first.directions[i] - second.directions[i]).norm() / first.directions.size();
  EXPECT_GT(apart * kRadToDeg, 5.0);  // the mean ray moved by degrees, not a repeat
}

// A board 2.5 m ahead of a Mid-40: tens of returns per frame, ten times as many over a 1 s hold,
// and the rosette's crossings of the sheet's border found as a ring's are.
TEST(LivoxSim, BoardReturnsGrowWithTheHoldAndCrossTheBorder) {
  LidarRectangle sheet;
  sheet.lidar_from_rectangle.translation() = Vec3(2.5, 0.1, 0.0);
  sheet.lidar_from_rectangle.linear() << 0, 0, -1, 1, 0, 0, 0, 1, 0;  // facing the sensor
  sheet.half_size_m = Vec2(0.21, 0.1485);                             // A3
  BeamTable frame = MakeBeamTable(LidarModel::kMid40);
  ASSERT_TRUE(frame.risley.has_value());
  EXPECT_FALSE(frame.HasRings());
  const BoardReturns one = CastBoardReturns(frame, sheet, 1.0);
  BeamTable hold = frame;
  hold.frame_s = 1.0;
  const BoardReturns many = CastBoardReturns(hold, sheet, 1.0);
  // The sheet covers (0.42 × 0.297) / 2.5² sr ≈ 0.0200 sr ≈ 65.5 deg² of the 1158 deg² circle:
  // about 5.7 % of the field, 560 of 10 k rays if the rosette were uniform (it is denser at
  // the centre and the rim).
  std::printf(
      "Mid-40 board at 2.5 m: %zu returns in 0.1 s, %zu in 1 s, %zu and %zu border "
      "crossings\n",
      one.points.size(), many.points.size(), one.edges.size(), many.edges.size());
  EXPECT_GT(one.points.size(), 200u);
  EXPECT_NEAR(double(many.points.size()) / one.points.size(), 10.0, 3.0);
  EXPECT_GT(one.edges.size(), 10u);
  for (const LidarEdgePoint& edge : one.edges) {
    // On the border: |x| = half width or |y| = half height in the sheet's axes, within the gap.
    const Vec3 local = sheet.lidar_from_rectangle.inverse() * edge.point;
    const double to_border =
        std::min(std::abs(std::abs(local.x()) - 0.21), std::abs(std::abs(local.y()) - 0.1485));
    EXPECT_LT(to_border, 2.0 * std::sqrt(12.0) * edge.sigma_along_m + 1e-6);
  }
}

SimOptions Livox(LidarModel model, double frame_s) {
  SimOptions sim = SimPreset("default");
  sim.lidar = model;
  sim.lidar_frame_s = frame_s;
  sim.num_pairs = 2;
  sim.min_distance_m = 2.0;
  sim.max_distance_m = 5.0;
  sim.lidar_range_noise_m = 0.02;
  return sim;
}

TEST(LivoxSim, DatasetsHoldRinglessScansFromOneCentre) {
  const fs::path dir = test::TempDir("livox_sim");
  for (const auto& [model, frame_s] :
       {std::pair{LidarModel::kMid40, 0.1}, std::pair{LidarModel::kMid40, 1.0},
        std::pair{LidarModel::kAvia, 0.1}, std::pair{LidarModel::kMid360, 0.1}}) {
    const std::string name = LidarModelName(model) + "_" + std::to_string(int(frame_s * 10));
    SCOPED_TRACE(name);
    const Dataset dataset = SimulateDataset(Livox(model, frame_s), dir / name);
    EXPECT_EQ(dataset.lidar_rings, 0);
    ASSERT_TRUE(dataset.simulation.has_value());
    EXPECT_EQ(dataset.simulation->lidar_model, LidarModelName(model));
    EXPECT_DOUBLE_EQ(dataset.simulation->lidar_frame_s, frame_s);
    // The record round-trips: the bound is computed for the same frame.
    EXPECT_DOUBLE_EQ(SimOptionsFromDataset(LoadDataset(dataset.manifest)).lidar_frame_s, frame_s);
    const LidarCloud cloud = LoadCloud(dataset.pairs[0].cloud);
    EXPECT_FALSE(cloud.HasRing());
    const RisleyPattern pattern = MakeRisleyPattern(LidarModelName(model));
    // In a closed room nearly every ray returns (the Mid-360's upward rays can miss the walls
    // within its 40 m only when they leave through the open ceiling).
    const double fired = frame_s * pattern.points_per_s;
    EXPECT_LE(cloud.size(), fired);
    EXPECT_GT(cloud.size(), (pattern.spinning ? 0.3 : 0.9) * fired);
    const LidarGeometryVerdict verdict = ClassifyLidarGeometry(cloud);
    EXPECT_EQ(verdict.geometry, LidarGeometry::kNonRepetitive) << verdict.why;
    EXPECT_EQ(verdict.why.find("segment"), std::string::npos) << verdict.why;
  }
  // Cropped to the board, the same scanner's cloud is a segment.
  SimOptions crop = Livox(LidarModel::kMid40, 0.1);
  crop.board_only_clouds = true;
  const LidarGeometryVerdict segment =
      ClassifyLidarGeometry(LoadCloud(SimulateDataset(crop, dir / "crop").pairs[0].cloud));
  EXPECT_EQ(segment.geometry, LidarGeometry::kSegment) << segment.why;
}

}  // namespace
}  // namespace calibench
