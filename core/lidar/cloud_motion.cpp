#include "core/lidar/cloud_motion.h"

#include <algorithm>
#include <cmath>

namespace calibench {

bool CloudMotionOptions::Check(std::string* why) const {
  if (!(azimuth_bin_deg > 0.0 && azimuth_bin_deg <= 10.0)) {
    *why = "azimuth_bin_deg must be in (0, 10]";
    return false;
  }
  if (!(elevation_bin_deg > 0.0 && elevation_bin_deg <= 10.0)) {
    *why = "elevation_bin_deg must be in (0, 10]";
    return false;
  }
  if (!(range_tolerance_m > 0.0) || !(relative_range_tolerance >= 0.0)) {
    *why = "range_tolerance_m must be > 0 and relative_range_tolerance >= 0";
    return false;
  }
  if (min_changed_cells < 0 || !(max_changed_fraction >= 0.0 && max_changed_fraction < 1.0)) {
    *why = "min_changed_cells must be >= 0 and max_changed_fraction in [0, 1)";
    return false;
  }
  if (!(noise_floor_factor >= 0.0) || noise_floor_sweeps < 1 ||
      !(max_noise_fraction >= 0.0 && max_noise_fraction < 1.0)) {
    *why = "noise_floor_factor must be >= 0, noise_floor_sweeps >= 1, max_noise_fraction in [0, 1)";
    return false;
  }
  return true;
}

SweepGrid MakeSweepGrid(const LidarCloud& cloud, const CloudMotionOptions& options) {
  SweepGrid grid;
  grid.columns = std::max(1, static_cast<int>(std::lround(360.0 / options.azimuth_bin_deg)));
  const bool rings = cloud.HasRing();
  // Without rings: elevation bins over [-90, 90] deg.
  const int elevation_rows = static_cast<int>(std::ceil(180.0 / options.elevation_bin_deg));
  if (rings) {
    int top = 0;
    for (int ring : cloud.ring) top = std::max(top, ring);
    grid.rows = top + 1;
  } else {
    grid.rows = elevation_rows;
  }
  grid.range_m.assign(static_cast<std::size_t>(grid.rows) * grid.columns, 0.0f);
  const double columns_per_rad = grid.columns / (2.0 * M_PI);
  const double rows_per_rad = 1.0 / (options.elevation_bin_deg * kDegToRad);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    const float range = p.norm();
    if (!std::isfinite(range) || range <= 0.0f) continue;
    int row = 0;
    if (rings) {
      row = cloud.ring[i];
      if (row < 0) continue;
    } else {
      const double elevation = std::asin(std::clamp(p.z() / range, -1.0f, 1.0f));
      row = std::clamp(static_cast<int>((elevation + M_PI / 2) * rows_per_rad), 0, grid.rows - 1);
    }
    const double azimuth = std::atan2(p.y(), p.x()) + M_PI;  // [0, 2 pi]
    const int column = static_cast<int>(azimuth * columns_per_rad) % grid.columns;
    float& cell = grid.range_m[static_cast<std::size_t>(row) * grid.columns + column];
    if (cell == 0.0f || range < cell) cell = range;
  }
  return grid;
}

SweepChange CompareSweeps(const SweepGrid& reference, const SweepGrid& current,
                          const CloudMotionOptions& options, double noise_floor) {
  SweepChange change;
  if (reference.rows != current.rows || reference.columns != current.columns) return change;
  const int columns = current.columns;
  for (int row = 0; row < current.rows; ++row) {
    const float* now = &current.range_m[static_cast<std::size_t>(row) * columns];
    const float* before = &reference.range_m[static_cast<std::size_t>(row) * columns];
    for (int column = 0; column < columns; ++column) {
      const float range = now[column];
      if (range == 0.0f) continue;
      float nearest = INFINITY;
      for (int step = -1; step <= 1; ++step) {
        const float other = before[(column + step + columns) % columns];
        if (other != 0.0f) nearest = std::min(nearest, std::abs(other - range));
      }
      if (!std::isfinite(nearest)) continue;
      ++change.common_cells;
      const double tolerance =
          std::max(options.range_tolerance_m, options.relative_range_tolerance * range);
      if (nearest > tolerance) ++change.changed_cells;
    }
  }
  const double fraction =
      std::max(options.max_changed_fraction,
               std::min(options.noise_floor_factor * noise_floor, options.max_noise_fraction));
  const double allowed =
      std::max<double>(options.min_changed_cells, fraction * change.common_cells);
  change.agree = change.common_cells > 0 && change.changed_cells <= allowed;
  return change;
}

void SweepNoiseFloor::Add(const SweepChange& consecutive) {
  if (consecutive.common_cells == 0) return;
  const double fraction = static_cast<double>(consecutive.changed_cells) /
                          static_cast<double>(consecutive.common_cells);
  if (recent_.size() < static_cast<std::size_t>(options_.noise_floor_sweeps)) {
    recent_.push_back(fraction);
  } else {
    recent_[next_] = fraction;
    next_ = (next_ + 1) % recent_.size();
  }
}

double SweepNoiseFloor::Fraction() const {
  constexpr std::size_t kMinSweeps = 10;
  if (recent_.size() < kMinSweeps) return 0.0;
  std::vector<double> sorted = recent_;
  const auto tenth = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 10);
  std::nth_element(sorted.begin(), tenth, sorted.end());
  return *tenth;
}

}  // namespace calibench
