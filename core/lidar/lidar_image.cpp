// Ring inference and the projection by ID (Ca²Lib Eq. (10)–(12)).
#include "core/lidar/lidar_image.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <unordered_set>

namespace calibench {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
// Two density peaks are separate rings when the valley between them is below this fraction of
// the lower peak. Two equal Gaussian rings d apart reach 0.7 at d = 2.9 sigma; a lower ratio
// merged HDL-64 rings (1/3 degree apart) already at 0.1 degree of elevation noise.
constexpr double kValleyRatio = 0.7;

// Elevation above the x-y plane of the LiDAR frame, radians.
double Elevation(const Eigen::Vector3f& p) {
  return std::atan2(static_cast<double>(p.z()), std::hypot(double{p.x()}, double{p.y()}));
}

bool HasDirection(const Eigen::Vector3f& p) { return p.allFinite() && p.squaredNorm() > 1e-12f; }

// Organized clouds: rows are rings, but drivers disagree on whether row 0 is the top or the
// bottom beam. Compare the median elevation of consecutive rows and flip when it falls.
std::vector<int> RingsFromRows(const LidarCloud& cloud) {
  const int rows = cloud.height, cols = cloud.width;
  std::vector<double> row_elevation(rows, std::numeric_limits<double>::quiet_NaN());
  std::vector<double> buffer;
  for (int r = 0; r < rows; ++r) {
    buffer.clear();
    for (int c = 0; c < cols; ++c) {
      const Eigen::Vector3f& p = cloud.points[static_cast<size_t>(r) * cols + c];
      if (HasDirection(p)) buffer.push_back(Elevation(p));
    }
    if (buffer.empty()) continue;
    std::nth_element(buffer.begin(), buffer.begin() + buffer.size() / 2, buffer.end());
    row_elevation[r] = buffer[buffer.size() / 2];
  }
  int votes = 0;  // > 0: elevation grows with the row index
  double previous = std::numeric_limits<double>::quiet_NaN();
  for (const double e : row_elevation) {
    if (std::isnan(e)) continue;
    if (!std::isnan(previous)) votes += e > previous ? 1 : (e < previous ? -1 : 0);
    previous = e;
  }
  std::vector<int> rings(cloud.size());
  for (size_t i = 0; i < rings.size(); ++i) {
    const int row = static_cast<int>(i / cols);
    rings[i] = votes < 0 ? rows - 1 - row : row;
  }
  return rings;
}

// A run [begin, end) of the elevation-sorted points that forms one ring.
struct Cluster {
  size_t begin, end;
  size_t size() const { return end - begin; }
};

// Splits at jumps larger than `gap`: exact for noise-free beams spaced more than `gap` apart.
std::vector<Cluster> SplitAtGaps(const std::vector<double>& sorted, double gap) {
  std::vector<Cluster> clusters;
  size_t begin = 0;
  for (size_t i = 1; i <= sorted.size(); ++i) {
    if (i == sorted.size() || sorted[i] - sorted[i - 1] > gap) {
      clusters.push_back({begin, i});
      begin = i;
    }
  }
  return clusters;
}

// Elevation noise (range noise off the ray, beam divergence) can bridge the gaps between
// closely spaced beams (HDL-64: about 1/3 degree). Inside such a run, rings show up as density
// peaks: split at valleys that are clearly (relatively and statistically) below both peaks.
std::vector<Cluster> SplitAtValleys(const std::vector<double>& sorted, Cluster run, double gap) {
  const double bin = gap / 4;
  const double lo = sorted[run.begin];
  const int bins = static_cast<int>((sorted[run.end - 1] - lo) / bin) + 1;
  if (bins < 8) return {run};  // too narrow to hold two rings `gap` apart with a valley between
  std::vector<double> counts(bins, 0.0), smooth(bins, 0.0);
  for (size_t i = run.begin; i < run.end; ++i)
    counts[static_cast<int>((sorted[i] - lo) / bin)] += 1;
  const double kernel[] = {0.006, 0.061, 0.242, 0.383, 0.242, 0.061, 0.006};  // Gaussian, 1 bin
  for (int b = 0; b < bins; ++b)
    for (int k = -3; k <= 3; ++k)
      if (b + k >= 0 && b + k < bins) smooth[b] += kernel[k + 3] * counts[b + k];
  std::vector<int> peaks;
  for (int b = 0; b < bins; ++b) {
    const bool left = b == 0 || smooth[b] > smooth[b - 1];
    const bool right = b == bins - 1 || smooth[b] >= smooth[b + 1];
    if (left && right && smooth[b] > 0) peaks.push_back(b);
  }
  auto valley = [&](int a, int b) {
    return static_cast<int>(std::min_element(smooth.begin() + a, smooth.begin() + b + 1) -
                            smooth.begin());
  };
  auto distinct = [&](int a, int b) {
    const double low_peak = std::min(smooth[a], smooth[b]), v = smooth[valley(a, b)];
    return (b - a) * bin > gap && v < kValleyRatio * low_peak &&
           low_peak - v > 3 * std::sqrt(low_peak);
  };
  // Merge the least distinct neighbours first (drop the lower peak) until all pairs are distinct.
  for (bool merged = true; merged && peaks.size() > 1;) {
    merged = false;
    int worst = -1;
    double worst_ratio = -1;
    for (size_t k = 0; k + 1 < peaks.size(); ++k) {
      if (distinct(peaks[k], peaks[k + 1])) continue;
      const double ratio =
          smooth[valley(peaks[k], peaks[k + 1])] / std::min(smooth[peaks[k]], smooth[peaks[k + 1]]);
      if (ratio > worst_ratio) {
        worst_ratio = ratio;
        worst = static_cast<int>(k);
      }
    }
    if (worst >= 0) {
      const int drop = smooth[peaks[worst]] < smooth[peaks[worst + 1]] ? worst : worst + 1;
      peaks.erase(peaks.begin() + drop);
      merged = true;
    }
  }
  std::vector<Cluster> parts;
  size_t begin = run.begin;
  for (size_t k = 0; k + 1 < peaks.size(); ++k) {
    const double boundary = lo + (valley(peaks[k], peaks[k + 1]) + 0.5) * bin;
    const size_t split = static_cast<size_t>(
        std::lower_bound(sorted.begin() + begin, sorted.begin() + run.end, boundary) -
        sorted.begin());
    if (split > begin && split < run.end) {
      parts.push_back({begin, split});
      begin = split;
    }
  }
  parts.push_back({begin, run.end});
  return parts;
}

// Stray points (noise tails, no-return points at the origin) form tiny clusters that would
// renumber every ring above them; fold them into the nearest real ring.
void MergeSlivers(const std::vector<double>& sorted, std::vector<Cluster>* clusters) {
  double sum = 0, sum_sq = 0;  // size of the cluster an average point belongs to
  for (const Cluster& c : *clusters) {
    sum += static_cast<double>(c.size());
    sum_sq += static_cast<double>(c.size()) * static_cast<double>(c.size());
  }
  const double min_size = 0.02 * sum_sq / std::max(sum, 1.0);
  while (clusters->size() > 1) {
    auto smallest =
        std::min_element(clusters->begin(), clusters->end(),
                         [](const Cluster& a, const Cluster& b) { return a.size() < b.size(); });
    if (smallest->size() >= min_size) break;
    const size_t k = static_cast<size_t>(smallest - clusters->begin());
    const double below = k > 0 ? sorted[smallest->begin] - sorted[smallest->begin - 1]
                               : std::numeric_limits<double>::infinity();
    const double above = k + 1 < clusters->size()
                             ? sorted[smallest->end] - sorted[smallest->end - 1]
                             : std::numeric_limits<double>::infinity();
    if (below <= above)
      (*clusters)[k - 1].end = smallest->end;
    else
      (*clusters)[k + 1].begin = smallest->begin;
    clusters->erase(clusters->begin() + k);
  }
}

std::vector<int> RingsFromElevation(const LidarCloud& cloud, double gap) {
  const size_t n = cloud.size();
  std::vector<double> elevation(n);
  for (size_t i = 0; i < n; ++i)
    elevation[i] = cloud.points[i].allFinite() ? Elevation(cloud.points[i]) : 0.0;
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), size_t{0});
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return elevation[a] < elevation[b]; });
  std::vector<double> sorted(n);
  for (size_t k = 0; k < n; ++k) sorted[k] = elevation[order[k]];

  std::vector<Cluster> clusters;
  for (const Cluster& run : SplitAtGaps(sorted, gap)) {
    for (const Cluster& part : SplitAtValleys(sorted, run, gap)) clusters.push_back(part);
  }
  MergeSlivers(sorted, &clusters);
  std::vector<int> rings(n);
  for (size_t c = 0; c < clusters.size(); ++c)
    for (size_t k = clusters[c].begin; k < clusters[c].end; ++k)
      rings[order[k]] = static_cast<int>(c);
  return rings;
}

