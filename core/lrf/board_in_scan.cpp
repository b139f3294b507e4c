// The board in the 2D laser scan (Zhang & Pless 2004): the returns on the board plane.
#include "core/lrf/board_in_scan.h"

#include <algorithm>
#include <cmath>

#include "core/lrf/scan_lines.h"

namespace calibench {

namespace {

// The returns that may lie on the board: inside a region, all of its returns (the user selected
// the board); otherwise the straight run with the most returns.
ScanPolyline BoardCandidates(const std::vector<ScanPolyline>& polylines, bool in_region,
                             double line_threshold_m) {
  ScanPolyline candidates;
  if (in_region) {
    for (const ScanPolyline& polyline : polylines)
      candidates.insert(candidates.end(), polyline.begin(), polyline.end());
    return candidates;
  }
  for (const ScanPolyline& polyline : polylines)
    for (const auto& [first, last] : StraightRuns(polyline, line_threshold_m))
      if (last - first + 1 > static_cast<int>(candidates.size()))
        candidates.assign(polyline.begin() + first, polyline.begin() + last + 1);
  return candidates;
}

// The board line through the candidates (RobustFitLine) and its inlier returns; false with a
// reason when fewer than options.min_points remain.
bool FitBoardLine(const ScanPolyline& candidates, const BoardScanOptions& options,
                  BoardScanPoints* out) {
  std::vector<Vec2> points;
  for (const ScanPoint& p : candidates) points.push_back(p.point);
  std::vector<int> inliers;
  out->line = RobustFitLine(points, options.line_threshold_m, 200, &inliers);
  if (static_cast<int>(inliers.size()) < options.min_points) {
    out->reason = "the board line has only " + std::to_string(inliers.size()) + " returns (need " +
                  std::to_string(options.min_points) + ")";
    return false;
  }
  for (int i : inliers) {
    out->points.push_back(points[i]);
    out->indices.push_back(candidates[i].index);
  }
  out->rms_m = LineRms(out->line, out->points);
  return true;
}

}  // namespace

bool BoardScanOptions::Check(std::string* why) const {
  if (!(line_threshold_m > 0)) return FailCheck(why, "line_threshold_m must be > 0 (metres)");
  if (min_points < 2) return FailCheck(why, "min_points must be >= 2");
  if (!(break_distance_m > 0)) return FailCheck(why, "break_distance_m must be > 0 (metres)");
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
  // Breaks as for the three-face target (6 ray spacings allow for grazing incidence).
  const std::vector<ScanPolyline> polylines =
      ScanPolylines(scan, region, options.break_distance_m, 6.0, &out.reason);
  if (polylines.empty()) return out;
  const ScanPolyline candidates =
      BoardCandidates(polylines, region != nullptr, options.line_threshold_m);
  if (static_cast<int>(candidates.size()) < std::max(2, options.min_points)) {
    out.reason = "no straight run of at least " + std::to_string(options.min_points) +
                 " returns (longest has " + std::to_string(candidates.size()) + ")";
    return out;
  }
  if (!FitBoardLine(candidates, options, &out)) return out;
  out.ok = true;
  return out;
}

}  // namespace calibench
