// Internal to the LiDAR board detection: the cloud on an angular grid (rows = rings, or elevation
// bins for ring-less clouds; columns = azimuth bins), the neighbourhood every step works in.
#pragma once

#include <utility>
#include <vector>

#include "core/base/types.h"
#include "core/geometry/geometry.h"
#include "core/lidar/cloud.h"

namespace calibench::board_grid {

struct AngularGrid {
  int rows = 0;
  int columns = 0;
  std::vector<int> point;        // per cell: cloud index of its nearest return, -1 where empty
  std::vector<float> range;      // per cell, metres; NaN where empty
  double row_step_rad = 0.0;     // elevation between rows (median between rings)
  double column_step_rad = 0.0;  // azimuth between columns
  bool from_rings = false;

  int Cell(int row, int column) const { return row * columns + column; }
  int Wrap(int column) const { return ((column % columns) + columns) % columns; }
  // Columns spanning one row step: the half width of a neighbourhood that is about as wide as it is
  // tall.
  int HalfWindowColumns() const;
  // The half size (rows, columns) of the neighbourhood of a return at `range_m`: at least one row
  // step, and at least `half_size_m` each way, so that dense sensors fit their local planes over
  // enough surface to rise above the range noise.
  std::pair<int, int> HalfWindow(double range_m, double half_size_m) const;
};

// Rings (the cloud's own, its organized rows, or clear elevation clusters) where they exist, else
// an azimuth x elevation grid of `cell_deg` (0 = about one return per cell).
AngularGrid BuildAngularGrid(const LidarCloud& cloud, double cell_deg);

// The fraction of a segment's border (its cells, marked in `in_segment`) with nothing right
// behind its plane: a return more than `jump_m` behind, or none (lidar_board_detect.cpp's
// "standing free").
double FreeEdgeFraction(const LidarCloud& cloud, const AngularGrid& grid,
                        const std::vector<int>& cells, const std::vector<char>& in_segment,
                        const Plane& plane, double jump_m);

// A convex hull (counter-clockwise) and its minimum-area enclosing rectangle.
std::vector<Vec2> ConvexHull(std::vector<Vec2> points);
double PolygonArea(const std::vector<Vec2>& polygon);
Vec2 MinAreaRectangle(const std::vector<Vec2>& hull);  // long side, short side

}  // namespace calibench::board_grid
