// The simulator's LiDAR scan (core/sim/sim.h): the rays and the sheet's hits of the one ray
// caster (core/lidar/board_returns.h), with the panels, the room, noise and intensities on top.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <random>

#include "core/base/names.h"
#include "core/lidar/board_returns.h"
#include "core/sim/sim.h"

namespace calibench {
namespace {

// Return intensities (0..255): retro-reflective-free paper and ink, painted walls, concrete floor.
constexpr double kPaperIntensity = 200.0;
constexpr double kInkIntensity = 20.0;
constexpr double kWallIntensity = 90.0;
constexpr double kFloorIntensity = 60.0;
constexpr double kIntensityNoise = 3.0;

// The nearest hit of one ray.
struct RayHit {
  double range = std::numeric_limits<double>::infinity();
  SimSurface surface = SimSurface::kWall;
  Vec2 board_xy = Vec2::Zero();
};

// A rectangle (the sheet, a panel) hit nearer than anything so far.
void IntersectRectangle(const BeamRay& ray, const LidarRectangle& rectangle, SimSurface surface,
                        RayHit* hit) {
  const auto at = HitRectangle(ray, rectangle);
  if (at && at->inside && at->range_m < hit->range)
    *hit = RayHit{at->range_m, surface, surface == SimSurface::kBoard ? at->xy : Vec2::Zero()};
}

// The room: floor z = floor_z (below the sensor) and walls |x| = d, |y| = d around it.
void IntersectRoom(const BeamRay& ray, const LidarScene& scene, RayHit* hit) {
  const double d = scene.wall_distance_m;
  const Vec3& dir = ray.direction;
  const Vec3& o = ray.origin;
  double wall = std::numeric_limits<double>::infinity();
  if (dir.x() != 0.0)
    wall = std::min(wall, (d - std::copysign(o.x(), dir.x())) / std::abs(dir.x()));
  if (dir.y() != 0.0)
    wall = std::min(wall, (d - std::copysign(o.y(), dir.y())) / std::abs(dir.y()));
  if (wall < hit->range) *hit = RayHit{wall, SimSurface::kWall, Vec2::Zero()};
  if (dir.z() < 0.0) {
    const double floor = (scene.floor_z_m - o.z()) / dir.z();
    if (floor > 0.0 && floor < hit->range) *hit = RayHit{floor, SimSurface::kFloor, Vec2::Zero()};
  }
}

double SurfaceIntensity(const RayHit& hit, const BoardPrint& print) {
  switch (hit.surface) {
    case SimSurface::kBoard:
      return kInkIntensity + (kPaperIntensity - kInkIntensity) * print.Reflectance(hit.board_xy);
    case SimSurface::kFloor:
      return kFloorIntensity;
    case SimSurface::kWall:
      return kWallIntensity;
  }
  return kWallIntensity;
}

// The nearest return the sensor reports (metres).
double MinRangeM(const BeamTable& beams) {
  return beams.risley ? std::max(kLidarMinRangeM, beams.risley->min_range_m) : kLidarMinRangeM;
}

}  // namespace

LidarCloud LidarScan::ToCloud(bool board_only, bool viewpoints) const {
  LidarCloud cloud;
  for (size_t i = 0; i < points.size(); ++i) {
    if (board_only && surface[i] != SimSurface::kBoard) continue;
    cloud.points.push_back(points[i].cast<float>());
    cloud.intensity.push_back(intensity[i]);
    if (has_rings && !board_only) cloud.ring.push_back(ring[i]);
    if (viewpoints) cloud.viewpoint.push_back(origin[i].cast<float>());
    if (!time_s.empty()) cloud.time_s.push_back(time_s[i]);
  }
  cloud.width = static_cast<int>(cloud.size());
  cloud.height = 1;
  return cloud;
}

namespace {

// `ray` turned by a Gaussian angle of `sigma_rad` about each of two axes across it.
BeamRay JitterRay(const BeamRay& ray, double sigma_rad,
                  std::normal_distribution<double>& unit_normal, std::mt19937_64& rng) {
  const Vec3 across_1 = ray.direction.unitOrthogonal();
  const Vec3 across_2 = ray.direction.cross(across_1);
  BeamRay jittered = ray;
  const double a = sigma_rad * unit_normal(rng);
  const double b = sigma_rad * unit_normal(rng);
  jittered.direction =
      (ray.direction + std::tan(a) * across_1 + std::tan(b) * across_2).normalized();
  return jittered;
}

}  // namespace

LidarScan SimulateLidarScan(const BeamTable& beams, const BoardPrint& print,
                            const LidarScene& scene, const LidarScanOptions& options) {
  CALIBENCH_CHECK(beams.risley || (beams.azimuth_steps > 0 && !beams.elevations_rad.empty()));
  CALIBENCH_CHECK(options.range_noise_m >= 0.0);
  // The sheet as the print has it (centred on the pattern), the panels as they stand.
  const Vec2 half_sheet = 0.5 * Vec2(print.board().SheetWidth(), print.board().SheetHeight());
  LidarRectangle sheet{scene.lidar_from_board, half_sheet};
  std::vector<LidarRectangle> panels;
  for (const ScenePanel& panel : scene.panels)
    panels.push_back({panel.lidar_from_panel, panel.size_m / 2});
  const BeamRays rays(beams, options.azimuth_offset_rad);
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> unit_normal(0.0, 1.0);
  LidarScan scan;
  scan.has_rings = beams.HasRings();
  CALIBENCH_CHECK(!scene.lidar_from_board_at || options.sweep_s > 0.0);
  for (int step = 0; step < rays.steps(); ++step) {
    const double step_s = options.sweep_s * rays.FiredFraction(step);
    if (scene.lidar_from_board_at) sheet = {scene.lidar_from_board_at(step_s), half_sheet};
    for (int r = 0; r < rays.rings(); ++r) {
      const BeamRay ray = rays.Ray(r, step);
      const BeamRay cast = options.angular_noise_rad > 0.0
                               ? JitterRay(ray, options.angular_noise_rad, unit_normal, rng)
                               : ray;
      RayHit hit;
      hit.range = beams.max_range_m;
      IntersectRectangle(cast, sheet, SimSurface::kBoard, &hit);
      for (const LidarRectangle& panel : panels)
        IntersectRectangle(cast, panel, SimSurface::kWall, &hit);
      if (scene.clutter) IntersectRoom(cast, scene, &hit);
      if (hit.range >= beams.max_range_m || hit.range < MinRangeM(beams)) continue;
      double range = hit.range + options.range_offset_m;
      if (options.range_noise_m > 0.0) range += options.range_noise_m * unit_normal(rng);
      const double intensity = SurfaceIntensity(hit, print) + kIntensityNoise * unit_normal(rng);
      scan.points.push_back(ray.origin + range * ray.direction);
      scan.intensity.push_back(static_cast<float>(std::clamp(intensity, 0.0, 255.0)));
      scan.ring.push_back(r);
      scan.surface.push_back(hit.surface);
      scan.origin.push_back(ray.origin);
      if (options.sweep_s > 0.0) scan.time_s.push_back(static_cast<float>(step_s));
    }
  }
  return scan;
}

}  // namespace calibench
