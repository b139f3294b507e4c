#include "core/target/scene_background.h"

#include <algorithm>
#include <cmath>
#include <unordered_set>

#include "core/base/text.h"
#include "core/base/types.h"

namespace calibench {

SceneBackground::SceneBackground(double cell_deg, double tolerance_m)
    : cell_rad_(cell_deg * kDegToRad), tolerance_m_(tolerance_m) {
  CALIBENCH_CHECK(cell_deg > 0 && tolerance_m > 0);
}

std::int64_t SceneBackground::Key(const LidarCloud& cloud, int index) const {
  const Eigen::Vector3f& p = cloud.points[index];
  const auto azimuth =
      static_cast<std::int64_t>(std::floor((std::atan2(p.y(), p.x()) + M_PI) / cell_rad_));
  std::int64_t row;
  if (cloud.HasRing())
    row = cloud.ring[index];
  else if (cloud.IsOrganized())
    row = index / cloud.width;
  else
    row = 100000 +
          static_cast<std::int64_t>(std::floor(
              std::atan2(double(p.z()), std::hypot(double(p.x()), double(p.y()))) / cell_rad_));
  return row * 1000000 + azimuth;
}

void SceneBackground::Add(const LidarCloud& cloud) {
  std::unordered_map<std::int64_t, float> nearest;
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    if (!p.allFinite() || p.squaredNorm() < 1e-12f) continue;
    const std::int64_t key = Key(cloud, static_cast<int>(i));
    auto [it, fresh] = nearest.try_emplace(key, p.norm());
    if (!fresh) it->second = std::min(it->second, p.norm());
  }
  std::unordered_set<std::int64_t> azimuths;
  for (const auto& [key, range] : nearest) {
    ranges_[key].push_back(range);
    azimuths.insert(key % 1000000);
  }
  azimuth_span_deg_.push_back(static_cast<double>(azimuths.size()) * cell_rad_ * kRadToDeg);
  extent_m_.push_back(CloudExtentM(cloud));
  ++clouds_;
  usable_ = false;
}

bool SceneBackground::Finish(std::string* why) {
  median_.clear();
  usable_ = false;
  if (clouds_ < 3) {
    *why = "a background needs at least 3 clouds, have " + std::to_string(clouds_);
    return false;
  }
  long agree = 0, total = 0;
  for (auto& [key, ranges] : ranges_) {
    if (2 * static_cast<int>(ranges.size()) < clouds_) continue;
    std::vector<float> sorted = ranges;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    const float median = sorted[sorted.size() / 2];
    median_[key] = median;
    for (float r : ranges) agree += std::abs(r - median) < tolerance_m_;
    total += static_cast<long>(ranges.size());
  }
  // A static sensor sees the same room in every cloud; most returns then sit on their medians.
  if (total == 0 || agree < total / 2) {
    // Say what was seen. Clouds that each hold little more than a board are segments (the board
    // cropped out of the scan): there is no scene in them to learn. Full scans that do not repeat
    // come from a sensor that moved, or a scene that changed: which of the two is not known here.
    auto median = [](std::vector<double> values) {
      std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
      return values[values.size() / 2];
    };
    const double median_span = median(azimuth_span_deg_);
    const double median_extent_m = median(extent_m_);
    const double repeat = total ? 100.0 * agree / total : 0.0;
    if (median_extent_m <= kSegmentExtentM) {
      *why = Printf(
          "the clouds hold segments, not scans (each lies within %.2f m of its centre and covers "
          "about %.0f deg of azimuth, median): no static scene to learn, so no background model",
          median_extent_m, median_span);
    } else {
      *why = Printf(
          "the clouds do not share a static scene (%.0f%% of returns repeat from cloud to "
          "cloud): the sensor moved or the scene changed between pairs, so no background model",
          repeat);
    }
    median_.clear();
    return false;
  }
  usable_ = true;
  return true;
}

bool SceneBackground::IsStatic(const LidarCloud& cloud, int index) const {
  if (!usable_) return false;
  const auto it = median_.find(Key(cloud, index));
  return it != median_.end() && std::abs(cloud.points[index].norm() - it->second) < tolerance_m_;
}

}  // namespace calibench
