// The board in the 2D laser scan: the LRF ↔ RGB camera checkerboard case (Zhang & Pless 2004),
// whose only scan feature is the returns on the board plane.
#pragma once

#include <string>
#include <vector>

#include "core/lrf_data/dataset.h"
#include "core/lrf_data/types.h"

namespace calibench {

struct BoardScanOptions {
  double line_threshold_m = 0.02;  // split-and-merge / RANSAC inlier distance (metres)
  int min_points = 10;             // returns on the board line
  double break_distance_m = 0.06;  // consecutive returns further apart start a new run (metres)
  bool Check(std::string* why) const;
};

// The scan returns on the board plane (LRF frame, metres). Inside `region` when given; otherwise
// the longest straight run. Fails (ok false, reason set) when none.
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
