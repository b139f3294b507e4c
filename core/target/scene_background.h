// The static scene of a dataset's clouds: which returns belong to what stays put between pairs
// (walls, cabinets), so that board detection can leave them out (the board moves, they do not).
#pragma once

#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/lidar/cloud.h"
#include "core/lidar/lidar_geometry.h"  // CloudExtentM, kSegmentExtentM

namespace calibench {

// Which returns of a dataset's clouds belong to the static scene: per angular cell (ring or
// elevation bin x azimuth bin), the median range over the clouds. Valid when the sensor stayed
// put; Finish() checks that and says why not.
class SceneBackground {
 public:
  explicit SceneBackground(double cell_deg = 0.5, double tolerance_m = 0.05);
  void Add(const LidarCloud& cloud);
  // Computes the medians; false with *why when fewer than 3 clouds were added or the scene does
  // not repeat, saying what was seen (segments rather than scans, or scans that differ), after
  // which IsStatic answers false.
  bool Finish(std::string* why);
  bool usable() const { return usable_; }
  int clouds() const { return clouds_; }
  // True when the return lies within the tolerance of its cell's median range and the cell held a
  // return in at least half of the clouds.
  bool IsStatic(const LidarCloud& cloud, int index) const;

 private:
  std::int64_t Key(const LidarCloud& cloud, int index) const;
  double cell_rad_;
  double tolerance_m_;
  int clouds_ = 0;
  bool usable_ = false;
  std::unordered_map<std::int64_t, std::vector<float>> ranges_;  // per cell, nearest per cloud
  std::unordered_map<std::int64_t, float> median_;
  std::vector<double> azimuth_span_deg_;  // per cloud: the azimuth its returns cover
  std::vector<double> extent_m_;          // per cloud: CloudExtentM
};

}  // namespace calibench
