// Guidance for a ring-less LiDAR (core/guidance/next_pose.h, LearnBeamTable): the rays of one of
// its own scans stand for the scanner, so a board is predicted to return what the scanner's rays
// of that integration would meet of it. Held against the simulator's own pattern fired at another
// phase (another capture), and through `advise` to a next pose a hand can hold.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "core/guidance/advise.h"
#include "core/guidance/next_pose.h"
#include "core/io/cloud_io.h"
#include "core/lidar/board_returns.h"
#include "core/lidar_camera/pipeline.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

SimOptions Livox(LidarModel model, double frame_s, int pairs) {
  SimOptions sim = SimPreset("default");
  sim.lidar = model;
  sim.lidar_frame_s = frame_s;
  sim.num_pairs = pairs;
  sim.seed = 7;
  return sim;
}

// A board (an A3 sheet) `distance_m` ahead of the LiDAR, turned `yaw_deg` about its vertical and
// tilted `pitch_deg`, its normal towards the LiDAR.
LidarRectangle SheetAhead(double distance_m, double yaw_deg, double pitch_deg, double aside_m) {
  LidarRectangle sheet;
  const double yaw = yaw_deg * M_PI / 180.0, pitch = pitch_deg * M_PI / 180.0;
  Mat3 facing;  // x along the sheet's width (LiDAR y), y up (LiDAR z), z towards the LiDAR (−x)
  facing << 0, 0, -1, 1, 0, 0, 0, 1, 0;
  sheet.lidar_from_rectangle = Pose::Identity();
  sheet.lidar_from_rectangle.linear() = Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix() *
                                        Eigen::AngleAxisd(pitch, Vec3::UnitY()).toRotationMatrix() *
                                        facing;
  sheet.lidar_from_rectangle.translation() = Vec3(distance_m, aside_m, 0.0);
  sheet.half_size_m = Vec2(0.21, 0.297);
  return sheet;
}

TEST(LearntRays, OneScansRaysPredictWhatTheScannersPatternReturnsOfABoard) {
  for (const LidarModel model : {LidarModel::kAvia, LidarModel::kMid360}) {
    SCOPED_TRACE(LidarModelName(model));
    const SimOptions sim = Livox(model, 0.5, 1);
    const auto dir = test::TempDir("learnt_rays_" + LidarModelName(model));
    const LidarCloud cloud = LoadCloud(SimulateDataset(sim, dir).pairs[0].cloud);
    ASSERT_FALSE(cloud.HasRing());
    const BeamTable learnt = LearnBeamTable({&cloud});
    ASSERT_TRUE(learnt.Fired());
    EXPECT_FALSE(learnt.HasRings());
    EXPECT_GT(learnt.rays->size(), cloud.size() * 9 / 10);  // every return a ray
    // The field: ahead is in it; straight up and down are outside either scanner's.
    EXPECT_TRUE(learnt.InField(Vec3(1, 0, 0)));
    EXPECT_FALSE(learnt.InField(Vec3(0, 0, 1)));
    EXPECT_FALSE(learnt.InField(Vec3(0, 0, -1)));

    // The scanner itself, its pattern fired for the same time from another start: another capture.
    BeamTable pattern = MakeBeamTable(model);
    pattern.frame_s = sim.lidar_frame_s;
    for (const double distance : {1.5, 2.5, 4.0}) {
      for (const double yaw : {0.0, 40.0}) {
        const LidarRectangle sheet = SheetAhead(distance, yaw, 20.0, 0.2);
        const int predicted = static_cast<int>(CastBoardReturns(learnt, sheet).points.size());
        const int scanned = static_cast<int>(CastBoardReturns(pattern, sheet, 2.1).points.size());
        std::printf("%s at %.1f m, turned %.0f deg: %d learnt, %d fired\n",
                    LidarModelName(model).c_str(), distance, yaw, predicted, scanned);
        ASSERT_GT(scanned, 40);
        // A rosette's density varies a little between integrations: within 15 %.
        EXPECT_NEAR(predicted, scanned, 0.15 * scanned) << distance << " m, " << yaw << " deg";
        // A sheet crossed by strokes: its border is crossed where consecutive rays leave it.
        EXPECT_FALSE(CastBoardReturns(learnt, sheet).edges.empty());
      }
    }
  }
}

TEST(LearntRays, BoardSegmentsAloneTeachNoRaysAndSaySo) {
  // A segment: a board's crop, no scene (core/lidar/lidar_geometry.h's kSegment).
  LidarCloud segment;
  for (int i = 0; i < 400; ++i)
    segment.points.emplace_back(2.0f, -0.2f + 0.001f * i, 0.1f * std::sin(0.05f * i));
  const BeamTable table = LearnBeamTable({&segment});
  EXPECT_FALSE(table.Fired());
  std::string why;
  PairFeatures accepted;
  accepted.status = PairStatus::kAccepted;
  accepted.lidar.emplace();
  accepted.camera.emplace();
  accepted.camera->cam_from_board.translation() = Vec3(0, 0, 2);
  EXPECT_FALSE(LearnSensorGeometry(CameraModel{}, BoardSpec{}, table, {accepted}, &why));
  EXPECT_NE(why.find("board segments only"), std::string::npos) << why;
}

