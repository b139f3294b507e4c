#include "core/target/board_edges.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
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
  if (!(max_firing_step_deg > 0 && max_firing_step_deg < 10))
    return fail("max_firing_step_deg must be in (0, 10) degrees");
  if (!(firing_step_over_median >= 1 && firing_step_over_median < 10))
    return fail("firing_step_over_median must be in [1, 10)");
  if (!(max_median_firing_step_deg > 0 && max_median_firing_step_deg < 10))
    return fail("max_median_firing_step_deg must be in (0, 10) degrees");
  if (!(min_consecutive_fraction >= 0 && min_consecutive_fraction <= 1))
    return fail("min_consecutive_fraction must be in [0, 1]");
  return true;
}

namespace {

// Where the ray through x meets the plane; nullopt for rays (nearly) parallel to it.
std::optional<Vec3> OnPlane(const Plane& plane, const Vec3& x) {
  const auto range = RangeOnPlane(plane, x);
  if (!range) return std::nullopt;
  return x.normalized() * *range;
}

// One end of a run of board returns: `board_x` the last return on the board, `outer_x` its
// neighbour along the beam's path. Adds the crossing to *edges when the neighbour missed the
// board (well behind its plane along its ray), and counts it in *tally.
void AddCrossing(const Plane& plane, const Vec3& board_x, const Vec3& outer_x,
                 const BoardEdgeOptions& options, std::vector<LidarEdgePoint>* edges,
                 BoardEdgeEnds* tally) {
  const auto board_on_plane = OnPlane(plane, board_x);
  const auto outer_on_plane = OnPlane(plane, outer_x);
  if (!board_on_plane || !outer_on_plane) return;
  if (outer_x.norm() - outer_on_plane->norm() < options.min_background_gap_m) {
    ++tally->not_behind;
    return;
  }
  const Vec3 gap = *outer_on_plane - *board_on_plane;
  const auto crossing = OnPlane(plane, board_x.normalized() + outer_x.normalized());
  if (!crossing || !(gap.norm() > 0)) return;
  edges->push_back({*crossing, gap.normalized(), gap.norm() / std::sqrt(12.0)});
}

double AngleBetweenDeg(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  const double na = a.norm(), nb = b.norm();
  if (!(na > 0 && nb > 0)) return 180.0;
  return std::acos(std::clamp(static_cast<double>(a.dot(b)) / (na * nb), -1.0, 1.0)) * kRadToDeg;
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
      // The outer return must have missed the board: well behind the plane along its ray.
      AddCrossing(plane, cloud.points[returns[board_k].second].cast<double>(),
                  cloud.points[returns[outer_k].second].cast<double>(), options, &edges, &tally);
    }
  }
  tally.edge_points = static_cast<int>(edges.size());
  if (ends) *ends = tally;
  return edges;
}

std::vector<LidarEdgePoint> ExtractBeamCrossingEdgePoints(
    const LidarCloud& cloud, const std::vector<int>& inliers, const Plane& plane,
    const BoardEdgeOptions& options, BoardEdgeEnds* ends, std::string* no_search) {
  std::vector<LidarEdgePoint> edges;
  BoardEdgeEnds tally;
  if (ends) *ends = tally;
  if (no_search) no_search->clear();
  if (inliers.size() < 4) return edges;
  std::vector<char> is_inlier(cloud.size(), 0);
  for (int i : inliers) is_inlier[i] = 1;
  // Stored in firing order? Then most board returns are followed by another, a small step away
  // along the beam's path.
  std::vector<double> steps;
  for (int i : inliers)
    if (i + 1 < static_cast<int>(cloud.size()) && is_inlier[i + 1])
      steps.push_back(AngleBetweenDeg(cloud.points[i], cloud.points[i + 1]));
  const double consecutive = static_cast<double>(steps.size()) / inliers.size();
  double median_step = 180.0;
  if (!steps.empty()) {
    std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
    median_step = steps[steps.size() / 2];
  }
  if (consecutive < options.min_consecutive_fraction ||
      median_step > options.max_median_firing_step_deg) {
    if (no_search) {
      char words[160];
      std::snprintf(words, sizeof(words),
                    "the cloud is not stored in firing order (%.0f %% of the board's returns "
                    "followed by another, median step %.2f deg): no beam path to cross its edges",
                    100.0 * consecutive, median_step);
      *no_search = words;
    }
    return edges;
  }
  const double max_step_deg =
      std::max(options.max_firing_step_deg, options.firing_step_over_median * median_step);
  const int n = static_cast<int>(cloud.size());
  for (int i : inliers) {
    // j: the neighbour beyond the board; k: the board return before i on the same stroke.
    for (const auto& [j, k] : {std::pair{i - 1, i + 1}, std::pair{i + 1, i - 1}}) {
      if (j < 0 || j >= n || is_inlier[j]) continue;
      ++tally.ends;
      const double out_step_deg = AngleBetweenDeg(cloud.points[i], cloud.points[j]);
      if (out_step_deg > max_step_deg || k < 0 || k >= n || !is_inlier[k]) {
        ++tally.no_return;
        continue;
      }
      const double board_step_deg = AngleBetweenDeg(cloud.points[k], cloud.points[i]);
      const Vec3 board_x = cloud.points[i].cast<double>();
      const Vec3 outer_x = cloud.points[j].cast<double>();
      const auto board_on_plane = OnPlane(plane, board_x);
      const auto before_on_plane = OnPlane(plane, cloud.points[k].cast<double>());
      const auto outer_on_plane = OnPlane(plane, outer_x);
      if (!board_on_plane || !before_on_plane || !outer_on_plane || !(board_step_deg > 0) ||
          board_step_deg > max_step_deg)
        continue;
      if (outer_x.norm() - outer_on_plane->norm() < options.min_background_gap_m) {
        ++tally.not_behind;
        continue;
      }
      // The crossing lies in the step from the last board return to the one beyond it. That
      // step is extrapolated along the stroke from the board's own returns (scaled by the angles,
      // a dropped return widens it): the return beyond lies far behind the plane, and carried
      // onto it along a ray from the origin it would move by the scanner's ray offset (a nodding
      // fan's mirror sits centimetres off its axis) times the depth gap over its range.
      const Vec3 stroke = *board_on_plane - *before_on_plane;
      const Vec3 gap = stroke * (out_step_deg / board_step_deg);
      if (!(gap.norm() > 0)) continue;
      edges.push_back(
          {*board_on_plane + 0.5 * gap, gap.normalized(), gap.norm() / std::sqrt(12.0)});
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
