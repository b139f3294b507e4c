#include "core/target/lidar_board_detect.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "core/base/text.h"
#include "core/target/lidar_board_clusters.h"
#include "core/target/lidar_board_grid.h"

namespace calibench {
namespace {

using board_grid::AngularGrid;
using board_grid::FreeEdgeFraction;
using board_grid::LinkDistance;

struct LocalPlane {
  Vec3 normal = Vec3::Zero();
  double rms_m = -1.0;  // about its own plane; < 0 where the neighbourhood is too thin to say
  bool planar = false;
};

Vec3 PointAt(const LidarCloud& cloud, int index) { return cloud.points[index].cast<double>(); }

// Each grid cell's return in double precision (NaN where the cell is empty): the neighbourhood
// loops below read it contiguously, without going through the cloud's index.
std::vector<Vec3> CellPoints(const LidarCloud& cloud, const AngularGrid& grid) {
  std::vector<Vec3> points(grid.point.size(), Vec3::Constant(std::nan("")));
  for (size_t cell = 0; cell < grid.point.size(); ++cell)
    if (grid.point[cell] >= 0) points[cell] = PointAt(cloud, grid.point[cell]);
  return points;
}

// The plane of each return's neighbourhood (one ring step around it in every direction). Flat
// where the neighbourhood spans two rings and hugs its plane; the returns near a sheet's border,
// whose neighbourhoods take in what lies behind, come out not planar. The scatter is accumulated
// in one pass relative to the centre return (shift-invariant, and no list of neighbours).
std::vector<LocalPlane> LocalPlanes(const AngularGrid& grid, const std::vector<Vec3>& cell_points,
                                    const LidarBoardDetectionOptions& options) {
  std::vector<LocalPlane> planes(grid.point.size());
  for (int row = 0; row < grid.rows; ++row) {
    for (int column = 0; column < grid.columns; ++column) {
      const int cell = grid.Cell(row, column);
      if (grid.point[cell] < 0) continue;
      const Vec3 centre = cell_points[cell];
      const double link = LinkDistance(grid, grid.range[cell]);
      const double link_squared = link * link;
      const auto [half_rows, half_columns] =
          grid.HalfWindow(grid.range[cell], options.neighbourhood_half_size_m);
      Vec3 sum = Vec3::Zero();
      double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;  // the scatter's distinct entries
      int count = 0;
      int rows_seen = 0;
      const int first_column = grid.Wrap(column - half_columns);
      const int width = std::min(2 * half_columns + 1, grid.columns);
      for (int r = std::max(0, row - half_rows); r <= std::min(grid.rows - 1, row + half_rows);
           ++r) {
        const int row_start = grid.Cell(r, 0);
        const int count_before = count;
        for (int k = 0, c = first_column; k < width; ++k, c = c + 1 == grid.columns ? 0 : c + 1) {
          if (grid.point[row_start + c] < 0) continue;
          const Vec3 q = cell_points[row_start + c] - centre;
          if (q.squaredNorm() > link_squared) continue;
          sum += q;
          xx += q.x() * q.x(), xy += q.x() * q.y(), xz += q.x() * q.z();
          yy += q.y() * q.y(), yz += q.y() * q.z(), zz += q.z() * q.z();
          ++count;
        }
        rows_seen += count > count_before ? 1 : 0;
      }
      if (count < 6 || rows_seen < 2) continue;
      const Vec3 mean = sum / count;
      Mat3 sum_outer;
      sum_outer << xx, xy, xz, xy, yy, yz, xz, yz, zz;
      const Mat3 scatter = sum_outer / count - mean * mean.transpose();
      Eigen::SelfAdjointEigenSolver<Mat3> eigen;
      eigen.computeDirect(scatter);
      planes[cell].normal = eigen.eigenvectors().col(0);
      planes[cell].rms_m = std::sqrt(std::max(0.0, eigen.eigenvalues()(0)));
      planes[cell].planar = planes[cell].rms_m < options.planar_rms_m;
    }
  }
  return planes;
}

// The cloud's range noise as its flat neighbourhoods show it: the median of their RMS about
// their own planes (metres; 0 when none says). It reads about half the sensor's σ: a cell keeps
// its nearest return (the spread of a minimum is narrower) and a small neighbourhood's plane
// absorbs part of its noise.
double MedianLocalRms(const std::vector<LocalPlane>& planes) {
  std::vector<double> rms;
  for (const LocalPlane& plane : planes)
    if (plane.rms_m >= 0) rms.push_back(plane.rms_m);
  if (rms.empty()) return 0.0;
  std::nth_element(rms.begin(), rms.begin() + rms.size() / 2, rms.end());
  return rms[rms.size() / 2];
}

// The thresholds assume a spinning LiDAR's few millimetres of range noise (its local RMS reads
// ~3 mm); a noisier sensor (a Livox-class scanner's 2 cm reads ~1 cm) would split its board
// into strips that each look too small. Planarity widens to 3 and growing to 5 times the local
// RMS where that exceeds the options'. Returns the planes re-judged.
std::vector<LocalPlane> ScaleToNoise(std::vector<LocalPlane> planes, double local_rms_m,
                                     LidarBoardDetectionOptions* options) {
  options->planar_rms_m = std::max(options->planar_rms_m, 3.0 * local_rms_m);
  options->plane_tolerance_m = std::max(options->plane_tolerance_m, 5.0 * local_rms_m);
  for (LocalPlane& plane : planes)
    plane.planar = plane.rms_m >= 0 && plane.rms_m < options->planar_rms_m;
  return planes;
}

// A plane through accumulated moments, kept relative to the first point for precision.
struct PlaneMoments {
  Vec3 origin = Vec3::Zero();
  Vec3 sum = Vec3::Zero();
  Mat3 sum_outer = Mat3::Zero();
  int count = 0;
  void Add(const Vec3& p) {
    if (count == 0) origin = p;
    const Vec3 q = p - origin;
    sum += q;
    sum_outer += q * q.transpose();
    ++count;
  }
  Vec3 Mean() const { return origin + sum / count; }
  Vec3 Normal() const {
    const Vec3 mean = sum / count;
    Eigen::SelfAdjointEigenSolver<Mat3> eigen;
    eigen.computeDirect(sum_outer / count - mean * mean.transpose());
    return eigen.eigenvectors().col(0);
  }
};

// Region growing over the grid: seeds in order of flatness, neighbours join by distance to the
// segment's plane (refitted as the segment doubles) and normal agreement. Returns that are not
// planar join but do not spread the segment, so a tripod's mast or a wall behind the border stays
// out. Returns segments as lists of cells.
std::vector<std::vector<int>> GrowSegments(const AngularGrid& grid,
                                           const std::vector<Vec3>& cell_points,
                                           const std::vector<LocalPlane>& planes,
                                           const LidarBoardDetectionOptions& options) {
  const double cos_tolerance = std::cos(options.normal_tolerance_deg * kDegToRad);
  std::vector<int> label(grid.point.size(), -1);
  std::vector<std::vector<int>> segments;
  std::vector<int> queue;  // cells whose neighbours are still to visit, from `next` on
  for (int seed = 0; seed < static_cast<int>(grid.point.size()); ++seed) {
    if (!planes[seed].planar || label[seed] >= 0) continue;
    const double seed_range = grid.range[seed];
    if (seed_range < options.min_range_m || seed_range > options.max_range_m) continue;
    const int id = static_cast<int>(segments.size());
    std::vector<int> cells = {seed};
    label[seed] = id;
    PlaneMoments moments;
    moments.Add(cell_points[seed]);
    Vec3 normal = planes[seed].normal;
    double offset = -normal.dot(cell_points[seed]);
    int refit_at = 40;  // a smaller patch's plane is no better than the seed's own
    int min_row = seed / grid.columns, max_row = min_row;
    queue.assign(1, seed);
    for (size_t next = 0; next < queue.size(); ++next) {
      const int cell = queue[next];
      const int row = cell / grid.columns, column = cell % grid.columns;
      const Vec3 here = cell_points[cell];
      const double link = LinkDistance(grid, grid.range[cell]);
      const double link_squared = link * link;
      const auto [half_rows, half_columns] =
          grid.HalfWindow(grid.range[cell], options.neighbourhood_half_size_m);
      for (int r = std::max(0, row - half_rows); r <= std::min(grid.rows - 1, row + half_rows); ++r)
        for (int dc = -half_columns; dc <= half_columns; ++dc) {
          const int other = grid.Cell(r, grid.Wrap(column + dc));
          if (grid.point[other] < 0 || label[other] >= 0) continue;
          const Vec3& p = cell_points[other];
          if ((p - here).squaredNorm() > link_squared ||
              std::abs(normal.dot(p) + offset) > options.plane_tolerance_m)
            continue;
          // Only flat returns that agree spread the segment; the others (a border whose
          // neighbourhood takes in what is behind) join without spreading it.
          const bool spreads =
              planes[other].planar && std::abs(planes[other].normal.dot(normal)) >= cos_tolerance;
          label[other] = id;
          cells.push_back(other);
          moments.Add(p);
          min_row = std::min(min_row, r);
          max_row = std::max(max_row, r);
          if (spreads) queue.push_back(other);
        }
      // Refit once the segment spans two rows (one row is a line: its plane is undetermined).
      if (moments.count >= refit_at && max_row > min_row) {
        normal = moments.Normal();
        offset = -normal.dot(moments.Mean());
        refit_at = 2 * moments.count;
      }
    }
    segments.push_back(std::move(cells));
  }
  return segments;
}

// The sheet's [long, short] side bounds: the known sheet, or the pattern plus margins.
struct SheetBounds {
  Vec2 min = Vec2::Zero();
  Vec2 max = Vec2::Zero();
};
SheetBounds BoundsFor(const BoardSpec& board, const LidarBoardDetectionOptions& options) {
  SheetBounds bounds;
  if (board.board_width > 0 && board.board_height > 0) {
    bounds.min = bounds.max = Vec2(std::max(board.board_width, board.board_height),
                                   std::min(board.board_width, board.board_height));
  } else {
    const Vec2 pattern(std::max(board.PatternWidth(), board.PatternHeight()),
                       std::min(board.PatternWidth(), board.PatternHeight()));
    bounds.min = pattern + Vec2::Constant(2 * options.min_unknown_margin_m);
    bounds.max = pattern + Vec2::Constant(2 * options.max_unknown_margin_m);
  }
  return bounds;
}

// Fits, measures and tests one segment. The candidate's `rejection` says why it is not the board.
// The plane, centre, RMS and outline of a set of returns.
void Measure(const LidarCloud& cloud, LidarBoardCandidate* c) {
  PlaneMoments moments;
  for (int index : c->indices) moments.Add(PointAt(cloud, index));
  c->centre = moments.Mean();
  Vec3 normal = moments.Normal();
  if (normal.dot(c->centre) > 0) normal = -normal;
  c->plane = Plane{normal, -normal.dot(c->centre)};
  const Vec3 e1 = normal.unitOrthogonal(), e2 = normal.cross(e1);
  std::vector<Vec2> flat;
  double squares = 0.0;
  for (int index : c->indices) {
    const Vec3 q = PointAt(cloud, index) - c->centre;
    flat.emplace_back(q.dot(e1), q.dot(e2));
    squares += std::pow(q.dot(normal), 2);
  }
  c->rms_m = std::sqrt(squares / c->indices.size());
  const std::vector<Vec2> hull = board_grid::ConvexHull(flat);
  c->hull_area_m2 = board_grid::PolygonArea(hull);
  c->extent_m = board_grid::MinAreaRectangle(hull);
}

// The chosen segment grown to the whole sheet: every return within the plane band and within the
// sheet's reach of the centre, twice (the second pass about the completed centre). A segment that
// noise split covers part of the sheet; its plane tilts with the part.
void CompleteSheet(const LidarCloud& cloud, const SheetBounds& sheet,
                   const LidarBoardDetectionOptions& options, LidarBoardCandidate* c) {
  // The band follows the segment's own noise, so that a wall a few centimetres behind stays out.
  const double band = std::clamp(3.0 * c->rms_m, 0.015, options.plane_tolerance_m);
  for (double reach : {sheet.max.norm(), 0.5 * sheet.max.norm() + options.size_tolerance_m}) {
    LidarBoardCandidate grown = *c;
    grown.indices.clear();
    for (size_t i = 0; i < cloud.size(); ++i) {
      const Vec3 p = PointAt(cloud, static_cast<int>(i));
      if (std::abs(c->plane.SignedDistance(p)) < band && (p - c->centre).norm() < reach)
        grown.indices.push_back(static_cast<int>(i));
    }
    if (grown.indices.size() < c->indices.size()) return;  // never lose the segment's returns
    Measure(cloud, &grown);
    // Grown past the sheet: something else shares the plane there; keep the segment.
    if ((grown.extent_m - sheet.max).maxCoeff() > options.size_tolerance_m) return;
    *c = std::move(grown);
  }
}

// Fits, measures and tests one segment. The candidate's `rejection` says why it is not the board.
LidarBoardCandidate Evaluate(const LidarCloud& cloud, const AngularGrid& grid,
                             const std::vector<int>& cells, std::vector<char>* in_segment,
                             const SheetBounds& sheet, const LidarBoardDetectionOptions& options,
                             const SceneBackground* background) {
  LidarBoardCandidate c;
  std::vector<int> rows;
  for (int cell : cells) {
    c.indices.push_back(grid.point[cell]);
    rows.push_back(cell / grid.columns);
  }
  std::sort(rows.begin(), rows.end());
  c.rings = static_cast<int>(std::unique(rows.begin(), rows.end()) - rows.begin());
  Measure(cloud, &c);
  const double fill_min = options.min_fill * sheet.min.prod();
  const double fill_max = options.max_fill * sheet.max.prod();
  const Vec2 too_long = c.extent_m - sheet.max - Vec2::Constant(options.size_tolerance_m);
  const double size_score =
      std::min(1.0, c.hull_area_m2 / (0.8 * sheet.min.prod())) *
      std::max(0.0, 1.0 - std::max(0.0, c.hull_area_m2 - sheet.max.prod()) / sheet.max.prod());
  c.score = 0.4 * size_score;
  if (c.rings < 2) {
    c.rejection = "spans a single ring";
  } else if (too_long.maxCoeff() > 0 || c.hull_area_m2 > fill_max) {
    c.rejection = "larger than the sheet";
  } else if (c.hull_area_m2 < fill_min) {
    c.rejection = "smaller than the sheet";
  }
  if (!c.rejection.empty()) return c;
  for (int cell : cells) (*in_segment)[cell] = 1;
  c.free_edge_fraction =
      FreeEdgeFraction(cloud, grid, cells, *in_segment, c.plane, options.edge_jump_m);
  for (int cell : cells) (*in_segment)[cell] = 0;
  if (background && background->usable()) {
    int on_background = 0;
    for (int index : c.indices) on_background += background->IsStatic(cloud, index);
    c.static_fraction = double(on_background) / c.indices.size();
  }
  const double flatness = std::clamp(1.0 - c.rms_m / options.plane_tolerance_m, 0.0, 1.0);
  c.score =
      (0.4 * size_score + 0.4 * c.free_edge_fraction + 0.2 * flatness) * (1.0 - c.static_fraction);
  if (c.free_edge_fraction < options.min_free_edge_fraction)
    c.rejection = Printf("attached to what is behind it (%.0f%% of its border free)",
                         100 * c.free_edge_fraction);
  else if (c.static_fraction > options.max_static_fraction)
    c.rejection = Printf("part of the static scene (%.0f%% of its returns in every cloud)",
                         100 * c.static_fraction);
  return c;
}

}  // namespace

bool LidarBoardDetectionOptions::Check(std::string* why) const {
  auto fail = [&](const char* what) {
    if (why) *why = what;
    return false;
  };
  if (!(plane_tolerance_m > 0)) return fail("plane_tolerance_m must be > 0");
  if (!(normal_tolerance_deg > 0 && normal_tolerance_deg < 90))
    return fail("normal_tolerance_deg must lie in (0, 90)");
  if (!(planar_rms_m > 0)) return fail("planar_rms_m must be > 0");
  if (min_points < 6) return fail("min_points must be at least 6");
  if (!(size_tolerance_m >= 0)) return fail("size_tolerance_m must be >= 0");
  if (!(min_fill > 0 && min_fill < max_fill)) return fail("need 0 < min_fill < max_fill");
  if (!(min_unknown_margin_m >= 0 && min_unknown_margin_m <= max_unknown_margin_m))
    return fail("need 0 <= min_unknown_margin_m <= max_unknown_margin_m");
  if (!(edge_jump_m > 0)) return fail("edge_jump_m must be > 0");
  if (!(min_free_edge_fraction >= 0 && min_free_edge_fraction <= 1))
    return fail("min_free_edge_fraction must lie in [0, 1]");
  if (!(max_static_fraction >= 0 && max_static_fraction <= 1))
    return fail("max_static_fraction must lie in [0, 1]");
  if (!(ambiguity_ratio > 0 && ambiguity_ratio <= 1)) return fail("ambiguity_ratio in (0, 1]");
  if (!(min_range_m >= 0 && min_range_m < max_range_m))
    return fail("need 0 <= min_range_m < max_range_m");
  if (!(angular_cell_deg >= 0)) return fail("angular_cell_deg must be >= 0");
  return true;
}

namespace {

// Whether the board's size is written longer side first (board_size [width, height]).
bool WiderThanTall(const BoardSpec& board) {
  return board.board_width > 0 && board.board_height > 0
             ? board.board_width >= board.board_height
             : board.PatternWidth() >= board.PatternHeight();
}

// A long side x short side pair, in the order the board's size is written.
Vec2 InBoardOrder(const Vec2& long_short, const BoardSpec& board) {
  return WiderThanTall(board) ? long_short : Vec2(long_short.y(), long_short.x());
}

}  // namespace

std::string LidarBoardCandidate::Describe(const BoardSpec& board) const {
  const Vec2 size = InBoardOrder(extent_m, board);
  return Printf("a %.2f x %.2f m plane at %.1f m, azimuth %.0f deg", size.x(), size.y(),
                centre.norm(), std::atan2(centre.y(), centre.x()) * kRadToDeg);
}

LidarBoardDetection DetectLidarBoard(const LidarCloud& cloud, const BoardSpec& board,
                                     const LidarBoardDetectionOptions& given_options,
                                     const SceneBackground* background) {
  std::string why;
  CALIBENCH_CHECK(given_options.Check(&why));
  LidarBoardDetection result;
  LidarBoardDetectionOptions options = given_options;
  const AngularGrid grid = board_grid::BuildAngularGrid(cloud, options.angular_cell_deg);
  const SheetBounds sheet = BoundsFor(board, options);
  const std::vector<Vec3> cell_points = CellPoints(cloud, grid);
  std::vector<LocalPlane> local = LocalPlanes(grid, cell_points, options);
  result.local_rms_m = MedianLocalRms(local);
  const std::vector<LocalPlane> planes =
      ScaleToNoise(std::move(local), result.local_rms_m, &options);
  std::vector<char> in_segment(grid.point.size(), 0);
  auto consider = [&](const std::vector<int>& cells) {
    LidarBoardCandidate c = Evaluate(cloud, grid, cells, &in_segment, sheet, options, background);
    (c.rejection.empty() ? result.candidates : result.near_misses).push_back(std::move(c));
  };
  for (const std::vector<int>& cells : GrowSegments(grid, cell_points, planes, options))
    if (static_cast<int>(cells.size()) >= options.min_points) consider(cells);
  // A sparse ring-less frame (strokes a cell apart, not surfaces) leaves no neighbourhood planar
  // enough to grow from; there the clusters that stand apart in range are the segments.
  if (result.candidates.empty() && !grid.from_rings) {
    board_grid::ClusterOptions clusters;
    clusters.min_points = options.min_points;
    clusters.max_diameter_m = sheet.max.norm() + 2 * options.size_tolerance_m;
    for (const std::vector<int>& cells : board_grid::RangeClusters(grid, cell_points, clusters))
      consider(cells);
  }
  auto by_score = [](const auto& a, const auto& b) { return a.score > b.score; };
  std::sort(result.candidates.begin(), result.candidates.end(), by_score);
  std::sort(result.near_misses.begin(), result.near_misses.end(), by_score);
  if (result.near_misses.size() > 5) result.near_misses.resize(5);
  const LidarBoardCandidate* near_miss =
      result.near_misses.empty() ? nullptr : &result.near_misses.front();
  const Vec2 sheet_size = InBoardOrder(sheet.max, board);  // sheet.max: long side, short side
  const std::string wanted =
      Printf("no planar segment of %.2f x %.2f m standing free", sheet_size.x(), sheet_size.y());
  if (result.candidates.empty()) {
    result.reason = wanted + (near_miss ? "; best candidate: " + near_miss->Describe(board) + ", " +
                                              near_miss->rejection
                                        : "; no planar segment at all");
    return result;
  }
  const LidarBoardCandidate& best = result.candidates.front();
  // Pieces of one sheet (a segment split by noise) are not rivals: the plane fit grows the best
  // piece to the whole sheet anyway.
  const double sheet_diagonal = sheet.max.norm();
  auto same_sheet = [&](const LidarBoardCandidate& other) {
    return (other.centre - best.centre).norm() < 0.75 * sheet_diagonal &&
           std::abs(other.plane.normal.dot(best.plane.normal)) > std::cos(10.0 * kDegToRad);
  };
  const auto rival = std::find_if(result.candidates.begin() + 1, result.candidates.end(),
                                  [&](const auto& other) { return !same_sheet(other); });
  const double second = rival != result.candidates.end() ? rival->score : 0.0;
  if (second > options.ambiguity_ratio * best.score) {
    result.reason = "two board-like planes, too close to tell apart: " + best.Describe(board) +
                    " and " + rival->Describe(board);
    return result;
  }
  result.confidence =
      best.score *
      std::clamp((1.0 - second / best.score) / (1.0 - options.ambiguity_ratio) * 0.5 + 0.5, 0.0,
                 1.0);
  result.board = best;
  CompleteSheet(cloud, sheet, options, &*result.board);
  return result;
}

}  // namespace calibench
