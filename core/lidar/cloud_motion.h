// Whether the scene moved between two sweeps of a spinning LiDAR, from the sweeps alone: each
// sweep is reduced to a range grid (rows = rings or elevation bins, columns = azimuth bins) and
// two grids are compared cell by cell. Import uses it to find the moments a board is held still
// before it looks at a single image (core/capture/recording_pairs.h).
#pragma once

#include <string>
#include <vector>

#include "core/lidar/cloud.h"

namespace calibench {

struct CloudMotionOptions {
  double azimuth_bin_deg = 1.0;    // grid columns; a VLP-16 fires every 0.2 deg at 10 Hz
  double elevation_bin_deg = 1.0;  // grid rows when the cloud has no ring field
  // A cell changed when its range differs from every occupied cell of the other sweep's same row
  // within one column (the firing phase drifts between sweeps) by more than
  // max(range_tolerance_m, relative_range_tolerance * range). Far above a VLP-16's ~2 cm noise.
  double range_tolerance_m = 0.08;
  double relative_range_tolerance = 0.02;
  // Two sweeps agree when at most max(min_changed_cells, max_changed_fraction * cells seen in
  // both) cells changed: an A4 sheet moved at 2 m changes ~25 cells of a VLP-16's ~5,800.
  int min_changed_cells = 6;
  double max_changed_fraction = 0.002;
  // A sensor noisier than that (mixed returns at edges, rain, glass) raises the bar to this
  // multiple of its own floor: the 10th percentile of the changed fraction between consecutive
  // sweeps over the last `noise_floor_sweeps` (a capture is mostly holds).
  double noise_floor_factor = 3.0;
  int noise_floor_sweeps = 300;
  // But not beyond this fraction: a person carrying a board changes 3-10 % of a VLP-16's cells
  // (the real ACFR sweeps). A sensor whose floor is higher sees nothing still, and import then
  // tries a sweep every second and lets the camera judge.
  double max_noise_fraction = 0.02;
  bool Check(std::string* why) const;
};

// A sweep as a range grid: the nearest return per cell, 0 where none fell.
struct SweepGrid {
  int rows = 0, columns = 0;
  std::vector<float> range_m;  // rows * columns
};

SweepGrid MakeSweepGrid(const LidarCloud& cloud, const CloudMotionOptions& options);

struct SweepChange {
  int common_cells = 0;   // cells of `current` with a return near them in `reference`
  int changed_cells = 0;  // of those, the ones whose range moved beyond the tolerance
  bool agree = false;     // the scene held still between the sweeps (options' rule)
};

// `current` against `reference` (grids of the same options); grids of different shapes (another
// sensor, another ring count) never agree. `noise_floor` is SweepNoiseFloor::Fraction().
SweepChange CompareSweeps(const SweepGrid& reference, const SweepGrid& current,
                          const CloudMotionOptions& options, double noise_floor = 0.0);

// The changed fraction a still scene shows on this sensor, learnt from consecutive sweeps.
class SweepNoiseFloor {
 public:
  explicit SweepNoiseFloor(const CloudMotionOptions& options) : options_(options) {}
  void Add(const SweepChange& consecutive);
  double Fraction() const;  // 0 until a few sweeps came

 private:
  CloudMotionOptions options_;
  std::vector<double> recent_;  // ring buffer of changed fractions
  std::size_t next_ = 0;
};

}  // namespace calibench
