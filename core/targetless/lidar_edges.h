// Edges a LiDAR sees without a target (docs/targetless.md "LiDAR edges"): depth discontinuities
// (the near side of a jump in range between neighbouring returns of one scan line) and
// reflectivity steps (paint, labels, a door against its wall), each placed between the two returns
// that bracket it, with the angular uncertainty that spacing leaves.
#pragma once

#include <string>
#include <vector>

#include "core/base/types.h"
#include "core/lidar/cloud.h"

namespace calibench {

struct LidarEdgeOptions {
  // A depth edge: the farther return lies beyond the nearer by both of these.
  double min_depth_jump_m = 0.3;
  double min_depth_jump_ratio = 0.08;  // of the nearer return's range
  // ... and, in inverse range, by this many times the larger step on either side of it: on a
  // plane seen at a grazing angle 1/range steps evenly, at a silhouette it jumps.
  double min_abruptness = 3.0;
  // A reflectivity edge: the mean intensity of the two returns after the step differs from the
  // two before by this fraction of the cloud's 98th-percentile intensity, on a surface without a
  // depth jump; only the strongest step of its neighbourhood is kept.
  double min_intensity_step = 0.25;
  double min_range_m = 1.0;   // nearer returns are the rig itself, its mount or a hand
  double max_range_m = 30.0;  // farther edges move less than a pixel per centimetre of error
  // Neighbours along a scan line further apart than this many times the line's median angular
  // step are a gap (no return between them), never an edge.
  double max_gap_steps = 2.5;
  bool depth_edges = true;      // use depth discontinuities
  bool intensity_edges = true;  // use reflectivity steps
  // Clouds without rings are cut into scan lines by elevation, this high (degrees).
  double line_height_deg = 0.3;

  bool Check(std::string* why) const;
};

enum class SceneEdgeKind { kDepth, kIntensity };

struct SceneEdgePoint {
  Vec3 point = Vec3::Zero();  // metres, LiDAR frame: between the two bracketing returns
  // 1σ of the edge's true direction between its two returns (radians): their angular step over
  // sqrt(12), as the edge lies anywhere between them; along `spread_direction` (unit, LiDAR
  // frame, across the ray: the azimuth's tangent along a scan line, the elevation's across lines).
  double angular_sigma_rad = 0.0;
  Vec3 spread_direction = Vec3::UnitY();
  SceneEdgeKind kind = SceneEdgeKind::kDepth;
};

// Edges of one cloud (LiDAR frame). Scan lines are the rings when the cloud has them, else bands
// of elevation; returns along a line are ordered by azimuth about the LiDAR's z axis. Depth edges
// are found along each line and between neighbouring lines (the top and bottom of objects);
// reflectivity edges along lines only (each laser's intensity scale is its own).
std::vector<SceneEdgePoint> ExtractLidarEdges(const LidarCloud& cloud,
                                              const LidarEdgeOptions& options);

}  // namespace calibench
