// Lines in the 2D laser scan: the three-face target's face lines and corners
// (papers/lrf-depth-camera-vboard.txt Section 3.1, Section 4.2 step 1, Fig. 4 and 6).
//
// The target's polyline (inside a user region or found automatically), split into segments, a
// RANSAC line per segment refined by least squares, the base line from the two outer segments
// together, and the intersection points F, G, H. Faces are named by the target frame (types.h),
// assuming the target stands upright (its y axis roughly up): ABC is the face on the sensor's left.
//
// The building blocks at the end (polylines, straight runs, robust lines) also serve the
// checkerboard case (board_in_scan.h).
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/lrf_data/dataset.h"
#include "core/lrf_data/types.h"

namespace calibench {

struct ScanFeatureOptions {
  // Consecutive returns further apart than max(break_distance_m, break_angle_factor · r · Δθ)
  // start a new polyline (metres; the factor allows for grazing incidence).
  double break_distance_m = 0.06;
  double break_angle_factor = 6.0;
  double line_threshold_m = 0.02;  // split-and-merge / RANSAC inlier distance (~3σ of an R2000)
  int min_points_per_face = 6;     // returns per face line
  double min_face_length_m = 0.05;
  // Lines closer than this to parallel give ill-conditioned corners: fail with a reason.
  double min_line_angle_deg = 8.0;
  int ransac_iterations = 200;
  bool Check(std::string* why) const;
};

// The target's face lines and corners F, G, H (LRF frame, metres). Automatic search (region ==
// nullptr) picks the polyline whose four segments best match the target: collinear outer
// segments, a tent bump towards the sensor between them, face lengths consistent with `target`.
// Fails with a reason (empty scan, all invalid, fewer than three faces crossed, lines near
// parallel).
ScanFeatures ExtractScanFeatures(const LaserScan& scan, const ThreeFaceTarget& target,
                                 const ScanFeatureOptions& options,
                                 const ScanRegion* region = nullptr);

// The intersection point of two 2D lines (LRF frame, metres); nullopt when they are parallel
// within 1e-9.
std::optional<Vec2> IntersectLines(const Line2& a, const Line2& b);
// Total-least-squares line through points (at least 2; metres), normal towards the origin.
Line2 FitLine2(const std::vector<Vec2>& points);

// Building blocks, shared with board_in_scan.cpp.

// One valid return of a scan (LRF frame, metres).
struct ScanPoint {
  Vec2 point;
  int index = 0;  // scan ray index
  double range = 0.0;
};
using ScanPolyline = std::vector<ScanPoint>;

// The scan's valid returns (inside `region` when given), in scan order, split where consecutive
// returns are further apart than max(break_distance_m, break_angle_factor · r · Δθ · rays
// between them). Empty, with *reason set, when the scan is empty or has no valid return there.
std::vector<ScanPolyline> ScanPolylines(const LaserScan& scan, const ScanRegion* region,
                                        double break_distance_m, double break_angle_factor,
                                        std::string* reason);

// Straight runs of a polyline, by split-and-merge (threshold_m, metres) over the smoothed
// returns: [first, last] positions in the polyline, inclusive, in scan order.
std::vector<std::pair<int, int>> StraightRuns(const ScanPolyline& polyline, double threshold_m);

// RANSAC line (deterministic seed) through points, then least squares on its inliers and on the
// returns within max(threshold_m, 3σ) of that, σ robust from the residuals (metres). *inliers:
// positions in `points` of the returns the final line was fitted to.
Line2 RobustFitLine(const std::vector<Vec2>& points, double threshold_m, int iterations,
                    std::vector<int>* inliers);

// RMS distance of points (at least one) to a line (metres).
double LineRms(const Line2& line, const std::vector<Vec2>& points);

}  // namespace calibench
