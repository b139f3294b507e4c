// The ray caster of the simulator (core/sim/sim.h; the beam tables: core/lidar/beam_table.h).
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <random>

#include "core/base/names.h"
#include "core/sim/sim.h"

namespace calibench {
namespace {

constexpr double kMinRangeM = 0.3;  // closer returns are suppressed, as real sensors do

// Return intensities (0..255): retro-reflective-free paper and ink, painted walls, concrete floor.
constexpr double kPaperIntensity = 200.0;
constexpr double kInkIntensity = 20.0;
constexpr double kWallIntensity = 90.0;
constexpr double kFloorIntensity = 60.0;
constexpr double kIntensityNoise = 3.0;

// The nearest hit of one ray from the LiDAR origin.
struct RayHit {
  double range = std::numeric_limits<double>::infinity();
  SimSurface surface = SimSurface::kWall;
  Vec2 board_xy = Vec2::Zero();
};

// The board sheet as a plane n·x = offset with in-plane axes, all in the LiDAR frame.
struct BoardGeometry {
  Vec3 normal, axis_x, axis_y, origin;
  double offset = 0.0;
};

BoardGeometry MakeBoardGeometry(const Pose& lidar_from_board) {
  BoardGeometry g;
  g.axis_x = lidar_from_board.linear().col(0);
  g.axis_y = lidar_from_board.linear().col(1);
  g.normal = lidar_from_board.linear().col(2);
  g.origin = lidar_from_board.translation();
  g.offset = g.normal.dot(g.origin);
  return g;
}

// A ray: where it starts (the LiDAR origin, or a swept scanner's mirror) and its unit direction.
struct Ray {
  Vec3 origin = Vec3::Zero();
  Vec3 dir = Vec3::UnitX();
};

// Where a ray meets a rectangle's plane nearer than `nearer_than`: its range and the point in
// the rectangle's axes; nullopt when parallel, behind or farther.
struct PlaneHit {
  double range;
  Vec2 xy;
};
std::optional<PlaneHit> HitPlane(const Ray& ray, const BoardGeometry& g, double nearer_than) {
  const double denom = g.normal.dot(ray.dir);
  if (std::abs(denom) < 1e-12) return std::nullopt;
  const double range = (g.offset - g.normal.dot(ray.origin)) / denom;
  if (range <= 0.0 || range >= nearer_than) return std::nullopt;
  const Vec3 local = ray.origin + range * ray.dir - g.origin;
  return PlaneHit{range, Vec2(g.axis_x.dot(local), g.axis_y.dot(local))};
}

void IntersectBoard(const Ray& ray, const BoardGeometry& g, const BoardPrint& print, RayHit* hit) {
  const auto at = HitPlane(ray, g, hit->range);
  if (at && print.InSheet(at->xy)) *hit = RayHit{at->range, SimSurface::kBoard, at->xy};
}

// A panel: its geometry (once per scan) and half extent.
struct PanelGeometry {
  BoardGeometry plane;
  Vec2 half_size;
};

void IntersectPanel(const Ray& ray, const PanelGeometry& panel, RayHit* hit) {
  const auto at = HitPlane(ray, panel.plane, hit->range);
  if (at && std::abs(at->xy.x()) <= panel.half_size.x() &&
      std::abs(at->xy.y()) <= panel.half_size.y())
    *hit = RayHit{at->range, SimSurface::kWall, Vec2::Zero()};
}

// The room: floor z = floor_z (below the sensor) and walls |x| = d, |y| = d around it.
void IntersectRoom(const Ray& ray, const LidarScene& scene, RayHit* hit) {
  const double d = scene.wall_distance_m;
  const Vec3& dir = ray.dir;
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

}  // namespace

LidarCloud LidarScan::ToCloud(bool board_only) const {
  LidarCloud cloud;
  for (size_t i = 0; i < points.size(); ++i) {
    if (board_only && surface[i] != SimSurface::kBoard) continue;
    cloud.points.push_back(points[i].cast<float>());
    cloud.intensity.push_back(intensity[i]);
    if (has_rings && !board_only) cloud.ring.push_back(ring[i]);
  }
  cloud.width = static_cast<int>(cloud.size());
  cloud.height = 1;
  return cloud;
}

LidarScan SimulateLidarScan(const BeamTable& beams, const BoardPrint& print,
                            const LidarScene& scene, const LidarScanOptions& options) {
  CALIBENCH_CHECK(beams.azimuth_steps > 0 && !beams.elevations_rad.empty());
  CALIBENCH_CHECK(options.range_noise_m >= 0.0);
  const BoardGeometry board = MakeBoardGeometry(scene.lidar_from_board);
  std::vector<PanelGeometry> panels;
  for (const ScenePanel& panel : scene.panels)
    panels.push_back({MakeBoardGeometry(panel.lidar_from_panel), panel.size_m / 2});
  const int rings = static_cast<int>(beams.elevations_rad.size());
  std::vector<double> cos_el(rings), sin_el(rings);
  for (int r = 0; r < rings; ++r) {
    cos_el[r] = std::cos(beams.elevations_rad[r]);
    sin_el[r] = std::sin(beams.elevations_rad[r]);
  }
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> unit_normal(0.0, 1.0);
  LidarScan scan;
  scan.has_rings = !beams.swept;
  for (int step = 0; step < beams.azimuth_steps; ++step) {
    const double azimuth = options.azimuth_offset_rad + 2.0 * M_PI * step / beams.azimuth_steps;
    const double cos_az = std::cos(azimuth), sin_az = std::sin(azimuth);
    // A swept scanner's rays start on its mirror, which the stage turns with the scan plane.
    const Vec3& m = beams.mirror_offset_m;
    const Vec3 origin(cos_az * m.x() - sin_az * m.y(), sin_az * m.x() + cos_az * m.y(), m.z());
    for (int r = 0; r < rings; ++r) {
      const Ray ray{origin, Vec3(cos_el[r] * cos_az, cos_el[r] * sin_az, sin_el[r])};
      const Vec3& dir = ray.dir;
      RayHit hit;
      hit.range = beams.max_range_m;
      IntersectBoard(ray, board, print, &hit);
      for (const PanelGeometry& panel : panels) IntersectPanel(ray, panel, &hit);
      if (scene.clutter) IntersectRoom(ray, scene, &hit);
      if (hit.range >= beams.max_range_m || hit.range < kMinRangeM) continue;
      double range = hit.range + options.range_offset_m;
      if (options.range_noise_m > 0.0) range += options.range_noise_m * unit_normal(rng);
      const double intensity = SurfaceIntensity(hit, print) + kIntensityNoise * unit_normal(rng);
      scan.points.push_back(origin + range * dir);
      scan.intensity.push_back(static_cast<float>(std::clamp(intensity, 0.0, 255.0)));
      scan.ring.push_back(r);
      scan.surface.push_back(hit.surface);
    }
  }
  return scan;
}

}  // namespace calibench