// Occupied cells of `cell_rad` (azimuth x elevation).
std::size_t OccupiedCells(const LidarCloud& cloud, double cell_rad) {
  std::unordered_set<std::int64_t> occupied;
  for (const Eigen::Vector3f& p : cloud.points) {
    if (!p.allFinite() || p.squaredNorm() < 1e-12f) continue;
    const auto az = static_cast<std::int64_t>(std::floor(std::atan2(p.y(), p.x()) / cell_rad));
    const auto el = static_cast<std::int64_t>(std::floor(Elevation(p) / cell_rad));
    occupied.insert(el * 100000 + az);
  }
  return occupied.size();
}

// Whether inferred rings are rings: each cluster a thin cone (median elevation extent within
// 0.5°), not a band tens of degrees tall (a rosette's returns make one or two such "clusters").
bool RingLike(const LidarCloud& cloud, const std::vector<int>& rings) {
  if (rings.empty()) return true;
  const int count = *std::max_element(rings.begin(), rings.end()) + 1;
  std::vector<double> low(count, M_PI), high(count, -M_PI);
  for (size_t i = 0; i < cloud.size(); ++i) {
    if (!HasDirection(cloud.points[i])) continue;
    const double e = Elevation(cloud.points[i]);
    low[rings[i]] = std::min(low[rings[i]], e);
    high[rings[i]] = std::max(high[rings[i]], e);
  }
  std::vector<double> extents;
  for (int r = 0; r < count; ++r)
    if (high[r] >= low[r]) extents.push_back(high[r] - low[r]);
  if (extents.empty()) return true;
  std::nth_element(extents.begin(), extents.begin() + extents.size() / 2, extents.end());
  return extents[extents.size() / 2] <= 0.5 * kDegToRad;
}

