// Internal to the LiDAR board detection: the returns of a sparse ring-less cloud (one 0.1 s frame
// of a Livox Mid-360: ~1 return per square degree, a board crossed by a few strokes) grouped into
// clusters that stand apart in range, for clouds too sparse for region growing
// (docs/architecture.md, "Board detection").
#pragma once

#include <vector>

#include "core/base/types.h"
#include "core/target/lidar_board_grid.h"

namespace calibench::board_grid {

struct ClusterOptions {
  // Two returns link when they lie within this distance (metres) or the grid's link distance at
  // their range, whichever is larger: a rosette's strokes over a sheet lie up to ~15 cm apart.
  double gap_m = 0.25;
  int max_half_window_cells = 10;  // neighbours looked for at most this many cells each way
  int min_points = 25;             // smaller clusters are dropped
  double max_diameter_m = 1.0;     // larger ones (walls, the floor) are dropped
};

// Connected components of the grid's returns, two returns linked when they lie within the gap of
// each other in space (looked for over the cells that gap spans at their range): a sheet held in
// front of the room separates from the walls by its range jump, whatever its returns' pattern.
// Returns the clusters as lists of cells.
std::vector<std::vector<int>> RangeClusters(const AngularGrid& grid,
                                            const std::vector<Vec3>& cell_points,
                                            const ClusterOptions& options);

// How far apart two neighbouring returns on one surface may be at `range`: a grid step on a
// surface tilted up to ~65 degrees, plus noise.
double LinkDistance(const AngularGrid& grid, double range);

}  // namespace calibench::board_grid
