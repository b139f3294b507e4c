#include "core/target/lidar_board_clusters.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace calibench::board_grid {
namespace {

int Root(std::vector<int>& parent, int cell) {
  while (parent[cell] != cell) cell = parent[cell] = parent[parent[cell]];
  return cell;
}

}  // namespace

double LinkDistance(const AngularGrid& grid, double range) {
  return 2.5 * range * std::max(grid.row_step_rad, grid.column_step_rad) + 0.05;
}

std::vector<std::vector<int>> RangeClusters(const AngularGrid& grid,
                                            const std::vector<Vec3>& cell_points,
                                            const ClusterOptions& options) {
  const int cells = static_cast<int>(grid.point.size());
  std::vector<int> parent(cells);
  std::iota(parent.begin(), parent.end(), 0);
  const double step_rad = std::max(1e-6, std::min(grid.row_step_rad, grid.column_step_rad));
  for (int row = 0; row < grid.rows; ++row)
    for (int column = 0; column < grid.columns; ++column) {
      const int cell = grid.Cell(row, column);
      if (grid.point[cell] < 0) continue;
      // The window spans the gap between a rosette's strokes at this range; the link distance
      // keeps a sheet apart from the wall metres behind it.
      const double range = grid.range[cell];
      const double link = std::max(options.gap_m, LinkDistance(grid, range));
      const double link_squared = link * link;
      const int k = std::clamp(static_cast<int>(std::ceil(link / (range * step_rad))), 1,
                               options.max_half_window_cells);
      for (int r = row; r <= std::min(grid.rows - 1, row + k); ++r)
        for (int dc = r == row ? 1 : -k; dc <= k; ++dc) {
          const int other = grid.Cell(r, grid.Wrap(column + dc));
          if (grid.point[other] < 0 || other == cell) continue;
          if ((cell_points[other] - cell_points[cell]).squaredNorm() > link_squared) continue;
          const int a = Root(parent, cell), b = Root(parent, other);
          if (a != b) parent[std::max(a, b)] = std::min(a, b);
        }
    }
  std::vector<std::vector<int>> by_root(cells);
  for (int cell = 0; cell < cells; ++cell)
    if (grid.point[cell] >= 0) by_root[Root(parent, cell)].push_back(cell);
  std::vector<std::vector<int>> clusters;
  for (std::vector<int>& members : by_root) {
    if (static_cast<int>(members.size()) < options.min_points) continue;
    Vec3 low = Vec3::Constant(1e30), high = Vec3::Constant(-1e30);
    for (int cell : members) {
      low = low.cwiseMin(cell_points[cell]);
      high = high.cwiseMax(cell_points[cell]);
    }
    if ((high - low).norm() <= options.max_diameter_m) clusters.push_back(std::move(members));
  }
  return clusters;
}

}  // namespace calibench::board_grid
