// Feature extraction for the three-face target (papers/lrf-depth-camera-vboard.txt Section 3.1,
// Fig. 6–7) and for the LRF ↔ checkerboard case.
//
// Scan: the target's polyline (inside a user region or found automatically), split into
// segments, a RANSAC line per segment refined by least squares, the base line from the two
// outer segments together, and the intersection points F, G, H.
// Depth: back-projection, RANSAC (PCL) for the three faces, the three pairwise intersection
// lines AB, AC, AD.
// Faces are named by the target frame (lrf_types.h), assuming the target stands upright (its y
// axis roughly up in both sensors): ABC is the face on the sensor's left.
#pragma once

#include <optional>
#include <string>

#include "core/lrf/dataset.h"
#include "core/lrf/types.h"

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

// Automatic search (region == nullptr) picks the polyline whose four segments best match the
// target: collinear outer segments, a tent bump towards the sensor between them, face lengths
// consistent with `target`. Fails with a reason (empty scan, all invalid, fewer than three faces
// crossed, lines near parallel).
ScanFeatures ExtractScanFeatures(const LaserScan& scan, const ThreeFaceTarget& target,
                                 const ScanFeatureOptions& options,
                                 const ScanRegion* region = nullptr);

struct DepthFeatureOptions {
  int stride_px = 2;  // back-project every stride-th pixel in u and v
  double max_depth_m = 6.0;
  // RANSAC inlier distance: base + per_m2 · z² (the depth noise grows with z²), metres.
  double plane_threshold_m = 0.008;
  double plane_threshold_per_m2 = 0.004;
  int min_inliers_per_face = 150;
  int max_planes = 8;               // planes extracted before choosing the target's three
  double min_face_angle_deg = 8.0;  // faces closer to parallel fail with a reason
  uint64_t seed = 7;                // RANSAC sampling
  bool Check(std::string* why) const;
};

// Optional pixel rectangle [u0, u1) × [v0, v1) holding the target (the user's selection).
struct DepthRegion {
  int u0 = 0, v0 = 0, u1 = 0, v1 = 0;
};

DepthFeatures ExtractDepthFeatures(const DepthImage& depth, const ThreeFaceTarget& target,
                                   const DepthFeatureOptions& options,
                                   const DepthRegion* region = nullptr);

// The intersection line of two planes; nullopt when they are parallel within 1e-6.
std::optional<Line3> IntersectPlanes(const Plane& a, const Plane& b);
// The intersection point of two 2D lines; nullopt when they are parallel within 1e-9.
std::optional<Vec2> IntersectLines(const Line2& a, const Line2& b);
// Total-least-squares line through points (at least 2).
Line2 FitLine2(const std::vector<Vec2>& points);

struct BoardScanOptions {
  double line_threshold_m = 0.02;
  int min_points = 10;
  double break_distance_m = 0.06;
  bool Check(std::string* why) const;
};

// Checkerboard case (Zhang & Pless): the scan returns on the board plane. Inside `region` when
// given; otherwise the longest straight run whose direction agrees with `expected_plane_in_lrf`
// (when given) or simply the longest straight run. Fails (empty, reason set) when none.
struct BoardScanPoints {
  bool ok = false;
  std::string reason;
  std::vector<Vec2> points;
  std::vector<int> indices;  // scan ray indices
  Line2 line;
  double rms_m = 0.0;
};
BoardScanPoints ExtractBoardScanPoints(const LaserScan& scan, const BoardScanOptions& options,
                                       const ScanRegion* region = nullptr);

}  // namespace calibench
