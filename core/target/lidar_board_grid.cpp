#include "core/target/lidar_board_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <unordered_set>

#include "core/lidar/lidar_image.h"

namespace calibench::board_grid {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

double Elevation(const Eigen::Vector3f& p) {
  return std::atan2(double(p.z()), std::hypot(double(p.x()), double(p.y())));
}

// Spinning LiDARs without a ring field still come in clear elevation clusters; swept and
// solid-state ones do not (many tiny "rings").
bool HasRingStructure(const LidarCloud& cloud) {
  if (cloud.HasRing() || cloud.IsOrganized()) return true;
  const std::vector<int> rings = InferRings(cloud, LidarImageOptions{});
  std::unordered_set<int> distinct(rings.begin(), rings.end());
  if (distinct.size() >= 8 && distinct.size() <= 256 && cloud.size() / distinct.size() >= 200)
    return true;  // a scan
  // A segment cut out of a spinning LiDAR's scan (a board-only cloud): a few rings of many
  // returns each, well apart in elevation (a swept scanner's beams lie a fraction of that apart).
  if (distinct.size() < 3 || cloud.size() / distinct.size() < 20) return false;
  std::vector<double> sum(*std::max_element(rings.begin(), rings.end()) + 1, 0.0);
  std::vector<int> count(sum.size(), 0);
  for (size_t i = 0; i < cloud.size(); ++i) {
    sum[rings[i]] += Elevation(cloud.points[i]);
    ++count[rings[i]];
  }
  std::vector<double> elevations;
  for (size_t r = 0; r < sum.size(); ++r)
    if (count[r] > 0) elevations.push_back(sum[r] / count[r]);
  std::sort(elevations.begin(), elevations.end());
  std::vector<double> steps;
  for (size_t k = 1; k < elevations.size(); ++k) steps.push_back(elevations[k] - elevations[k - 1]);
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  return steps[steps.size() / 2] >= 0.3 * kDegToRad;
}

AngularGrid FromRings(const LidarCloud& cloud) {
  const LidarImage image = ProjectById(cloud, LidarImageOptions{});
  AngularGrid grid;
  grid.rows = image.rows;
  grid.columns = image.columns;
  grid.point = image.point_index;
  grid.range = image.range;
  grid.from_rings = true;
  grid.column_step_rad = 2.0 * M_PI / std::max(1, image.columns);
  // The rows' mean elevations; their median spacing is the ring spacing (uneven on some sensors,
  // the median is the typical one).
  std::vector<double> sum(image.rows, 0.0);
  std::vector<int> count(image.rows, 0);
  for (int cell = 0; cell < static_cast<int>(image.point_index.size()); ++cell) {
    if (image.point_index[cell] < 0) continue;
    sum[cell / image.columns] += Elevation(cloud.points[image.point_index[cell]]);
    ++count[cell / image.columns];
  }
  std::vector<double> steps;
  for (int row = 1; row < image.rows; ++row)
    if (count[row] > 0 && count[row - 1] > 0)
      steps.push_back(std::abs(sum[row] / count[row] - sum[row - 1] / count[row - 1]));
  if (!steps.empty()) {
    std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
    grid.row_step_rad = std::max(steps[steps.size() / 2], grid.column_step_rad);
  } else {
    grid.row_step_rad = grid.column_step_rad;
  }
  return grid;
}

AngularGrid FromAngles(const LidarCloud& cloud, double cell_deg) {
  AngularGrid grid;
  const double cell = (cell_deg > 0 ? cell_deg : RasterCellDeg(cloud)) * kDegToRad;
  double top = -M_PI, bottom = M_PI;
  for (const Eigen::Vector3f& p : cloud.points) {
    if (!p.allFinite() || p.squaredNorm() < 1e-12f) continue;
    top = std::max(top, Elevation(p));
    bottom = std::min(bottom, Elevation(p));
  }
  grid.columns = std::max(1, static_cast<int>(std::lround(2.0 * M_PI / cell)));
  grid.rows = top >= bottom ? static_cast<int>((top - bottom) / cell) + 1 : 0;
  grid.row_step_rad = cell;
  grid.column_step_rad = 2.0 * M_PI / grid.columns;
  grid.point.assign(static_cast<size_t>(grid.rows) * grid.columns, -1);
  grid.range.assign(grid.point.size(), kNaN);
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    if (!p.allFinite() || p.squaredNorm() < 1e-12f) continue;
    const int row = std::min(grid.rows - 1, static_cast<int>((top - Elevation(p)) / cell));
    const int cell_index = grid.Cell(row, AzimuthColumn(p, grid.columns));
    const float range = p.norm();
    if (grid.point[cell_index] >= 0 && !(range < grid.range[cell_index])) continue;
    grid.point[cell_index] = static_cast<int>(i);
    grid.range[cell_index] = range;
  }
  return grid;
}

