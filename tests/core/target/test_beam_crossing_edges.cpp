// Board edges of a ring-less scan (issue 46 item 3): a Livox-class rosette stored in firing order
// crosses the sheet's border hundreds of times in a hold, each crossing an edge point like a
// ring's end. Ground truth: a sheet scanned by the Mid-40's rosette before a wall, with range
// noise; the crossings must lie on the sheet's border within their stated σ, also when the rays
// start off the origin (a nodding fan's mirror), and a cloud whose order was lost gives none and
// says why.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "core/lidar/beam_table.h"
#include "core/lidar/board_returns.h"
#include "core/lidar/risley_pattern.h"
#include "core/target/board_edges.h"

namespace calibench {
namespace {

struct ScannedSheet {
  LidarCloud cloud;
  std::vector<int> on_sheet;  // indices of the sheet's returns
  LidarRectangle sheet;
  Plane plane;
};

// One second of a Mid-40 at an A3 sheet 2.5 m ahead, turned 30° about its vertical axis, before a
// wall at 5 m; 2 cm range noise; every ray starting at `ray_origin`.
ScannedSheet ScanSheet(const Vec3& ray_origin) {
  ScannedSheet scan;
  scan.sheet.half_size_m = Vec2(0.21, 0.1485);
  Mat3 facing;
  facing << 0, 0, -1, 1, 0, 0, 0, 1, 0;  // the sheet's normal towards the sensor
  scan.sheet.lidar_from_rectangle.linear() =
      Eigen::AngleAxisd(30.0 * kDegToRad, Vec3::UnitZ()).toRotationMatrix() * facing;
  scan.sheet.lidar_from_rectangle.translation() = Vec3(2.5, 0.1, 0.05);
  const Vec3 normal = scan.sheet.lidar_from_rectangle.linear().col(2);
  scan.plane = {normal, -normal.dot(scan.sheet.lidar_from_rectangle.translation())};
  LidarRectangle wall;
  wall.lidar_from_rectangle.linear() = facing;
  wall.lidar_from_rectangle.translation() = Vec3(5.0, 0.0, 0.0);
  wall.half_size_m = Vec2(50.0, 50.0);
  const RisleyRays rays = FireRisleyPattern(MakeRisleyPattern("mid40"), 0.0, 1.0);
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.02);
  for (const Vec3& direction : rays.directions) {
    const BeamRay ray{ray_origin, direction};
    const auto on_sheet = HitRectangle(ray, scan.sheet);
    const bool sheet_hit = on_sheet && on_sheet->inside;
    const auto on_wall = HitRectangle(ray, wall);
    if (!sheet_hit && !(on_wall && on_wall->inside)) continue;
    const double range = (sheet_hit ? on_sheet->range_m : on_wall->range_m) + noise(rng);
    if (sheet_hit) scan.on_sheet.push_back(static_cast<int>(scan.cloud.points.size()));
    scan.cloud.points.push_back((ray_origin + range * direction).cast<float>());
  }
  scan.cloud.width = static_cast<int>(scan.cloud.points.size());
  return scan;
}

// Distance in the sheet's plane from an edge point to the sheet's border.
double ToBorder(const ScannedSheet& scan, const LidarEdgePoint& edge) {
  const Vec3 local = scan.sheet.lidar_from_rectangle.inverse() * edge.point;
  return std::min(std::abs(std::abs(local.x()) - scan.sheet.half_size_m.x()),
                  std::abs(std::abs(local.y()) - scan.sheet.half_size_m.y()));
}

void ExpectCrossingsOnTheBorder(const ScannedSheet& scan, const char* what) {
  BoardEdgeEnds ends;
  std::string no_search;
  const std::vector<LidarEdgePoint> edges = ExtractBeamCrossingEdgePoints(
      scan.cloud, scan.on_sheet, scan.plane, BoardEdgeOptions{}, &ends, &no_search);
  EXPECT_TRUE(no_search.empty()) << no_search;
  double sum_sq = 0.0, sum_sigma_sq = 0.0;
  for (const LidarEdgePoint& edge : edges) {
    const double d = ToBorder(scan, edge);
    sum_sq += d * d;
    sum_sigma_sq += edge.sigma_along_m * edge.sigma_along_m;
    // Uniform within its gap: never further than the gap (√12 σ) plus the plane's own noise.
    EXPECT_LT(d, std::sqrt(12.0) * edge.sigma_along_m + 0.004) << what;
  }
  const double rms_mm = 1e3 * std::sqrt(sum_sq / edges.size());
  const double sigma_mm = 1e3 * std::sqrt(sum_sigma_sq / edges.size());
  std::printf("%s: %zu crossings of %d run ends, %.2f mm RMS from the border (σ %.2f mm)\n", what,
              edges.size(), ends.ends, rms_mm, sigma_mm);
  EXPECT_GT(edges.size(), 200u) << what;  // a second's rosette crosses the border hundreds of times
  EXPECT_EQ(ends.edge_points, static_cast<int>(edges.size()));
  // The distance to the border mixes the crossing's spread along the stroke with where the
  // stroke meets the border at a slant: under twice the stated σ.
  EXPECT_LT(rms_mm, 2.0 * sigma_mm + 1.0) << what;
}

TEST(BeamCrossingEdges, ARosetteCrossesTheSheetsBorderWhereItIs) {
  ExpectCrossingsOnTheBorder(ScanSheet(Vec3::Zero()), "rays from the origin");
}

// A ray origin off the centre (4 cm, as a nodding scanner's mirror): the return beyond the board
// carried back onto the plane along a ray from the origin would move by centimetres; the crossing
// is taken along the stroke from the board's own returns instead.
TEST(BeamCrossingEdges, RaysFromOffTheOriginStillCrossWhereTheBorderIs) {
  ExpectCrossingsOnTheBorder(ScanSheet(Vec3(0.03, 0.0, 0.04)), "rays from 5 cm off the origin");
}

TEST(BeamCrossingEdges, ACloudThatLostItsFiringOrderGivesNoneAndSaysWhy) {
  ScannedSheet scan = ScanSheet(Vec3::Zero());
  // Sorted by x, as a filter or a voxel grid would leave it: the beam's path is gone.
  std::vector<int> order(scan.cloud.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return scan.cloud.points[a].x() < scan.cloud.points[b].x(); });
  LidarCloud sorted;
  std::vector<int> position(order.size());
  for (size_t k = 0; k < order.size(); ++k) {
    sorted.points.push_back(scan.cloud.points[order[k]]);
    position[order[k]] = static_cast<int>(k);
  }
  std::vector<int> on_sheet;
  for (int i : scan.on_sheet) on_sheet.push_back(position[i]);
  BoardEdgeEnds ends;
  std::string no_search;
  const std::vector<LidarEdgePoint> edges = ExtractBeamCrossingEdgePoints(
      sorted, on_sheet, scan.plane, BoardEdgeOptions{}, &ends, &no_search);
  EXPECT_TRUE(edges.empty());
  EXPECT_NE(no_search.find("not stored in firing order"), std::string::npos) << no_search;
}

TEST(BeamCrossingEdges, OptionsAreChecked) {
  BoardEdgeOptions options;
  std::string why;
  EXPECT_TRUE(options.Check(&why)) << why;
  options.max_median_firing_step_deg = 0;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("max_median_firing_step_deg"), std::string::npos);
  options = BoardEdgeOptions{};
  options.firing_step_over_median = 0.5;  // a step limit below the beam's own median step
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("firing_step_over_median"), std::string::npos);
}

}  // namespace
}  // namespace calibench
