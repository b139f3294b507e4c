#include "core/target/board_edges.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <string>

#include "core/lidar/lidar_image.h"

namespace calibench {

bool BoardEdgeOptions::Check(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (!(min_background_gap_m > 0)) return fail("min_background_gap_m must be > 0 (metres)");
  if (!(max_azimuth_gap_deg > 0 && max_azimuth_gap_deg < 10))
    return fail("max_azimuth_gap_deg must be in (0, 10) degrees");
  return true;
}

namespace {

// Where the ray through x meets the plane; nullopt for rays (nearly) parallel to it.
std::optional<Vec3> OnPlane(const Plane& plane, const Vec3& x) {
  const auto range = RangeOnPlane(plane, x);
  if (!range) return std::nullopt;
  return x.normalized() * *range;
}

}  // namespace

std::vector<LidarEdgePoint> ExtractBoardEdgePoints(const LidarCloud& cloud,
                                                   const std::vector<int>& inliers,
                                                   const Plane& plane,
                                                   const BoardEdgeOptions& options,
                                                   BoardEdgeEnds* ends) {
  std::vector<LidarEdgePoint> edges;
  BoardEdgeEnds tally;
  if (ends) *ends = tally;
  if (inliers.size() < 4) return edges;
  const std::vector<int> rings = InferRings(cloud, LidarImageOptions{});
  std::vector<char> is_inlier(cloud.size(), 0);
  Vec3 centre = Vec3::Zero();
  for (int i : inliers) {
    is_inlier[i] = 1;
    centre += cloud.points[i].cast<double>();
  }
  // Azimuths relative to the board's centre, so that a board behind the LiDAR (azimuth ±π)
  // does not wrap.
  const double centre_azimuth = std::atan2(centre.y(), centre.x());
  auto relative_azimuth = [&](const Vec3& x) {
    return std::remainder(std::atan2(x.y(), x.x()) - centre_azimuth, 2 * M_PI);
  };
  double half_width = 0.0;
  std::map<int, int> inliers_per_ring;
  for (int i : inliers) {
    half_width = std::max(half_width, std::abs(relative_azimuth(cloud.points[i].cast<double>())));
    ++inliers_per_ring[rings[i]];
  }
  const double window = half_width + 3.0 * kDegToRad;
  // Per ring, every return in the board's azimuth window, sorted by azimuth.
  std::map<int, std::vector<std::pair<double, int>>> by_ring;
  for (size_t i = 0; i < cloud.size(); ++i) {
    if (!inliers_per_ring.count(rings[i])) continue;
    const double azimuth = relative_azimuth(cloud.points[i].cast<double>());
    if (std::abs(azimuth) <= window) by_ring[rings[i]].push_back({azimuth, static_cast<int>(i)});
  }
  const double max_gap = options.max_azimuth_gap_deg * kDegToRad;
  for (auto& [ring, returns] : by_ring) {
    if (inliers_per_ring[ring] < 2) continue;
    std::sort(returns.begin(), returns.end());
    int first = -1, last = -1;
    for (int k = 0; k < static_cast<int>(returns.size()); ++k) {
      if (!is_inlier[returns[k].second]) continue;
      if (first < 0) first = k;
      last = k;
    }
    // Each end: the board return and its outer neighbour on the ring.
    for (const auto& [board_k, outer_k] :
         {std::pair{first, first - 1}, std::pair{last, last + 1}}) {
      ++tally.ends;
      if (outer_k < 0 || outer_k >= static_cast<int>(returns.size()) ||
          std::abs(returns[outer_k].first - returns[board_k].first) > max_gap) {
        ++tally.no_return;
        continue;
      }
      const Vec3 board_x = cloud.points[returns[board_k].second].cast<double>();
      const Vec3 outer_x = cloud.points[returns[outer_k].second].cast<double>();
      const auto board_on_plane = OnPlane(plane, board_x);
      const auto outer_on_plane = OnPlane(plane, outer_x);
      if (!board_on_plane || !outer_on_plane) continue;
      // The outer return must have missed the board: well behind the plane along its ray.
      if (outer_x.norm() - outer_on_plane->norm() < options.min_background_gap_m) {
        ++tally.not_behind;
        continue;
      }
      const Vec3 gap = *outer_on_plane - *board_on_plane;
      const auto crossing = OnPlane(plane, board_x.normalized() + outer_x.normalized());
      if (!crossing || !(gap.norm() > 0)) continue;
      edges.push_back({*crossing, gap.normalized(), gap.norm() / std::sqrt(12.0)});
    }
  }
  tally.edge_points = static_cast<int>(edges.size());
  if (ends) *ends = tally;
  return edges;
}

double BoardEdgeResidual(const Pose& cam_from_lidar, const Pose& camera_from_board,
                         const Vec2& sheet_half_size_m, const LidarEdgePoint& edge,
                         double floor_sigma_m, Eigen::Matrix<double, 1, 6>* jacobian,
                         double* sigma_m, Eigen::Matrix<double, 1, 6>* board_pose_jacobian) {
  const Mat3 board_from_camera = camera_from_board.linear().transpose();
  const Vec3 in_camera = cam_from_lidar * edge.point;
  const Vec3 in_board = board_from_camera * (in_camera - camera_from_board.translation());
  // The nearest of the four edges: the axis whose |coordinate| is closest to its half size.
  const double dx = std::abs(in_board.x()) - sheet_half_size_m.x();
  const double dy = std::abs(in_board.y()) - sheet_half_size_m.y();
  const int axis = std::abs(dx) <= std::abs(dy) ? 0 : 1;
  const double sign = in_board[axis] >= 0 ? 1.0 : -1.0;
  const double residual = axis == 0 ? dx : dy;
  // d residual / d in_camera = sign · (row `axis` of board_from_camera).
  const Eigen::RowVector3d d_camera = sign * board_from_camera.row(axis);
  const Mat3& rotation = cam_from_lidar.linear();
  if (jacobian) {
    jacobian->head<3>() = d_camera * rotation;
    jacobian->tail<3>() = -d_camera * rotation * Skew(edge.point);
  }
  if (board_pose_jacobian) {
    // The point in the perturbed board frame: Exp(−xi)(p − ρ) ≈ p − ρ − φ × p = p − ρ + [p]× φ.
    const Eigen::RowVector3d d_board = sign * Eigen::RowVector3d::Unit(axis);
    board_pose_jacobian->head<3>() = -d_board;
    board_pose_jacobian->tail<3>() = d_board * Skew(in_board);
  }
  if (sigma_m) {
    const double along = d_camera.dot(rotation * edge.along_ring) * edge.sigma_along_m;
    *sigma_m = std::sqrt(along * along + floor_sigma_m * floor_sigma_m);
  }
  return residual;
}

}  // namespace calibench
