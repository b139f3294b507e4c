// What guidance knows of the two sensors, learnt from the data seen so far (next_pose.h): the
// LiDAR's rings from its clouds, the usable distances and the sensors' noise from the pairs.
#include <algorithm>
#include <cmath>
#include <map>

#include "core/base/statistics.h"
#include "core/guidance/next_pose.h"
#include "core/lidar/lidar_geometry.h"
#include "core/target/lidar_noise.h"

namespace calibench {

BeamTable LearnBeamTable(const std::vector<const LidarCloud*>& clouds) {
  std::map<int, std::vector<double>> elevations;
  std::vector<double> gaps;
  for (const LidarCloud* cloud : clouds) {
    if (!cloud || !cloud->HasRing()) continue;
    std::map<int, std::vector<double>> azimuths;
    for (size_t i = 0; i < cloud->size(); ++i) {
      const Eigen::Vector3f& p = cloud->points[i];
      if (!p.allFinite() || p.squaredNorm() < 1e-6f) continue;
      elevations[cloud->ring[i]].push_back(std::atan2(p.z(), std::hypot(p.x(), p.y())));
      azimuths[cloud->ring[i]].push_back(std::atan2(p.y(), p.x()));
    }
    for (auto& [ring, values] : azimuths) {
      if (values.size() < 20) continue;
      std::sort(values.begin(), values.end());
      for (size_t k = 1; k < values.size(); ++k)
        if (values[k] - values[k - 1] > 1e-5) gaps.push_back(values[k] - values[k - 1]);
    }
  }
  BeamTable table;
  for (auto& [ring, values] : elevations)
    if (values.size() >= 20) table.elevations_rad.push_back(Median(values));
  std::sort(table.elevations_rad.begin(), table.elevations_rad.end());
  const double gap = Median(gaps);
  table.azimuth_steps = gap > 0 ? static_cast<int>(std::lround(2 * M_PI / gap)) : 0;
  if (table.elevations_rad.size() >= 2 && table.azimuth_steps >= 1) return table;
  // No rings: the rays of the ring-less scan with the most returns (a whole scan, not a board's
  // segment, whose rays cover its board alone).
  const LidarCloud* widest = nullptr;
  for (const LidarCloud* cloud : clouds)
    if (cloud && !cloud->HasRing() && (!widest || cloud->size() > widest->size()) &&
        ClassifyLidarGeometry(*cloud).geometry != LidarGeometry::kSegment)
      widest = cloud;
  if (!widest) return table;
  std::vector<Vec3> returns;
  returns.reserve(widest->size());
  for (const Eigen::Vector3f& p : widest->points)
    if (p.allFinite()) returns.push_back(p.cast<double>());
  return LearntRayTable(returns);
}

std::optional<SensorGeometry> LearnSensorGeometry(const CameraModel& camera, const BoardSpec& board,
                                                  const BeamTable& lidar,
                                                  const std::vector<PairFeatures>& pairs,
                                                  std::string* why) {
  std::vector<double> distances, range_rms, corner_sigmas;
  std::vector<RangeResidualMoments> moments;
  for (const PairFeatures& p : pairs) {
    if (p.status != PairStatus::kAccepted || !p.lidar || !p.camera) continue;
    distances.push_back(p.camera->cam_from_board.translation().norm());
    range_rms.push_back(p.lidar->rms_m);
    corner_sigmas.push_back(p.camera->corner_sigma_px);
    if (p.lidar->range_moments.count > 0) moments.push_back(p.lidar->range_moments);
  }
  if (distances.empty()) {
    *why = "no accepted pair yet: the distances and the sensors' noise are learnt from the data";
    return std::nullopt;
  }
  if (!lidar.Fired() && (lidar.elevations_rad.size() < 2 || lidar.azimuth_steps < 1)) {
    *why =
        "the clouds carry no ring numbers and no whole scan (board segments only): the LiDAR's "
        "rays cannot be learnt";
    return std::nullopt;
  }
  SensorGeometry sensors;
  sensors.camera = camera;
  sensors.board = board;
  sensors.lidar = lidar;
  const auto [nearest, farthest] = std::minmax_element(distances.begin(), distances.end());
  double low = *nearest * 0.9, high = *farthest * 1.1;
  if (high - low < 1.0) {
    const double centre = 0.5 * (low + high);
    low = centre - 0.5;
    high = centre + 0.5;
  }
  sensors.min_distance_m = std::max({low, *nearest - 0.5, 0.3});
  sensors.max_distance_m = std::max(high, sensors.min_distance_m + 0.5);
  sensors.range_sigma_m = std::max(Median(range_rms), 1e-3);
  // Where the boards resolve a beam jitter, a return's noise grows with its range and incidence:
  // the intercept is the range term and the slope the angular one (the median RMS held both).
  if (const LidarNoiseEstimate noise = EstimateLidarNoise(moments); noise.angular_resolved) {
    sensors.range_sigma_m = std::max(noise.range_sigma_median_m, 1e-3);
    sensors.angular_sigma_rad = noise.angular_sigma_rad;
  }
  sensors.corner_sigma_px = std::max(Median(corner_sigmas), 0.05);
  return sensors;
}

}  // namespace calibench
