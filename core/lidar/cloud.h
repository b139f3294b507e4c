// LiDAR point clouds with optional per-point intensity, ring and range (files: core/io/cloud_io.h).
#pragma once

#include <vector>

#include "core/base/types.h"

namespace calibench {

struct LidarCloud {
  std::vector<Eigen::Vector3f> points;  // metres, LiDAR frame
  std::vector<float> intensity;         // empty when the file has none
  std::vector<int> ring;                // laser index, 0 = lowest beam; empty when unknown
  std::vector<float> range;             // metres; empty when the file has none
  // Organized clouds (height > 1) store rows = rings, columns = firing order.
  int width = 0;
  int height = 1;

  size_t size() const { return points.size(); }
  bool HasIntensity() const { return !intensity.empty(); }
  bool HasRing() const { return !ring.empty(); }
  bool IsOrganized() const { return height > 1 && static_cast<size_t>(width) * height == size(); }
};

}  // namespace calibench
