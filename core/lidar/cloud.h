// LiDAR point clouds with optional per-point intensity, ring, range, ray origin and time (files:
// core/io/cloud_io.h).
#pragma once

#include <vector>

#include "core/base/types.h"

namespace calibench {

struct LidarCloud {
  std::vector<Eigen::Vector3f> points;  // metres, LiDAR frame
  std::vector<float> intensity;         // empty when the file has none
  std::vector<int> ring;                // laser index, 0 = lowest beam; empty when unknown
  std::vector<float> range;             // metres; empty when the file has none
  // Where each return's ray starts (metres, LiDAR frame): a swept scanner's mirror as the stage
  // turned it, written by its driver (PCD / PLY / PointCloud2 fields vp_x, vp_y, vp_z, as PCL's
  // PointWithViewpoint). Empty: every ray starts at the LiDAR's origin.
  std::vector<Eigen::Vector3f> viewpoint;
  // Each return's time, seconds after the cloud's stamp (the pair's lidar_stamp_ns; negative for
  // returns before it, as a driver that stamps the sweep's end gives them): the drivers' fields
  // read by core/lidar/point_times.h, a PCD / PLY field `t`. Empty: the cloud is instantaneous.
  std::vector<float> time_s;
  // Organized clouds (height > 1) store rows = rings, columns = firing order.
  int width = 0;
  int height = 1;

  size_t size() const { return points.size(); }
  bool HasIntensity() const { return !intensity.empty(); }
  bool HasRing() const { return !ring.empty(); }
  bool HasViewpoint() const { return !viewpoint.empty(); }
  bool HasTime() const { return !time_s.empty(); }
  // Where return i's ray starts (see viewpoint).
  Eigen::Vector3d RayOrigin(size_t i) const {
    if (viewpoint.empty()) return Eigen::Vector3d::Zero();
    return viewpoint[i].cast<double>();
  }
  bool IsOrganized() const { return height > 1 && static_cast<size_t>(width) * height == size(); }
};

}  // namespace calibench
