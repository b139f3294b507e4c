// Where a swept scanner's rays start, estimated from its cloud (docs/architecture.md, "A ray's
// origin is given, never assumed"). A line scanner on a rotary stage fires a fan from a mirror
// that the stage turns about its axis (the LiDAR frame's z): each scan line lies in the
// half-plane at its azimuth, and in that half-plane (distance ρ from the axis, height z) every
// line starts at the same point, the mirror (ρ_m, z_m). Seen from there the fan's beams leave at
// a few discrete angles, whatever the range; seen from anywhere else each beam's returns smear
// over angles with the range (what ClassifyLidarGeometry reads as "rays that do not meet at the
// origin"). The estimate is the point from which the returns' angles are sharpest, searched
// coarse to fine. Range noise does not blur it: it moves a return along its own ray.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/lidar/cloud.h"

namespace calibench {

struct SweptOriginOptions {
  double search_m = 0.25;       // |ρ_m|, |z_m| searched up to this (metres)
  double coarse_step_m = 0.01;  // the first grid's step (metres)
  double fine_step_m = 0.002;   // the refinement's step, over ± 1.5 coarse steps (metres)
  double coarse_bin_deg = 0.1;  // the direction histogram's bin on the first grid (degrees)
  double fine_bin_deg = 0.05;   // and on the refinement (degrees)
  int max_points = 8000;        // returns used (every k-th), for speed
  // The estimate is used only when the angles are this many times sharper from it than from the
  // origin (Σ n² over the histogram's bins): a fan on a stage, not a scan that happens to be
  // ring-less.
  double min_gain = 1.3;
  bool Check(std::string* why) const;
};

struct SweptOrigin {
  double radial_m = 0.0;  // the mirror's distance from the stage's axis, in the scan's half-plane
  double height_m = 0.0;  // its height along the axis
  double gain = 1.0;      // how much sharper the angles are from there than from the origin
};

// nullopt when the angles are not min_gain times sharper anywhere (or too few returns).
std::optional<SweptOrigin> EstimateSweptOrigin(const LidarCloud& cloud,
                                               const SweptOriginOptions& options = {});

// Each return's ray origin from the estimate: the mirror turned to the return's azimuth.
std::vector<Eigen::Vector3f> SweptViewpoints(const LidarCloud& cloud, const SweptOrigin& origin);

// "its rays start 10.0 cm from the stage's axis and 5.0 cm up it (estimated: the beams' angles
// 3.1x sharper from there than from the origin)"
std::string DescribeSweptOrigin(const SweptOrigin& origin);

}  // namespace calibench
