// Feature extraction for the three-face target (papers/lrf-depth-camera-vboard.txt Section 3.1,
// Section 4.2 steps 1 and 3, Fig. 4, 6, 7) and for the LRF ↔ checkerboard case.
#include "core/lrf/features.h"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/ransac.h>
#include <pcl/sample_consensus/sac_model_normal_plane.h>
#include <pcl/sample_consensus/sac_model_plane.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>

namespace calibench {

namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr double kRadToDeg = 180.0 / M_PI;
const char* const kLineNames[3] = {"EI", "FG", "GH"};
const char* const kFaceNames[3] = {"base PBDQ", "face ABC", "face ACD"};

std::string Format(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

// Angle between two unit normals, ignoring their sign (degrees).
double UnsignedAngleDeg(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return std::acos(std::clamp(std::abs(a.dot(b)), 0.0, 1.0)) * kRadToDeg;
}

// ---------------------------------------------------------------------------------------------
// Scan side.

struct ScanPoint {
  Vec2 point;
  int index = 0;  // scan ray index
  double range = 0.0;
};
using Polyline = std::vector<ScanPoint>;

// Valid returns (inside the region when given), in scan order, split where consecutive returns
// are further apart than max(break_distance, factor · r · Δθ · rays between them). A single
// noisy return (the R2000's σ is a fifth of the default break distance) must not split a face:
// the jump must also hold between the returns on either side of the pair.
std::vector<Polyline> SplitAtRangeBreaks(const LaserScan& scan, const ScanRegion* region,
                                         double break_distance_m, double break_angle_factor) {
  Polyline valid;
  for (size_t i = 0; i < scan.ranges.size(); ++i) {
    if (!scan.Valid(i)) continue;
    if (region && !region->Contains(scan.Angle(i), scan.ranges[i])) continue;
    valid.push_back(ScanPoint{scan.Point(i), static_cast<int>(i), scan.ranges[i]});
  }
  const int n = static_cast<int>(valid.size());
  auto apart = [&](int a, int b) {
    if (a < 0 || b >= n) return true;
    const double rays = static_cast<double>(valid[b].index - valid[a].index);
    const double limit =
        std::max(break_distance_m, break_angle_factor * std::max(valid[a].range, valid[b].range) *
                                       std::abs(scan.angle_increment) * rays);
    return (valid[b].point - valid[a].point).norm() > limit;
  };
  std::vector<Polyline> polylines;
  Polyline current;
  for (int i = 0; i < n; ++i) {
    if (!current.empty() && apart(i - 1, i) && apart(i - 2, i) && apart(i - 1, i + 1)) {
      polylines.push_back(std::move(current));
      current.clear();
    }
    current.push_back(valid[i]);
  }
  if (!current.empty()) polylines.push_back(std::move(current));
  return polylines;
}

// Moving average over about ±1.5 cm of the polyline: split-and-merge on raw R2000-like returns
// (σ ≈ 1 cm) would split at noise; the average rounds the corners by a centimetre at most.
std::vector<Vec2> SmoothPolyline(const Polyline& polyline) {
  const int n = static_cast<int>(polyline.size());
  std::vector<Vec2> smoothed(n);
  if (n < 2) {
    for (int i = 0; i < n; ++i) smoothed[i] = polyline[i].point;
    return smoothed;
  }
  const double spacing = (polyline.back().point - polyline.front().point).norm() / (n - 1);
  const int half =
      std::clamp(static_cast<int>(std::lround(0.015 / std::max(spacing, 1e-6))), 1, 25);
  for (int i = 0; i < n; ++i) {
    const int a = std::max(0, i - half), b = std::min(n - 1, i + half);
    Vec2 sum = Vec2::Zero();
    for (int k = a; k <= b; ++k) sum += polyline[k].point;
    smoothed[i] = sum / (b - a + 1);
  }
  return smoothed;
}

// Max distance of points[first..last] to the TLS line through them.
double MaxLineDeviation(const std::vector<Vec2>& points, int first, int last) {
  std::vector<Vec2> subset(points.begin() + first, points.begin() + last + 1);
  const Line2 line = FitLine2(subset);
  double worst = 0.0;
  for (const Vec2& p : subset) worst = std::max(worst, std::abs(line.SignedDistance(p)));
  return worst;
}

// Split-and-merge over a polyline: returns [first, last] ranges (inclusive, in polyline order).
std::vector<std::pair<int, int>> SplitAndMerge(const std::vector<Vec2>& points, double threshold) {
  std::vector<std::pair<int, int>> segments;
  if (points.size() < 2) return segments;
  // Split: recursively at the point furthest from the chord.
  std::vector<std::pair<int, int>> stack{{0, static_cast<int>(points.size()) - 1}};
  while (!stack.empty()) {
    const auto [a, b] = stack.back();
    stack.pop_back();
    const Vec2 chord = points[b] - points[a];
    const double length = chord.norm();
    int worst = -1;
    double worst_distance = threshold;
    for (int k = a + 1; k < b; ++k) {
      const Vec2 d = points[k] - points[a];
      const double distance =
          length > 1e-12 ? std::abs(chord.x() * d.y() - chord.y() * d.x()) / length : d.norm();
      if (distance > worst_distance) worst = k, worst_distance = distance;
    }
    if (worst < 0) {
      segments.push_back({a, b});
    } else {
      stack.push_back({worst, b});  // processed after [a, worst]: keeps scan order
      stack.push_back({a, worst});
    }
  }
  // Merge neighbours whose union is still straight (the split's chords can over-split).
  for (bool merged = true; merged;) {
    merged = false;
    for (size_t i = 0; i + 1 < segments.size(); ++i) {
      if (MaxLineDeviation(points, segments[i].first, segments[i + 1].second) <= threshold) {
        segments[i].second = segments[i + 1].second;
        segments.erase(segments.begin() + i + 1);
        merged = true;
        break;
      }
    }
  }
  return segments;
}

struct Segment {
  std::vector<Vec2> points;  // raw returns
  std::vector<int> polyline_positions;
  Line2 line;
  double length = 0.0;  // between the projections of its end returns, metres
};

Segment MakeSegment(const Polyline& polyline, int first, int last) {
  Segment segment;
  for (int k = first; k <= last; ++k) {
    segment.points.push_back(polyline[k].point);
    segment.polyline_positions.push_back(k);
  }
  if (segment.points.size() >= 2) {
    segment.line = FitLine2(segment.points);
    segment.length = (segment.points.back() - segment.points.front()).norm();
  }
  return segment;
}

// RANSAC line (deterministic) then least squares on the inliers, then once more on the returns
// within max(threshold, 3σ) of it, σ from the median absolute residual (robust to the R2000's
// noise being larger than the threshold assumes).
Line2 RobustFitLine(const std::vector<Vec2>& points, double threshold, int iterations,
                    std::vector<int>* inliers) {
  const int n = static_cast<int>(points.size());
  std::mt19937_64 rng(12345);
  std::uniform_int_distribution<int> pick(0, n - 1);
  Line2 best = FitLine2(points);
  int best_count = -1;
  for (int it = 0; it < iterations && n >= 2; ++it) {
    const int i = pick(rng), j = pick(rng);
    const Vec2 d = points[j] - points[i];
    if (i == j || d.norm() < 1e-9) continue;
    Line2 candidate;
    candidate.normal = Vec2(-d.y(), d.x()).normalized();
    candidate.offset = -candidate.normal.dot(points[i]);
    int count = 0;
    for (const Vec2& p : points) count += std::abs(candidate.SignedDistance(p)) <= threshold;
    if (count > best_count) best = candidate, best_count = count;
  }
  auto select = [&](const Line2& line, double limit) {
    std::vector<Vec2> chosen;
    inliers->clear();
    for (int k = 0; k < n; ++k)
      if (std::abs(line.SignedDistance(points[k])) <= limit) {
        chosen.push_back(points[k]);
        inliers->push_back(k);
      }
    return chosen;
  };
  std::vector<Vec2> chosen = select(best, threshold);
  if (chosen.size() < 2) return best;
  Line2 line = FitLine2(chosen);
  std::vector<double> residuals;
  for (const Vec2& p : points) residuals.push_back(std::abs(line.SignedDistance(p)));
  std::nth_element(residuals.begin(), residuals.begin() + n / 2, residuals.end());
  const double sigma = 1.4826 * residuals[n / 2];
  chosen = select(line, std::max(threshold, 3.0 * sigma));
  return chosen.size() >= 2 ? FitLine2(chosen) : line;
}

// Target lengths bounding what a scan can see of it (a plane section of a triangle is at most
// its longest side).
struct TargetSpans {
  double max_face_chord = 0.0;  // longest side of ABC / ACD
  double max_footprint = 0.0;   // longest side of ABD (F–H)
  double max_bump = 0.0;        // ridge height
};

TargetSpans SpansOf(const ThreeFaceTarget& t) {
  TargetSpans spans;
  spans.max_face_chord =
      std::max({(t.A() - t.B()).norm(), (t.A() - t.C()).norm(), (t.B() - t.C()).norm(),
                (t.A() - t.D()).norm(), (t.C() - t.D()).norm()});
  spans.max_footprint =
      std::max({(t.A() - t.B()).norm(), (t.B() - t.D()).norm(), (t.A() - t.D()).norm()});
  spans.max_bump = t.ridge_height;
  return spans;
}

// Does base–face–face–base (segments s[0..3] in scan order) look like the target? Returns a
// score (smaller is better) or nullopt with *why.
std::optional<double> MatchWindow(const std::array<const Segment*, 4>& s, const TargetSpans& spans,
                                  const ScanFeatureOptions& options, std::string* why) {
  for (int k = 0; k < 4; ++k) {
    if (static_cast<int>(s[k]->points.size()) < options.min_points_per_face ||
        s[k]->length < options.min_face_length_m) {
      *why = "segment " + std::to_string(k + 1) + " of 4 is too short (" +
             std::to_string(s[k]->points.size()) + " returns, " + Format("%.3f m)", s[k]->length);
      return std::nullopt;
    }
  }
  const double chord_limit = 1.2 * spans.max_face_chord + 0.05;
  if (s[1]->length > chord_limit || s[2]->length > chord_limit) {
    *why = "the middle segments are longer than the target's faces (" +
           Format("%.2f m", std::max(s[1]->length, s[2]->length)) +
           Format(" > %.2f m)", chord_limit);
    return std::nullopt;
  }
  // The outer segments are one line: the base (paper Fig. 4, line EI).
  std::vector<Vec2> base_points = s[0]->points;
  base_points.insert(base_points.end(), s[3]->points.begin(), s[3]->points.end());
  const Line2 base = FitLine2(base_points);  // normal towards the sensor (offset >= 0)
  double sum_sq = 0.0;
  for (const Vec2& p : base_points) sum_sq += std::pow(base.SignedDistance(p), 2);
  const double base_rms = std::sqrt(sum_sq / base_points.size());
  if (base_rms > options.line_threshold_m) {
    *why = "the outer segments are not collinear (" + Format("RMS %.3f m)", base_rms);
    return std::nullopt;
  }
  // The two middle segments form a bump towards the sensor, at most the ridge height high.
  const auto ridge = IntersectLines(s[1]->line, s[2]->line);
  const auto foot_a = IntersectLines(s[1]->line, base);
  const auto foot_b = IntersectLines(s[2]->line, base);
  if (!ridge || !foot_a || !foot_b) {
    *why = "the middle segments are parallel to each other or to the base";
    return std::nullopt;
  }
  const double bump = base.SignedDistance(*ridge);
  if (bump < std::max(options.line_threshold_m, 0.01) || bump > 1.3 * spans.max_bump + 0.05) {
    *why = "the middle segments do not form the tent's ridge towards the sensor (height " +
           Format("%.3f m)", bump);
    return std::nullopt;
  }
  const double footprint = (*foot_a - *foot_b).norm();
  if (footprint > 1.2 * spans.max_footprint + 0.05) {
    *why = "the tent's footprint on the scan is too wide (" + Format("%.2f m)", footprint);
    return std::nullopt;
  }
  return base_rms / options.line_threshold_m;
}

struct Window {
  const Polyline* polyline = nullptr;
  std::array<Segment, 4> segments;
  double score = 0.0;
};

// Polar angle of a point, unwrapped to the scan's angle near `reference` (radians).
double AngleNear(const Vec2& p, double reference) {
  double a = std::atan2(p.y(), p.x());
  while (a - reference > M_PI) a -= 2 * M_PI;
  while (a - reference < -M_PI) a += 2 * M_PI;
  return a;
}

// Given the lines (0 base, 1 ABC, 2 ACD) fits the faces again from the returns of the window's
// span: each return is assigned by its scan angle between the corners F, G, H; returns within
// max(2 rays, 5 mm across the ray) of a corner are left out (mixed returns and beam footprint
// live there).
bool FitFaces(const LaserScan& scan, const Polyline& span, const ScanFeatureOptions& options,
              ScanFeatures* out) {
  // Two passes: the corners from the segments' lines, then from the refined lines. More passes
  // can drift on a face seen at grazing incidence (few returns, a poorly known direction).
  for (int iteration = 0; iteration < 2; ++iteration) {
    std::array<std::optional<Vec2>, 3> corners = {IntersectLines(out->lines[0], out->lines[1]),
                                                  IntersectLines(out->lines[1], out->lines[2]),
                                                  IntersectLines(out->lines[2], out->lines[0])};
    for (int k = 0; k < 3; ++k) {
      if (!corners[k]) {
        out->reason = std::string("lines ") + kLineNames[k] + " and " + kLineNames[(k + 1) % 3] +
                      " are parallel";
        return false;
      }
    }
    const double reference = std::atan2(corners[1]->y(), corners[1]->x());
    const double a_f = AngleNear(*corners[0], reference);
    const double a_g = AngleNear(*corners[1], reference);
    const double a_h = AngleNear(*corners[2], reference);
    std::array<std::vector<Vec2>, 3> face_points;
    for (const ScanPoint& p : span) {
      const double a = AngleNear(p.point, reference);
      const double margin = std::max(2.0 * std::abs(scan.angle_increment), 0.005 / p.range);
      if (std::abs(a - a_f) < margin || std::abs(a - a_g) < margin || std::abs(a - a_h) < margin)
        continue;
      int face = 0;
      if ((a - a_f) * (a - a_g) < 0)
        face = 1;  // between F and G: ABC
      else if ((a - a_g) * (a - a_h) < 0)
        face = 2;
      face_points[face].push_back(p.point);
    }
    for (int k = 0; k < 3; ++k) {
      if (static_cast<int>(face_points[k].size()) >= options.min_points_per_face) continue;
      if (iteration > 0) return true;  // keep the first pass
      out->reason = std::string(kFaceNames[k]) + " has only " +
                    std::to_string(face_points[k].size()) +
                    " returns away from the corners (need " +
                    std::to_string(options.min_points_per_face) + ")";
      return false;
    }
    for (int k = 0; k < 3; ++k) {
      std::vector<int> inliers;
      out->lines[k] = RobustFitLine(face_points[k], options.line_threshold_m,
                                    options.ransac_iterations, &inliers);
      out->face_points[k].clear();
      for (int i : inliers) out->face_points[k].push_back(face_points[k][i]);
    }
  }
  return true;
}

// ---------------------------------------------------------------------------------------------
// Depth side.

// Every stride-th pixel back-projected, with its cell in the subsampled grid (for connectivity).
struct DepthCloud {
  std::vector<Vec3> points;   // camera frame, metres
  std::vector<Vec3> normals;  // local surface normal towards the camera; zero where unknown
  std::vector<int> pixel_u, pixel_v, cell;
  std::vector<int> point_of_cell;  // -1 = no point
  int grid_width = 0, grid_height = 0;
};

DepthCloud BackProject(const DepthImage& depth, const DepthRegion& region, int stride,
                       double max_depth_m) {
  const DepthIntrinsics& k = depth.intrinsics;
  DepthCloud cloud;
  cloud.grid_width = std::max(0, (region.u1 - region.u0 + stride - 1) / stride);
  cloud.grid_height = std::max(0, (region.v1 - region.v0 + stride - 1) / stride);
  cloud.point_of_cell.assign(static_cast<size_t>(cloud.grid_width) * cloud.grid_height, -1);
  for (int gv = 0; gv < cloud.grid_height; ++gv) {
    for (int gu = 0; gu < cloud.grid_width; ++gu) {
      const int u = region.u0 + gu * stride, v = region.v0 + gv * stride;
      const double z = depth.At(u, v);
      if (!std::isfinite(z) || z <= 0.0 || z > max_depth_m) continue;
      const int cell = gv * cloud.grid_width + gu;
      cloud.point_of_cell[cell] = static_cast<int>(cloud.points.size());
      cloud.points.emplace_back((u - k.cx) * z / k.fx, (v - k.cy) * z / k.fy, z);
      cloud.pixel_u.push_back(u);
      cloud.pixel_v.push_back(v);
      cloud.cell.push_back(cell);
    }
  }
  return cloud;
}

// Inlier distance at depth z: the depth noise grows with z² (stereo: σ_z = z² σ_disp / (f b)).
double PlaneThreshold(const DepthFeatureOptions& options, double z) {
  return options.plane_threshold_m + options.plane_threshold_per_m2 * z * z;
}

// Local normals by PCA over grid neighbours: they tell the faces apart where the inlier distance
// (several centimetres at 3 m) cannot, e.g. a plane slicing through the ridge of the tent. The
// window's spread must exceed the depth noise (σ ≈ threshold / 3) by about twice, else the
// smallest eigenvector is noise: half-width ≈ 1.15 · threshold / cell, 2 to 8 cells.
// Neighbours across a depth jump are left out.
void ComputeNormals(const DepthIntrinsics& k, const DepthFeatureOptions& options,
                    DepthCloud* cloud) {
  const int stride = options.stride_px;
  cloud->normals.assign(cloud->points.size(), Vec3::Zero());
  for (size_t i = 0; i < cloud->points.size(); ++i) {
    const Vec3& x = cloud->points[i];
    const double cell_m = stride * x.z() / k.fx;
    const int half = std::clamp(
        static_cast<int>(std::lround(1.15 * PlaneThreshold(options, x.z()) / cell_m)), 2, 8);
    // Within the window plus the noise (a jump to the wall behind is a metre or more).
    const double reach_sq =
        std::pow(std::sqrt(2.0) * half * cell_m + 2.0 * PlaneThreshold(options, x.z()), 2);
    const int gu = cloud->cell[i] % cloud->grid_width, gv = cloud->cell[i] / cloud->grid_width;
    Vec3 sum = Vec3::Zero();
    Mat3 sum_sq = Mat3::Zero();
    int n = 0;
    for (int nv = std::max(0, gv - half); nv <= std::min(cloud->grid_height - 1, gv + half); ++nv)
      for (int nu = std::max(0, gu - half); nu <= std::min(cloud->grid_width - 1, gu + half);
           ++nu) {
        const int j = cloud->point_of_cell[nv * cloud->grid_width + nu];
        if (j < 0 || (cloud->points[j] - x).squaredNorm() > reach_sq) continue;
        const Vec3 d = cloud->points[j] - x;
        sum += d;
        sum_sq += d * d.transpose();
        ++n;
      }
    if (n < 6) continue;
    const Mat3 scatter = sum_sq - sum * sum.transpose() / n;
    Eigen::SelfAdjointEigenSolver<Mat3> eigen;
    eigen.computeDirect(scatter);
    Vec3 normal = eigen.eigenvectors().col(0);
    if (normal.dot(x) > 0) normal = -normal;
    cloud->normals[i] = normal;
  }
}

// Local normals further than this from a plane's do not belong to it (normal noise at 3 m is a
// few degrees; the target's faces are 40° or more apart).
constexpr double kNormalToleranceDeg = 25.0;

bool IsInlier(const DepthCloud& cloud, int i, const Plane& plane,
              const DepthFeatureOptions& options) {
  return std::abs(plane.SignedDistance(cloud.points[i])) <=
             PlaneThreshold(options, cloud.points[i].z()) &&
         std::abs(cloud.normals[i].dot(plane.normal)) >= std::cos(kNormalToleranceDeg * kDegToRad);
}

// The largest 8-connected set of `members` in the subsampled pixel grid.
std::vector<int> LargestComponent(const DepthCloud& cloud, const std::vector<int>& members) {
  std::vector<char> in_set(cloud.point_of_cell.size(), 0), visited(in_set.size(), 0);
  for (int i : members) in_set[cloud.cell[i]] = 1;
  std::vector<int> best, current, queue;
  for (int seed : members) {
    if (visited[cloud.cell[seed]]) continue;
    current.clear();
    queue.assign(1, cloud.cell[seed]);
    visited[cloud.cell[seed]] = 1;
    while (!queue.empty()) {
      const int c = queue.back();
      queue.pop_back();
      current.push_back(cloud.point_of_cell[c]);
      const int gu = c % cloud.grid_width, gv = c / cloud.grid_width;
      for (int dv = -1; dv <= 1; ++dv)
        for (int du = -1; du <= 1; ++du) {
          const int nu = gu + du, nv = gv + dv;
          if (nu < 0 || nv < 0 || nu >= cloud.grid_width || nv >= cloud.grid_height) continue;
          const int n = nv * cloud.grid_width + nu;
          if (in_set[n] && !visited[n]) {
            visited[n] = 1;
            queue.push_back(n);
          }
        }
    }
    if (current.size() > best.size()) best = current;
  }
  return best;
}

struct PlanePatch {
  std::vector<int> inliers;  // indices into DepthCloud::points
  Plane plane;               // normal towards the camera (d > 0)
  Mat4 covariance = Mat4::Zero();
  double rms_m = 0.0;
};

// Weighted total least squares with the (n, d) covariance, as FitPlaneLeastSquares
// (core/lidar_plane.cpp) does it: residual r_i = n·x_i + d with n perturbed in its tangent plane
// (basis B), J_i = [x_iᵀ B, 1], Σ = s² (Jᵀ W J)⁻¹. The weights w_i = 1 / t(z_i)², t the inlier
// threshold, follow the depth noise's growth with z²; s² = Σ w r² / (N - 3) rescales them.
std::optional<PlanePatch> FitPlaneWeighted(const DepthCloud& cloud, const std::vector<int>& indices,
                                           const DepthFeatureOptions& options) {
  if (indices.size() < 4) return std::nullopt;
  std::vector<double> weights;
  double weight_sum = 0.0;
  Vec3 centroid = Vec3::Zero();
  for (int i : indices) {
    weights.push_back(1.0 / std::pow(PlaneThreshold(options, cloud.points[i].z()), 2));
    weight_sum += weights.back();
    centroid += weights.back() * cloud.points[i];
  }
  centroid /= weight_sum;
  Mat3 scatter = Mat3::Zero();
  for (size_t k = 0; k < indices.size(); ++k) {
    const Vec3 p = cloud.points[indices[k]] - centroid;
    scatter += weights[k] * p * p.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Mat3> eigen(scatter);
  if (eigen.eigenvalues()[1] < 1e-6 * eigen.eigenvalues()[2] || eigen.eigenvalues()[1] <= 0)
    return std::nullopt;
  PlanePatch patch;
  patch.inliers = indices;
  patch.plane = OrientTowardsOrigin(
      Plane{eigen.eigenvectors().col(0), -eigen.eigenvectors().col(0).dot(centroid)});
  Eigen::Matrix<double, 3, 2> tangent;
  tangent.col(0) = patch.plane.normal.unitOrthogonal();
  tangent.col(1) = patch.plane.normal.cross(tangent.col(0));
  Mat3 normal_matrix = Mat3::Zero();
  double weighted_sq = 0.0, sum_sq = 0.0;
  for (size_t k = 0; k < indices.size(); ++k) {
    const Vec3& x = cloud.points[indices[k]];
    const double r = patch.plane.SignedDistance(x);
    weighted_sq += weights[k] * r * r;
    sum_sq += r * r;
    Eigen::RowVector3d j;
    j << x.transpose() * tangent, 1.0;
    normal_matrix += weights[k] * j.transpose() * j;
  }
  patch.rms_m = std::sqrt(sum_sq / indices.size());
  const double dof = std::max<double>(1.0, static_cast<double>(indices.size()) - 3.0);
  const Mat3 local_cov = (weighted_sq / dof) * normal_matrix.inverse();
  Eigen::Matrix<double, 4, 3> to_coefficients = Eigen::Matrix<double, 4, 3>::Zero();
  to_coefficients.topLeftCorner<3, 2>() = tangent;
  to_coefficients(3, 2) = 1.0;
  patch.covariance = to_coefficients * local_cov * to_coefficients.transpose();
  return patch;
}

// One PCL RANSAC plane over (a random subset of) the live points, with the subset's inliers
// (cloud indices); nullopt when none.
std::optional<Plane> RansacPlane(const DepthCloud& cloud, std::vector<int> live,
                                 std::mt19937_64* rng, const DepthFeatureOptions& options,
                                 std::vector<int>* ransac_inliers) {
  // PCL samples with a fixed internal seed; shuffling with ours makes the result depend on
  // options.seed only. 4000 points are plenty to find a plane and keep each RANSAC fast.
  std::shuffle(live.begin(), live.end(), *rng);
  live.resize(std::min<size_t>(live.size(), 4000));
  std::vector<double> depths;
  pcl::PointCloud<pcl::PointXYZ>::Ptr points(new pcl::PointCloud<pcl::PointXYZ>);
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  for (int i : live) {
    const Vec3& p = cloud.points[i];
    const Vec3& n = cloud.normals[i];
    points->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
    normals->push_back(pcl::Normal(n.x(), n.y(), n.z()));  // curvature 0: full normal weight
    depths.push_back(p.z());
  }
  // The threshold of the nearer quarter: leftovers far away (where the threshold is wide) must
  // not let RANSAC slice one plane through several near surfaces.
  const size_t quarter = depths.size() / 4;
  std::nth_element(depths.begin(), depths.begin() + quarter, depths.end());
  const double threshold = PlaneThreshold(options, depths[quarter]);
  // PCL's distance is w·angle + (1 - w)·distance: a kNormalToleranceDeg difference in normal
  // costs a whole threshold, as in IsInlier.
  pcl::SampleConsensusModelNormalPlane<pcl::PointXYZ, pcl::Normal>::Ptr model(
      new pcl::SampleConsensusModelNormalPlane<pcl::PointXYZ, pcl::Normal>(points, false));
  model->setInputNormals(normals);
  model->setNormalDistanceWeight(std::min(0.5, threshold / (kNormalToleranceDeg * kDegToRad)));
  pcl::RandomSampleConsensus<pcl::PointXYZ> ransac(model, threshold);
  ransac.setMaxIterations(300);
  if (!ransac.computeModel()) return std::nullopt;
  Eigen::VectorXf coefficients;
  ransac.getModelCoefficients(coefficients);
  if (coefficients.size() != 4) return std::nullopt;
  const Vec3 normal = coefficients.head<3>().cast<double>();
  if (normal.norm() < 1e-9) return std::nullopt;
  std::vector<int> local;
  ransac.getInliers(local);
  ransac_inliers->clear();
  for (int k : local) ransac_inliers->push_back(live[k]);
  return Plane{normal.normalized(), coefficients[3] / normal.norm()};
}

std::optional<std::array<int, 3>> ChooseTriple(const DepthCloud& cloud,
                                               const std::vector<PlanePatch>& patches,
                                               const ThreeFaceTarget& target);

// Sequential RANSAC: each plane keeps its largest connected set of inliers (a plane's inliers
// elsewhere, e.g. a band of a wall along its intersection, stay for later planes), until three
// planes look like the target. Coplanar pieces (the base on both sides of the tent) are merged
// afterwards.
std::vector<PlanePatch> ExtractPlanes(const DepthCloud& cloud, const ThreeFaceTarget& target,
                                      const DepthFeatureOptions& options) {
  std::vector<PlanePatch> patches;
  std::vector<char> live(cloud.points.size(), 1);
  std::mt19937_64 rng(options.seed);
  // Stop after a few RANSAC planes in a row that hold no surface: what is left is edges and
  // speckle.
  int failures_in_a_row = 0;
  for (int attempt = 0; attempt < 3 * options.max_planes && failures_in_a_row < 3 &&
                        static_cast<int>(patches.size()) < options.max_planes;
       ++attempt) {
    std::vector<int> live_indices;
    for (size_t i = 0; i < live.size(); ++i)
      if (live[i]) live_indices.push_back(static_cast<int>(i));
    if (static_cast<int>(live_indices.size()) < options.min_inliers_per_face) break;
    std::vector<int> ransac_inliers;
    const auto plane = RansacPlane(cloud, live_indices, &rng, options, &ransac_inliers);
    if (!plane) break;
    // RANSAC's plane leans towards neighbouring surfaces to catch more inliers in its wide
    // band; least squares on the connected inliers and a new selection pull it back.
    std::vector<int> inliers, component;
    Plane current = *plane;
    for (int refine = 0; refine < 3; ++refine) {
      inliers.clear();
      for (int i : live_indices)
        if (IsInlier(cloud, i, current, options)) inliers.push_back(i);
      component = LargestComponent(cloud, inliers);
      if (static_cast<int>(component.size()) < options.min_inliers_per_face) break;
      const auto refit = FitPlaneWeighted(cloud, component, options);
      if (!refit) break;
      current = refit->plane;
    }
    std::optional<PlanePatch> patch;
    if (static_cast<int>(component.size()) >= options.min_inliers_per_face)
      patch = FitPlaneWeighted(cloud, component, options);
    if (!patch) {  // a small or degenerate surface, or edge points: do not draw them again
      for (int i : component) live[i] = 0;
      for (int i : ransac_inliers) live[i] = 0;
      ++failures_in_a_row;
      continue;
    }
    failures_in_a_row = 0;
    for (int i : component) live[i] = 0;
    // Noise tails of a surface (returns just beyond the threshold, scattered inside it) would
    // feed spurious planes later: drop live points within 3 thresholds of the patch that are
    // surrounded by it (5 of 8 neighbours; the edge of a neighbouring face has at most 3).
    std::vector<char> in_patch(cloud.point_of_cell.size(), 0);
    for (int i : component) in_patch[cloud.cell[i]] = 1;
    for (size_t j = 0; j < live.size(); ++j) {
      if (!live[j] || std::abs(patch->plane.SignedDistance(cloud.points[j])) >
                          3.0 * PlaneThreshold(options, cloud.points[j].z()))
        continue;
      const int gu = cloud.cell[j] % cloud.grid_width, gv = cloud.cell[j] / cloud.grid_width;
      int surrounding = 0;
      for (int dv = -1; dv <= 1; ++dv)
        for (int du = -1; du <= 1; ++du) {
          const int nu = gu + du, nv = gv + dv;
          if (nu >= 0 && nv >= 0 && nu < cloud.grid_width && nv < cloud.grid_height)
            surrounding += in_patch[nv * cloud.grid_width + nu];
        }
      if (surrounding >= 5) live[j] = 0;
    }
    patches.push_back(std::move(*patch));
    if (ChooseTriple(cloud, patches, target)) break;  // the target is found: the rest is clutter
  }
  for (bool merged = true; merged;) {
    merged = false;
    for (size_t a = 0; a < patches.size() && !merged; ++a)
      for (size_t b = a + 1; b < patches.size() && !merged; ++b) {
        if (patches[a].plane.normal.dot(patches[b].plane.normal) < std::cos(3.0 * kDegToRad))
          continue;
        std::vector<int> both = patches[a].inliers;
        both.insert(both.end(), patches[b].inliers.begin(), patches[b].inliers.end());
        auto joint = FitPlaneWeighted(cloud, both, options);
        if (!joint || joint->rms_m > 1.5 * std::max(patches[a].rms_m, patches[b].rms_m)) continue;
        patches[a] = std::move(*joint);
        patches.erase(patches.begin() + b);
        merged = true;
      }
  }
  return patches;
}

double AngleDeg(const Vec3& a, const Vec3& b) {
  return std::acos(std::clamp(a.dot(b), -1.0, 1.0)) * kRadToDeg;
}

// The point where the three planes meet (A on the target); nullopt when dependent.
std::optional<Vec3> MeetingPoint(const Plane& a, const Plane& b, const Plane& c) {
  Mat3 normals;
  normals << a.normal.transpose(), b.normal.transpose(), c.normal.transpose();
  if (std::abs(normals.determinant()) < 1e-6) return std::nullopt;
  return Vec3(normals.inverse() * Vec3(-a.distance, -b.distance, -c.distance));
}

// 98th percentile of the distances from `point` to a patch's points.
double FarExtent(const DepthCloud& cloud, const PlanePatch& patch, const Vec3& point) {
  std::vector<double> d;
  for (int i : patch.inliers) d.push_back((cloud.points[i] - point).norm());
  const size_t k = std::min(d.size() - 1, static_cast<size_t>(0.98 * d.size()));
  std::nth_element(d.begin(), d.begin() + k, d.end());
  return d[k];
}

double NearestDistance(const DepthCloud& cloud, const PlanePatch& patch, const Vec3& point) {
  double best = std::numeric_limits<double>::infinity();
  for (int i : patch.inliers) best = std::min(best, (cloud.points[i] - point).norm());
  return best;
}

double MeanU(const DepthCloud& cloud, const PlanePatch& patch) {
  double sum = 0.0;
  for (int i : patch.inliers) sum += cloud.pixel_u[i];
  return sum / patch.inliers.size();
}

// Fig. 7 (c): the (base, ABC, ACD) triple whose normals make the target's angles, whose planes
// meet at a point A next to all three patches, no larger than the target, ABC left of ACD in the
// image. Walls and floor fail the angles or the size. Returns patch indices or nullopt.
std::optional<std::array<int, 3>> ChooseTriple(const DepthCloud& cloud,
                                               const std::vector<PlanePatch>& patches,
                                               const ThreeFaceTarget& target) {
  const std::array<Plane, 3> faces = target.FacePlanes();  // normals towards +z
  const std::array<double, 3> expected = {AngleDeg(faces[0].normal, faces[1].normal),
                                          AngleDeg(faces[1].normal, faces[2].normal),
                                          AngleDeg(faces[2].normal, faces[0].normal)};
  const double face_reach =
      1.15 * std::max((target.A() - target.B()).norm(), (target.A() - target.C()).norm()) + 0.05;
  double base_reach = 0.0;
  for (double sx : {-0.5, 0.5})
    for (double sy : {-0.5, 0.5})
      base_reach =
          std::max(base_reach,
                   (Vec3(sx * target.base_width, sy * target.base_height, 0) - target.A()).norm());
  base_reach = 1.15 * base_reach + 0.05;
  const double near_a = 0.3 * face_reach + 0.05;
  constexpr double kAngleTolerance = 12.0;  // degrees, per pair
  std::optional<std::array<int, 3>> best;
  double best_score = 0.0;
  const int count = static_cast<int>(patches.size());
  for (int b = 0; b < count; ++b)
    for (int f1 = 0; f1 < count; ++f1)
      for (int f2 = 0; f2 < count; ++f2) {
        if (b == f1 || b == f2 || f1 == f2) continue;
        const std::array<const PlanePatch*, 3> p = {&patches[b], &patches[f1], &patches[f2]};
        double score = 0.0;
        bool angles_match = true;
        for (int k = 0; k < 3 && angles_match; ++k) {
          const double error =
              std::abs(AngleDeg(p[k]->plane.normal, p[(k + 1) % 3]->plane.normal) - expected[k]);
          angles_match = error <= kAngleTolerance;
          score += error;
        }
        if (!angles_match || (best && score >= best_score)) continue;
        if (MeanU(cloud, *p[1]) >= MeanU(cloud, *p[2])) continue;  // ABC on the left
        const auto a = MeetingPoint(p[0]->plane, p[1]->plane, p[2]->plane);
        if (!a) continue;
        bool fits = true;
        for (int k = 0; k < 3 && fits; ++k)
          fits = NearestDistance(cloud, *p[k], *a) <= near_a &&
                 FarExtent(cloud, *p[k], *a) <= (k == 0 ? base_reach : face_reach);
        if (!fits) continue;
        best = std::array<int, 3>{b, f1, f2};
        best_score = score;
      }
  return best;
}

// Each point of the three patches goes to the one plane it is an inlier of (distance and local
// normal); points that fit two (along the edges AB, AC, AD) are left out, since they would pull
// the planes towards each other. Then the planes are fitted again.
bool ReassignAndRefit(const DepthCloud& cloud, const DepthFeatureOptions& options,
                      std::array<PlanePatch, 3>* faces) {
  std::vector<int> pool;
  for (const PlanePatch& f : *faces) pool.insert(pool.end(), f.inliers.begin(), f.inliers.end());
  std::array<std::vector<int>, 3> assigned;
  for (int i : pool) {
    int owner = -1, owners = 0;
    for (int k = 0; k < 3; ++k)
      if (IsInlier(cloud, i, (*faces)[k].plane, options)) owner = k, ++owners;
    if (owners != 1) continue;
    // A window straddling an edge can give a normal close to the dominant face's: the distance
    // to the other planes (half a threshold, ~1.5σ) catches those points.
    bool near_other = false;
    for (int k = 0; k < 3; ++k)
      near_other |= k != owner && std::abs((*faces)[k].plane.SignedDistance(cloud.points[i])) <=
                                      0.5 * PlaneThreshold(options, cloud.points[i].z());
    if (!near_other) assigned[owner].push_back(i);
  }
  std::array<PlanePatch, 3> refit;
  for (int k = 0; k < 3; ++k) {
    if (static_cast<int>(assigned[k].size()) < options.min_inliers_per_face) return false;
    auto fit = FitPlaneWeighted(cloud, assigned[k], options);
    if (!fit) return false;
    refit[k] = std::move(*fit);
  }
  *faces = std::move(refit);
  return true;
}

}  // namespace

bool ScanFeatureOptions::Check(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (!(break_distance_m > 0)) return fail("break_distance_m must be > 0 (metres)");
  if (!(break_angle_factor >= 0)) return fail("break_angle_factor must be >= 0");
  if (!(line_threshold_m > 0)) return fail("line_threshold_m must be > 0 (metres)");
  if (min_points_per_face < 2) return fail("min_points_per_face must be >= 2");
  if (!(min_face_length_m >= 0)) return fail("min_face_length_m must be >= 0 (metres)");
  if (!(min_line_angle_deg >= 0 && min_line_angle_deg < 90))
    return fail("min_line_angle_deg must be in [0, 90)");
  if (ransac_iterations < 1) return fail("ransac_iterations must be >= 1");
  return true;
}

ScanFeatures ExtractScanFeatures(const LaserScan& scan, const ThreeFaceTarget& target,
                                 const ScanFeatureOptions& options, const ScanRegion* region) {
  ScanFeatures out;
  std::string why;
  if (!options.Check(&why)) {
    out.reason = "bad scan feature options: " + why;
    return out;
  }
  if (!target.Check(&why)) {
    out.reason = "bad target: " + why;
    return out;
  }
  if (scan.ranges.empty()) {
    out.reason = "scan is empty";
    return out;
  }
  const std::vector<Polyline> polylines =
      SplitAtRangeBreaks(scan, region, options.break_distance_m, options.break_angle_factor);
  if (polylines.empty()) {
    out.reason = region ? "no valid returns inside the selected region" : "no valid returns";
    return out;
  }
  const TargetSpans spans = SpansOf(target);

  // Fig. 6 (c): the polyline E-F-G-H-I is four straight segments in a row.
  std::optional<Window> best;
  size_t most_segments = 0;
  std::string first_rejection;
  for (const Polyline& polyline : polylines) {
    const auto ranges = SplitAndMerge(SmoothPolyline(polyline), options.line_threshold_m);
    std::vector<Segment> segments;
    for (const auto& [first, last] : ranges) {
      Segment segment = MakeSegment(polyline, first, last);
      // Short pieces are the rounded corners of the smoothing or mixed returns, not faces.
      if (static_cast<int>(segment.points.size()) >= std::max(3, options.min_points_per_face / 2) &&
          segment.length >= 0.5 * options.min_face_length_m)
        segments.push_back(std::move(segment));
    }
    most_segments = std::max(most_segments, segments.size());
    for (size_t i = 0; i + 3 < segments.size(); ++i) {
      std::array<const Segment*, 4> window = {&segments[i], &segments[i + 1], &segments[i + 2],
                                              &segments[i + 3]};
      std::string rejection;
      const auto score = MatchWindow(window, spans, options, &rejection);
      if (!score) {
        if (first_rejection.empty()) first_rejection = rejection;
        continue;
      }
      if (!best || *score < best->score)
        best = Window{
            &polyline, {segments[i], segments[i + 1], segments[i + 2], segments[i + 3]}, *score};
    }
  }
  if (!best) {
    if (most_segments < 4) {
      out.reason = "target crosses fewer than three faces (found " + std::to_string(most_segments) +
                   " straight segments in a row, need base, two faces, base)";
    } else {
      out.reason = "no four straight segments in a row match the target: " + first_rejection;
    }
    return out;
  }

  // Faces as seen from the sensor: ABC on the left (larger scan angle, LRF y is left).
  const Window& w = *best;
  const Polyline& polyline = *w.polyline;
  const int span_first = w.segments[0].polyline_positions.front();
  const int span_last = w.segments[3].polyline_positions.back();
  const Polyline span(polyline.begin() + span_first, polyline.begin() + span_last + 1);
  const bool increasing = scan.angle_increment > 0;
  const Segment& abc = increasing ? w.segments[2] : w.segments[1];
  const Segment& acd = increasing ? w.segments[1] : w.segments[2];
  std::vector<Vec2> base_points = w.segments[0].points;
  base_points.insert(base_points.end(), w.segments[3].points.begin(), w.segments[3].points.end());
  out.lines = {FitLine2(base_points), abc.line, acd.line};
  if (!FitFaces(scan, span, options, &out)) return out;

  for (int k = 0; k < 3; ++k) {
    const int next = (k + 1) % 3;
    const double angle = UnsignedAngleDeg(out.lines[k].normal, out.lines[next].normal);
    if (angle < options.min_line_angle_deg) {
      out.reason = std::string("lines ") + kLineNames[k] + " and " + kLineNames[next] +
                   " are within " + Format("%.1f", options.min_line_angle_deg) + "° of parallel (" +
                   Format("%.1f°)", angle);
      return out;
    }
    out.corners[k] = *IntersectLines(out.lines[k], out.lines[next]);  // F, G, H
  }
  double sum_sq = 0.0;
  size_t count = 0;
  for (int k = 0; k < 3; ++k)
    for (const Vec2& p : out.face_points[k]) {
      sum_sq += std::pow(out.lines[k].SignedDistance(p), 2);
      ++count;
    }
  out.rms_m = std::sqrt(sum_sq / std::max<size_t>(1, count));
  for (const ScanPoint& p : span) out.target_indices.push_back(p.index);
  out.ok = true;
  return out;
}

// ---------------------------------------------------------------------------------------------
// Geometry helpers.

std::optional<Line3> IntersectPlanes(const Plane& a, const Plane& b) {
  const Vec3 direction = a.normal.cross(b.normal);
  const double sq = direction.squaredNorm();
  if (direction.norm() < 1e-6) return std::nullopt;
  // The point of the line closest to the origin: p·n_a = -d_a, p·n_b = -d_b, p·dir = 0.
  Line3 line;
  line.point =
      (-a.distance * b.normal.cross(direction) - b.distance * direction.cross(a.normal)) / sq;
  line.direction = direction.normalized();
  return line;
}

std::optional<Vec2> IntersectLines(const Line2& a, const Line2& b) {
  const double det = a.normal.x() * b.normal.y() - a.normal.y() * b.normal.x();
  if (std::abs(det) < 1e-9) return std::nullopt;
  return Vec2((-a.offset * b.normal.y() + b.offset * a.normal.y()) / det,
              (-b.offset * a.normal.x() + a.offset * b.normal.x()) / det);
}

Line2 FitLine2(const std::vector<Vec2>& points) {
  CALIBENCH_CHECK(points.size() >= 2);
  Vec2 centroid = Vec2::Zero();
  for (const Vec2& p : points) centroid += p;
  centroid /= static_cast<double>(points.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const Vec2& p : points) scatter += (p - centroid) * (p - centroid).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(scatter);
  Line2 line;
  line.normal = eigen.eigenvectors().col(0).normalized();
  line.offset = -line.normal.dot(centroid);
  // Normal towards the sensor (the origin on the positive side), as planes have d > 0.
  if (line.offset < 0) {
    line.normal = -line.normal;
    line.offset = -line.offset;
  }
  return line;
}

// ---------------------------------------------------------------------------------------------
// Depth side (paper Section 3.1, Eq. (6)–(7)).

bool DepthFeatureOptions::Check(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (stride_px < 1) return fail("stride_px must be >= 1");
  if (!(max_depth_m > 0)) return fail("max_depth_m must be > 0 (metres)");
  if (!(plane_threshold_m > 0)) return fail("plane_threshold_m must be > 0 (metres)");
  if (!(plane_threshold_per_m2 >= 0)) return fail("plane_threshold_per_m2 must be >= 0 (1/m)");
  if (min_inliers_per_face < 4) return fail("min_inliers_per_face must be >= 4");
  if (max_planes < 3) return fail("max_planes must be >= 3 (the target has three faces)");
  if (!(min_face_angle_deg >= 0 && min_face_angle_deg < 90))
    return fail("min_face_angle_deg must be in [0, 90)");
  return true;
}

DepthFeatures ExtractDepthFeatures(const DepthImage& depth, const ThreeFaceTarget& target,
                                   const DepthFeatureOptions& options, const DepthRegion* region) {
  DepthFeatures out;
  std::string why;
  if (!options.Check(&why)) {
    out.reason = "bad depth feature options: " + why;
    return out;
  }
  if (!target.Check(&why)) {
    out.reason = "bad target: " + why;
    return out;
  }
  const DepthIntrinsics& k = depth.intrinsics;
  if (k.width <= 0 || k.height <= 0 || !(k.fx > 0) || !(k.fy > 0)) {
    out.reason = "depth image has no valid intrinsics (size " + std::to_string(k.width) + "x" +
                 std::to_string(k.height) + ", fx and fy must be > 0)";
    return out;
  }
  if (depth.depth_m.size() != static_cast<size_t>(k.width) * k.height) {
    out.reason = "depth image holds " + std::to_string(depth.depth_m.size()) +
                 " values, expected " + std::to_string(k.width) + "x" + std::to_string(k.height);
    return out;
  }
  DepthRegion window{0, 0, k.width, k.height};
  if (region) {
    window = DepthRegion{std::clamp(region->u0, 0, k.width), std::clamp(region->v0, 0, k.height),
                         std::clamp(region->u1, 0, k.width), std::clamp(region->v1, 0, k.height)};
  }
  DepthCloud cloud = BackProject(depth, window, options.stride_px, options.max_depth_m);
  if (cloud.points.empty()) {
    out.reason =
        region ? "no depth data inside the selected region" : "no depth data (all pixels 0)";
    return out;
  }

  ComputeNormals(k, options, &cloud);

  // Fig. 7 (c)–(d): segment planes, pick the target's three, refit.
  const std::vector<PlanePatch> patches = ExtractPlanes(cloud, target, options);
  const auto triple = ChooseTriple(cloud, patches, target);
  if (!triple) {
    out.reason = "fewer than three faces found: " + std::to_string(patches.size()) +
                 " planes with >= " + std::to_string(options.min_inliers_per_face) +
                 " connected points, no three of them with the target's face angles, size and "
                 "layout";
    return out;
  }
  std::array<PlanePatch, 3> faces = {patches[(*triple)[0]], patches[(*triple)[1]],
                                     patches[(*triple)[2]]};
  for (int iteration = 0; iteration < 2; ++iteration) {
    if (!ReassignAndRefit(cloud, options, &faces)) {
      out.reason = "fewer than three faces found: after separating the faces one has fewer than " +
                   std::to_string(options.min_inliers_per_face) + " points";
      return out;
    }
  }

  out.min_face_angle_deg = 90.0;
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3;
    const double angle = UnsignedAngleDeg(faces[a].plane.normal, faces[b].plane.normal);
    out.min_face_angle_deg = std::min(out.min_face_angle_deg, angle);
    if (angle < options.min_face_angle_deg) {
      out.reason = std::string(kFaceNames[a]) + " and " + kFaceNames[b] + " are within " +
                   Format("%.1f", options.min_face_angle_deg) + "° of parallel (" +
                   Format("%.1f°)", angle);
      return out;
    }
  }
  const auto apex = MeetingPoint(faces[0].plane, faces[1].plane, faces[2].plane);
  if (!apex) {
    out.reason = "the three faces do not meet in a point";
    return out;
  }
  auto centroid = [&](std::initializer_list<int> which) {
    Vec3 sum = Vec3::Zero();
    double n = 0;
    for (int f : which)
      for (int i : faces[f].inliers) sum += cloud.points[i], n += 1;
    return Vec3(sum / n);
  };
  // Eq. (7): AB = base ∩ ABC, AC = ABC ∩ ACD, AD = ACD ∩ base; each through A, pointing from A
  // into the face it borders (towards B, C, D).
  const std::array<Vec3, 3> towards = {centroid({1}), centroid({1, 2}), centroid({2})};
  double sum_sq = 0.0;
  size_t total = 0;
  for (int f = 0; f < 3; ++f) {
    out.planes[f] = faces[f].plane;
    out.plane_covariances[f] = faces[f].covariance;
    out.inlier_counts[f] = static_cast<int>(faces[f].inliers.size());
    auto line = IntersectPlanes(faces[f].plane, faces[(f + 1) % 3].plane);
    if (!line) {
      out.reason = std::string(kFaceNames[f]) + " and " + kFaceNames[(f + 1) % 3] + " are parallel";
      return out;
    }
    line->point = line->point + line->direction.dot(*apex - line->point) * line->direction;
    if (line->direction.dot(towards[f] - *apex) < 0) line->direction = -line->direction;
    out.lines[f] = *line;
    sum_sq += faces[f].rms_m * faces[f].rms_m * faces[f].inliers.size();
    total += faces[f].inliers.size();
  }
  out.rms_m = std::sqrt(sum_sq / total);

  out.face_of_pixel.assign(static_cast<size_t>(k.width) * k.height, -1);
  for (int f = 0; f < 3; ++f)
    for (int i : faces[f].inliers)
      for (int v = cloud.pixel_v[i]; v < std::min(k.height, cloud.pixel_v[i] + options.stride_px);
           ++v)
        for (int u = cloud.pixel_u[i]; u < std::min(k.width, cloud.pixel_u[i] + options.stride_px);
             ++u)
          out.face_of_pixel[static_cast<size_t>(v) * k.width + u] = static_cast<signed char>(f);
  out.ok = true;
  return out;
}

// ---------------------------------------------------------------------------------------------
// Checkerboard case (Zhang & Pless 2004).

bool BoardScanOptions::Check(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (!(line_threshold_m > 0)) return fail("line_threshold_m must be > 0 (metres)");
  if (min_points < 2) return fail("min_points must be >= 2");
  if (!(break_distance_m > 0)) return fail("break_distance_m must be > 0 (metres)");
  return true;
}

BoardScanPoints ExtractBoardScanPoints(const LaserScan& scan, const BoardScanOptions& options,
                                       const ScanRegion* region) {
  BoardScanPoints out;
  std::string why;
  if (!options.Check(&why)) {
    out.reason = "bad board scan options: " + why;
    return out;
  }
  if (scan.ranges.empty()) {
    out.reason = "scan is empty";
    return out;
  }
  // Breaks as for the three-face target (6 ray spacings allow for grazing incidence).
  const std::vector<Polyline> polylines =
      SplitAtRangeBreaks(scan, region, options.break_distance_m, 6.0);
  if (polylines.empty()) {
    out.reason = region ? "no valid returns inside the selected region" : "no valid returns";
    return out;
  }
  // Inside a region: all its returns are candidates. Otherwise the straight run with the most
  // returns.
  Polyline candidates;
  if (region) {
    for (const Polyline& polyline : polylines)
      candidates.insert(candidates.end(), polyline.begin(), polyline.end());
  } else {
    for (const Polyline& polyline : polylines)
      for (const auto& [first, last] :
           SplitAndMerge(SmoothPolyline(polyline), options.line_threshold_m))
        if (last - first + 1 > static_cast<int>(candidates.size()))
          candidates.assign(polyline.begin() + first, polyline.begin() + last + 1);
  }
  if (static_cast<int>(candidates.size()) < std::max(2, options.min_points)) {
    out.reason = "no straight run of at least " + std::to_string(options.min_points) +
                 " returns (longest has " + std::to_string(candidates.size()) + ")";
    return out;
  }
  std::vector<Vec2> points;
  for (const ScanPoint& p : candidates) points.push_back(p.point);
  std::vector<int> inliers;
  out.line = RobustFitLine(points, options.line_threshold_m, 200, &inliers);
  if (static_cast<int>(inliers.size()) < options.min_points) {
    out.reason = "the board line has only " + std::to_string(inliers.size()) + " returns (need " +
                 std::to_string(options.min_points) + ")";
    return out;
  }
  double sum_sq = 0.0;
  for (int i : inliers) {
    out.points.push_back(points[i]);
    out.indices.push_back(candidates[i].index);
    sum_sq += std::pow(out.line.SignedDistance(points[i]), 2);
  }
  out.rms_m = std::sqrt(sum_sq / inliers.size());
  out.ok = true;
  return out;
}

}  // namespace calibench