double Cross(const Vec2& o, const Vec2& a, const Vec2& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

}  // namespace

int AngularGrid::HalfWindowColumns() const {
  if (column_step_rad <= 0) return 1;
  return std::clamp(static_cast<int>(std::lround(row_step_rad / column_step_rad)), 1, 16);
}

std::pair<int, int> AngularGrid::HalfWindow(double range_m, double half_size_m) const {
  const double rows_needed = half_size_m / (std::max(range_m, 0.1) * row_step_rad);
  const int half_rows = std::clamp(static_cast<int>(std::ceil(rows_needed)), 1, 3);
  const double columns_needed = half_size_m / (std::max(range_m, 0.1) * column_step_rad);
  const int half_columns =
      std::max(static_cast<int>(std::lround(half_rows * row_step_rad / column_step_rad)),
               static_cast<int>(std::ceil(columns_needed)));
  return {half_rows, std::clamp(half_columns, 1, 24)};
}

AngularGrid BuildAngularGrid(const LidarCloud& cloud, double cell_deg) {
  return HasRingStructure(cloud) ? FromRings(cloud) : FromAngles(cloud, cell_deg);
}

// Andrew's monotone chain.
std::vector<Vec2> ConvexHull(std::vector<Vec2> points) {
  std::sort(points.begin(), points.end(), [](const Vec2& a, const Vec2& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  if (points.size() < 3) return points;
  std::vector<Vec2> hull(2 * points.size());
  size_t k = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && Cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (size_t i = points.size() - 1, lower = k + 1; i > 0; --i) {
    while (k >= lower && Cross(hull[k - 2], hull[k - 1], points[i - 1]) <= 0) --k;
    hull[k++] = points[i - 1];
  }
  hull.resize(k - 1);
  return hull;
}

double PolygonArea(const std::vector<Vec2>& polygon) {
  double twice = 0.0;
  for (size_t i = 0; i < polygon.size(); ++i) {
    const Vec2& a = polygon[i];
    const Vec2& b = polygon[(i + 1) % polygon.size()];
    twice += a.x() * b.y() - b.x() * a.y();
  }
  return std::abs(twice) / 2.0;
}

// The minimum-area rectangle has a side along one hull edge (Freeman & Shapira 1975).
Vec2 MinAreaRectangle(const std::vector<Vec2>& hull) {
  if (hull.size() < 3) return Vec2::Zero();
  double best_area = std::numeric_limits<double>::infinity();
  Vec2 best = Vec2::Zero();
  for (size_t i = 0; i < hull.size(); ++i) {
    const Vec2 edge = hull[(i + 1) % hull.size()] - hull[i];
    if (edge.norm() < 1e-9) continue;
    const Vec2 u = edge.normalized();
    const Vec2 v(-u.y(), u.x());
    double u_min = 1e300, u_max = -1e300, v_min = 1e300, v_max = -1e300;
    for (const Vec2& p : hull) {
      u_min = std::min(u_min, p.dot(u));
      u_max = std::max(u_max, p.dot(u));
      v_min = std::min(v_min, p.dot(v));
      v_max = std::max(v_max, p.dot(v));
    }
    const double area = (u_max - u_min) * (v_max - v_min);
    if (area < best_area) {
      best_area = area;
      best = Vec2(std::max(u_max - u_min, v_max - v_min), std::min(u_max - u_min, v_max - v_min));
    }
  }
  return best;
}

namespace {

enum class Border { kFree, kAttached, kOccluded };

// What lies at `cell` seen from a segment with `plane`: nothing or something behind (free),
// something on the plane (attached) or in front (occluded).
Border Classify(const LidarCloud& cloud, const AngularGrid& grid, int cell, const Plane& plane,
                double jump_m) {
  if (grid.point[cell] < 0) return Border::kFree;
  const Vec3 p = cloud.points[grid.point[cell]].cast<double>();
  const double range = p.norm();
  const double along = plane.normal.dot(p / range);
  if (along >= -1e-6) return Border::kFree;  // the ray never meets the plane's front
  const double predicted = -plane.distance / along;
  if (range > predicted + jump_m) return Border::kFree;
  return range < predicted - jump_m ? Border::kOccluded : Border::kAttached;
}

}  // namespace

// The fraction of a segment's border with nothing right behind it: the row ends (along rings) and
// the column ends (across rings), each half of the answer.
double FreeEdgeFraction(const LidarCloud& cloud, const AngularGrid& grid,
                        const std::vector<int>& cells, const std::vector<char>& in_segment,
                        const Plane& plane, double jump_m) {
  std::map<int, std::pair<int, int>> row_ends;     // row -> columns unwrapped about the first cell
  std::map<int, std::pair<int, int>> column_ends;  // column -> rows
  const int reference = cells.front() % grid.columns;
  for (int cell : cells) {
    const int row = cell / grid.columns, column = cell % grid.columns;
    int unwrapped = column - reference;
    if (unwrapped > grid.columns / 2) unwrapped -= grid.columns;
    if (unwrapped < -grid.columns / 2) unwrapped += grid.columns;
    auto [it, fresh] = row_ends.try_emplace(row, unwrapped, unwrapped);
    it->second = {std::min(it->second.first, unwrapped), std::max(it->second.second, unwrapped)};
    auto [ct, cfresh] = column_ends.try_emplace(column, row, row);
    ct->second = {std::min(ct->second.first, row), std::max(ct->second.second, row)};
  }
  // Walking outward, the first return off the plane decides; a fringe of the sheet's own returns
  // that the segment left out (noise at its border) is stepped over, a wall is not (it stays on
  // the plane for the whole reach).
  const int reach = grid.HalfWindowColumns() + 3;
  // Cells without a return (a dropout on black ink) are stepped over too; a row end with no
  // return at all within the reach has nothing behind it (a cloud of the board alone).
  auto along_row = [&](int row, int from, int step) {
    bool any_return = false;
    for (int k = 1; k <= reach; ++k) {
      const int cell = grid.Cell(row, grid.Wrap(reference + from + step * k));
      if (in_segment[cell] || grid.point[cell] < 0) continue;
      any_return = true;
      const Border border = Classify(cloud, grid, cell, plane, jump_m);
      if (border != Border::kAttached) return border;
    }
    return any_return ? Border::kAttached : Border::kFree;
  };
  auto along_column = [&](int column, int from, int step) {
    for (int k = 1; k <= 3; ++k) {
      const int row = from + step * k;
      if (row < 0 || row >= grid.rows) return Border::kFree;
      const int cell = grid.Cell(row, column);
      if (in_segment[cell]) continue;
      const Border border = Classify(cloud, grid, cell, plane, jump_m);
      if (border != Border::kAttached) return border;
    }
    return Border::kAttached;
  };
  int free_h = 0, total_h = 0, free_v = 0, total_v = 0;
  for (const auto& [row, ends] : row_ends) {
    free_h += (along_row(row, ends.first, -1) == Border::kFree) +
              (along_row(row, ends.second, +1) == Border::kFree);
    total_h += 2;
  }
  for (const auto& [column, ends] : column_ends) {
    free_v += (along_column(column, ends.first, -1) == Border::kFree) +
              (along_column(column, ends.second, +1) == Border::kFree);
    total_v += 2;
  }
  const double h = total_h ? double(free_h) / total_h : 0.0;
  const double v = total_v ? double(free_v) / total_v : 0.0;
  return 0.5 * (h + v);
}

}  // namespace calibench::board_grid
