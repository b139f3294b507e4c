#include "core/target/ring_bias.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace calibench {

std::vector<int> ElevationGroups(const LidarCloud& cloud, const std::vector<int>& indices) {
  std::vector<std::pair<double, size_t>> elevations;
  for (size_t k = 0; k < indices.size(); ++k) {
    const Vec3 x = cloud.points[indices[k]].cast<double>();
    elevations.push_back({std::atan2(x.z(), x.head<2>().norm()), k});
  }
  std::sort(elevations.begin(), elevations.end());
  std::vector<int> group(indices.size(), 0);
  int current = 0;
  for (size_t j = 0; j < elevations.size(); ++j) {
    if (j > 0 && elevations[j].first - elevations[j - 1].first > 0.15 * kDegToRad) ++current;
    group[elevations[j].second] = current;
  }
  return group;
}

int ElevationRings(const LidarCloud& cloud, const std::vector<int>& indices) {
  std::map<int, int> sizes;
  for (int g : ElevationGroups(cloud, indices)) ++sizes[g];
  int rings = 0, in_rings = 0;
  for (const auto& [g, size] : sizes)
    if (size >= 3) ++rings, in_rings += size;
  return in_rings >= 0.9 * static_cast<double>(indices.size()) ? rings : 0;
}

Mat4 RingBiasCovariance(const LidarCloud& cloud, const std::vector<int>& indices,
                        const Plane& plane, double ring_bias_sigma_m) {
  if (indices.size() < 4) return Mat4::Zero();
  // Ring of each return: the cloud's, else elevation clusters.
  std::vector<int> ring(indices.size(), 0);
  if (cloud.HasRing()) {
    for (size_t k = 0; k < indices.size(); ++k) ring[k] = cloud.ring[indices[k]];
  } else {
    ring = ElevationGroups(cloud, indices);
  }
  const Eigen::Matrix<double, 3, 2> basis = PlaneTangentBasis(plane.normal);
  Mat3 normal_matrix = Mat3::Zero();
  std::map<int, Vec3> per_ring;  // s_r
  for (size_t k = 0; k < indices.size(); ++k) {
    const Vec3 x = cloud.points[indices[k]].cast<double>();
    const double r = x.norm();
    if (!(r > 0)) continue;
    const Vec3 a(basis.col(0).dot(x), basis.col(1).dot(x), 1.0);
    normal_matrix += a * a.transpose();
    auto [it, added] = per_ring.try_emplace(ring[k], Vec3::Zero());
    it->second += a * plane.normal.dot(x / r);
  }
  Mat3 middle = Mat3::Zero();
  for (const auto& [r, s] : per_ring) middle += s * s.transpose();
  const Mat3 inverse = normal_matrix.inverse();
  if (!inverse.allFinite()) return Mat4::Zero();
  return TangentToPlaneCovariance(
      ring_bias_sigma_m * ring_bias_sigma_m * inverse * middle * inverse, plane.normal);
}

}  // namespace calibench