// About one column per point of a ring: the median ring size, within sane image widths.
int AutoColumns(const std::vector<int>& rings, const std::vector<int>& ring_ids) {
  if (ring_ids.empty()) return 360;
  std::vector<int> count(ring_ids.back() + 1, 0);
  for (const int r : rings) ++count[r];
  std::vector<int> sizes;
  for (const int id : ring_ids) sizes.push_back(count[id]);
  std::nth_element(sizes.begin(), sizes.begin() + sizes.size() / 2, sizes.end());
  return std::clamp(sizes[sizes.size() / 2], 360, 4096);
}

}  // namespace

// About one return per cell, and cells that are mostly filled: neighbourhoods need returns on
// every side. A uniform scan fills cells of its solid angle (counted on a 1 degree grid) over its
// returns; a non-repetitive pattern lays its returns along curves (a Livox rosette's petals, a
// tenth of a second leaving gaps of a degree), so the cell grows until at least
// kMinCellFill of the covered area's cells hold a return.
double RasterCellDeg(const LidarCloud& cloud) {
  constexpr double kMinCellFill = 0.6;
  const double covered_deg2 = double(OccupiedCells(cloud, kDegToRad));
  if (covered_deg2 == 0 || cloud.size() == 0) return 1.0;
  double cell_deg = std::clamp(std::sqrt(covered_deg2 / double(cloud.size())), 0.05, 2.0);
  while (cell_deg < 1.0 && double(OccupiedCells(cloud, cell_deg * kDegToRad)) <
                               kMinCellFill * covered_deg2 / (cell_deg * cell_deg))
    cell_deg = std::min(1.0, cell_deg * 1.2);
  return cell_deg;
}

bool LidarImageOptions::Check(std::string* why) const {
  if (columns < 0 || columns > 65536) {
    if (why) *why = "columns must be 0 (automatic) or 1..65536, got " + std::to_string(columns);
    return false;
  }
  // Below 0.05 degrees the elevation histogram gets needlessly fine (and slow); above 0.1 rad
  // (5.7 degrees) the gap exceeds the beam spacing of every spinning LiDAR.
  constexpr double kMinGap = 0.05 * kDegToRad, kMaxGap = 0.1;
  if (!(ring_gap_rad >= kMinGap && ring_gap_rad < kMaxGap)) {
    if (why)
      *why = "ring_gap_rad must be in [0.05 deg, 0.1 rad) and below the beam spacing, got " +
             std::to_string(ring_gap_rad);
    return false;
  }
  return true;
}

namespace {

// Options are checked by the caller (CLI, GUI) before any work; reaching here with bad ones is a
// programmer error.
void RequireValid(const LidarImageOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw std::invalid_argument("LidarImageOptions: " + why);
}

}  // namespace

std::vector<int> InferRings(const LidarCloud& cloud, const LidarImageOptions& options) {
  RequireValid(options);
  if (cloud.HasRing()) {
    CALIBENCH_CHECK(cloud.ring.size() == cloud.size());
    return cloud.ring;
  }
  if (cloud.IsOrganized()) return RingsFromRows(cloud);
  return RingsFromElevation(cloud, options.ring_gap_rad);
}

