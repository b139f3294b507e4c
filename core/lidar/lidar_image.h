// The projection by ID of Ca²Lib Eq. (10)–(12): rows are rings, columns are azimuth bins.
#pragma once

#include <vector>

#include "core/lidar/cloud.h"

namespace calibench {

struct LidarImageOptions {
  int columns = 0;  // azimuth bins over 360 degrees; 0 = choose from the cloud (about 1 per point)
  // Elevation clustering when neither ring nor organized layout is known: a new ring starts
  // where sorted elevations jump by more than this (radians). Default 0.15 deg.
  double ring_gap_rad = 0.15 * kDegToRad;
  bool Check(std::string* why) const;
};

// Ring index per point: the cloud's own, else the organized row, else elevation clustering.
// Rings are numbered from the lowest elevation (0) upwards.
std::vector<int> InferRings(const LidarCloud& cloud, const LidarImageOptions& options);

struct LidarImage {
  int rows = 0;  // number of rings; row 0 is the highest ring (drawn on top)
  int columns =
      0;  // azimuth bins; column 0 at azimuth +pi (left), increasing clockwise seen from above
  // Per pixel: index into the cloud, -1 where no point fell (Eq. (10)–(12)).
  std::vector<int> point_index;
  std::vector<float> intensity;  // NaN where empty; raw intensity (range when the cloud has none)
  std::vector<float> range;      // metres, NaN where empty
  std::vector<int> ring_of_row;  // ring id shown in each row
  // Mean elevation of each row's returns (radians, NaN for an empty row): what the workbench
  // needs to draw rows at the sensor's angular aspect.
  std::vector<float> row_elevation_rad;
  // Per point: the pixel it landed in (row * columns + col), or -1 when another point won the
  // pixel.
  std::vector<int> pixel_of_point;

  int PixelIndex(int row, int col) const { return row * columns + col; }
  // The elevation the rows span (highest minus lowest row, plus one median row step), radians;
  // 0 when fewer than two rows hold returns.
  double VerticalSpanRad() const;
};

// The cell side (degrees) of an azimuth x elevation raster of a ring-less cloud: about one return
// per cell over the solid angle the returns cover (counted on a 1° grid), grown until at least
// 60 % of the covered cells hold a return (a rosette lays its returns along curves), at most 1°.
double RasterCellDeg(const LidarCloud& cloud);

// Builds the image; within a pixel the nearest point wins. A cloud without rings (no ring field,
// not organized, no thin cones of elevation) gets rows of RasterCellDeg's elevation bins.
LidarImage ProjectById(const LidarCloud& cloud, const LidarImageOptions& options);

// Azimuth column of a point, Eq. (10)–(11): u = fx·atan2(y, x) + cx with fx = -columns/(2 pi)
// and cx = columns/2 (so that forward, +x, is in the middle and left, +y, is on the left).
int AzimuthColumn(const Eigen::Vector3f& point, int columns);

}  // namespace calibench