// `advise` on a simulated Avia capture whose goal is not met: a next pose, where before a
// ring-less LiDAR got none; the returns it expects are the sheet's, with no rings.
TEST(LearntRays, AdviseSuggestsANextPoseForALivoxCapture) {
  const SimOptions sim = Livox(LidarModel::kAvia, 0.5, 6);
  const Dataset dataset = SimulateDataset(sim, test::TempDir("learnt_rays_advise"));
  AdviseOptions options;
  options.goal.translation_mm = 0.2;
  options.goal.rotation_deg = 0.005;
  const CaptureAdvice advice =
      AdviseCapture(dataset, CalibrateDataset(dataset, options.pipeline), options);
  ASSERT_TRUE(advice.state);
  EXPECT_FALSE(advice.state->done);
  ASSERT_TRUE(advice.next) << advice.next_failure;
  EXPECT_TRUE(advice.next->feasibility.feasible);
  EXPECT_EQ(advice.next->feasibility.rings, 0);
  EXPECT_GE(advice.next->feasibility.points, 40);
  EXPECT_NE(FormatCaptureAdvice(advice).find("returns on the sheet"), std::string::npos)
      << FormatCaptureAdvice(advice);
}

// Casting only the learnt rays near a sheet (their cells) gives what casting every ray gives: the
// same returns in the same order and the same crossings, wherever the sheet is — behind the
// LiDAR across the azimuth's wrap, overhead around the vertical, near, far, turned.
TEST(LearntRays, CastingTheRaysNearASheetGivesWhatCastingThemAllGives) {
  const SimOptions sim = Livox(LidarModel::kMid360, 0.5, 1);
  const LidarCloud cloud =
      LoadCloud(SimulateDataset(sim, test::TempDir("learnt_rays_near")).pairs[0].cloud);
  const BeamTable indexed = LearnBeamTable({&cloud});
  ASSERT_TRUE(indexed.ray_cells);
  BeamTable every = indexed;
  every.ray_cells.reset();  // no cells: every ray is cast
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<LidarRectangle> sheets;
  for (int k = 0; k < 150; ++k) {
    const double azimuth = (2 * unit(rng) - 1) * M_PI, elevation = (unit(rng) - 0.5) * 1.6;
    const double distance = 0.5 + 4.5 * unit(rng);
    LidarRectangle sheet;
    sheet.half_size_m = Vec2(0.21, 0.297);
    sheet.lidar_from_rectangle = Pose::Identity();
    sheet.lidar_from_rectangle.linear() =
        Eigen::AngleAxisd(2 * M_PI * unit(rng),
                          Vec3(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng)).normalized())
            .toRotationMatrix();
    sheet.lidar_from_rectangle.translation() =
        distance * Vec3(std::cos(elevation) * std::cos(azimuth),
                        std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
    sheets.push_back(sheet);
  }
  // Behind, straddling azimuth ±180°; overhead, around the vertical; facing, close.
  sheets.push_back(SheetAhead(-2.0, 0.0, 0.0, 0.0));
  LidarRectangle overhead = SheetAhead(1.0, 0.0, 0.0, 0.0);
  overhead.lidar_from_rectangle.translation() = Vec3(0.05, 0.0, 1.0);
  overhead.lidar_from_rectangle.linear() = Mat3::Identity();
  sheets.push_back(overhead);
  sheets.push_back(SheetAhead(0.6, 30.0, 10.0, 0.0));
  int seen = 0;
  for (size_t k = 0; k < sheets.size(); ++k) {
    const BoardReturns near = CastBoardReturns(indexed, sheets[k]);
    const BoardReturns all = CastBoardReturns(every, sheets[k]);
    ASSERT_EQ(near.points.size(), all.points.size()) << "sheet " << k;
    for (size_t i = 0; i < all.points.size(); ++i) ASSERT_EQ(near.points[i], all.points[i]);
    ASSERT_EQ(near.edges.size(), all.edges.size()) << "sheet " << k;
    for (size_t i = 0; i < all.edges.size(); ++i)
      ASSERT_EQ(near.edges[i].point, all.edges[i].point) << "sheet " << k;
    seen += all.points.empty() ? 0 : 1;
  }
  EXPECT_GT(seen, 60);  // most sheets return something: the comparison is not of empty sets
}

}  // namespace
}  // namespace calibench
