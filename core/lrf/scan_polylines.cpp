// Straight lines in a 2D laser scan: its valid returns as polylines split at range breaks, the
// straight runs of a polyline (split and merge), and line fits (least squares, robust). The
// three-face target's matching on top of them is scan_lines.cpp's.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <random>

#include "core/lrf/scan_lines.h"

namespace calibench {

namespace {

// Valid returns (inside the region when given), in scan order, split where consecutive returns
// are further apart than max(break_distance, factor · r · Δθ · rays between them). A single
// noisy return (the R2000's σ is a fifth of the default break distance) must not split a face:
// the jump must also hold between the returns on either side of the pair.
std::vector<ScanPolyline> SplitAtRangeBreaks(const LaserScan& scan, const ScanRegion* region,
                                             double break_distance_m, double break_angle_factor) {
  ScanPolyline valid;
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
  std::vector<ScanPolyline> polylines;
  ScanPolyline current;
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
std::vector<Vec2> SmoothPolyline(const ScanPolyline& polyline) {
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

// ---------------------------------------------------------------------------------------------
// Finding the target: four straight segments in a row (paper Fig. 6 (c)).

}  // namespace

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

std::vector<ScanPolyline> ScanPolylines(const LaserScan& scan, const ScanRegion* region,
                                        double break_distance_m, double break_angle_factor,
                                        std::string* reason) {
  if (scan.ranges.empty()) {
    *reason = "scan is empty";
    return {};
  }
  std::vector<ScanPolyline> polylines =
      SplitAtRangeBreaks(scan, region, break_distance_m, break_angle_factor);
  if (polylines.empty())
    *reason = region ? "no valid returns inside the selected region" : "no valid returns";
  return polylines;
}

std::vector<std::pair<int, int>> StraightRuns(const ScanPolyline& polyline, double threshold_m) {
  return SplitAndMerge(SmoothPolyline(polyline), threshold_m);
}

// The RANSAC stage is deterministic (fixed seed) so that a scan always gives the same lines. The
// second selection uses max(threshold, 3σ), σ = 1.4826 · median |residual| (the MAD scale of a
// Gaussian): robust to the R2000's noise being larger than the threshold assumes.
Line2 RobustFitLine(const std::vector<Vec2>& points, double threshold_m, int iterations,
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
    for (const Vec2& p : points) count += std::abs(candidate.SignedDistance(p)) <= threshold_m;
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
  std::vector<Vec2> chosen = select(best, threshold_m);
  if (chosen.size() < 2) return best;
  Line2 line = FitLine2(chosen);
  std::vector<double> residuals;
  for (const Vec2& p : points) residuals.push_back(std::abs(line.SignedDistance(p)));
  std::nth_element(residuals.begin(), residuals.begin() + n / 2, residuals.end());
  const double sigma = 1.4826 * residuals[n / 2];
  chosen = select(line, std::max(threshold_m, 3.0 * sigma));
  return chosen.size() >= 2 ? FitLine2(chosen) : line;
}

double LineRms(const Line2& line, const std::vector<Vec2>& points) {
  double sum_sq = 0.0;
  for (const Vec2& p : points) sum_sq += std::pow(line.SignedDistance(p), 2);
  return std::sqrt(sum_sq / points.size());
}

}  // namespace calibench