int AzimuthColumn(const Eigen::Vector3f& point, int columns) {
  CALIBENCH_CHECK(columns > 0);
  // Eq. (10)–(11) with fx = -columns / (2 pi), cx = columns / 2. Rounding puts pixel centres on
  // integer u, so scanners firing on a regular azimuth grid fill one column per firing.
  const double fx = -columns / (2 * M_PI), cx = columns / 2.0;
  const double u = fx * std::atan2(double{point.y()}, double{point.x()}) + cx;
  const int col = static_cast<int>(std::lround(u)) % columns;
  return col < 0 ? col + columns : col;
}

LidarImage ProjectById(const LidarCloud& cloud, const LidarImageOptions& options) {
  std::vector<int> rings = InferRings(cloud, options);
  // A cloud without rings (a Livox rosette, a nodding scanner): rows are elevation bins of the
  // raster cell, so the image is an azimuth x elevation raster at the sensor's aspect.
  double raster_cell_rad = 0.0;
  if (!cloud.HasRing() && !cloud.IsOrganized() && !RingLike(cloud, rings)) {
    raster_cell_rad = RasterCellDeg(cloud) * kDegToRad;
    double lowest = M_PI;
    for (const Eigen::Vector3f& p : cloud.points)
      if (HasDirection(p)) lowest = std::min(lowest, Elevation(p));
    for (size_t i = 0; i < cloud.size(); ++i)
      rings[i] = HasDirection(cloud.points[i])
                     ? static_cast<int>((Elevation(cloud.points[i]) - lowest) / raster_cell_rad)
                     : 0;
  }
  std::vector<int> ring_ids = rings;
  std::sort(ring_ids.begin(), ring_ids.end());
  ring_ids.erase(std::unique(ring_ids.begin(), ring_ids.end()), ring_ids.end());
  CALIBENCH_CHECK(ring_ids.empty() || ring_ids.front() >= 0);

  LidarImage image;
  image.rows = static_cast<int>(ring_ids.size());
  image.columns =
      options.columns > 0 ? options.columns
      : raster_cell_rad > 0
          ? std::clamp(static_cast<int>(std::lround(2.0 * M_PI / raster_cell_rad)), 360, 8192)
          : AutoColumns(rings, ring_ids);
  image.ring_of_row.assign(ring_ids.rbegin(), ring_ids.rend());  // row 0 = highest ring
  std::vector<int> row_of_ring(ring_ids.empty() ? 0 : ring_ids.back() + 1, -1);
  for (int row = 0; row < image.rows; ++row) row_of_ring[image.ring_of_row[row]] = row;

  const size_t pixels = static_cast<size_t>(image.rows) * image.columns;
  image.point_index.assign(pixels, -1);
  image.intensity.assign(pixels, kNaN);
  image.range.assign(pixels, kNaN);
  image.pixel_of_point.assign(cloud.size(), -1);
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    if (!p.allFinite()) continue;
    // The sensor's own range when the file has it, else the distance from the LiDAR origin.
    const float range =
        !cloud.range.empty() && std::isfinite(cloud.range[i]) ? cloud.range[i] : p.norm();
    // Eq. (12): row from ring(v), column from atan2(v_y, v_x).
    const int pixel = image.PixelIndex(row_of_ring[rings[i]], AzimuthColumn(p, image.columns));
    const int previous = image.point_index[pixel];
    if (previous >= 0 && !(range < image.range[pixel])) continue;  // nearest point wins
    if (previous >= 0) image.pixel_of_point[previous] = -1;
    image.point_index[pixel] = static_cast<int>(i);
    image.pixel_of_point[i] = pixel;
    image.range[pixel] = range;
    image.intensity[pixel] = cloud.HasIntensity() ? cloud.intensity[i] : range;
  }
  std::vector<double> sum(image.rows, 0.0);
  std::vector<int> count(image.rows, 0);
  for (size_t pixel = 0; pixel < pixels; ++pixel) {
    const int index = image.point_index[pixel];
    if (index < 0) continue;
    const Eigen::Vector3f& p = cloud.points[index];
    sum[pixel / image.columns] += std::atan2(p.z(), std::hypot(p.x(), p.y()));
    ++count[pixel / image.columns];
  }
  image.row_elevation_rad.resize(image.rows);
  for (int row = 0; row < image.rows; ++row)
    image.row_elevation_rad[row] = count[row] ? static_cast<float>(sum[row] / count[row]) : kNaN;
  return image;
}

double LidarImage::VerticalSpanRad() const {
  std::vector<double> elevations;
  for (float e : row_elevation_rad)
    if (std::isfinite(e)) elevations.push_back(e);
  if (elevations.size() < 2) return 0.0;
  std::sort(elevations.begin(), elevations.end());
  std::vector<double> steps;
  for (size_t i = 1; i < elevations.size(); ++i) steps.push_back(elevations[i] - elevations[i - 1]);
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  return elevations.back() - elevations.front() + steps[steps.size() / 2];
}

}  // namespace calibench
