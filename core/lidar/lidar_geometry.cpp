#include "core/lidar/lidar_geometry.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <unordered_set>
#include <vector>

#include "core/base/names.h"

namespace calibench {
namespace {

constexpr EnumName<LidarGeometry> kLidarGeometryNames[] = {
    {LidarGeometry::kSpinning, "spinning"},
    {LidarGeometry::kSwept, "swept"},
    {LidarGeometry::kNonRepetitive, "non-repetitive"},
    {LidarGeometry::kSegment, "segment"}};

// Elevation clusters of the returns: each one's width and the spacing of their centres, and how
// far from the origin their rays start: a beam whose rays start a distance s off the origin
// (perpendicular to it) shows its returns at elevation α + s/r, so the slope of elevation over
// 1/r within a cluster measures s.
struct ElevationClusters {
  int count = 0;
  double median_width_deg = 0.0;
  double median_spacing_deg = 0.0;
  double ray_offset_m = 0.0;  // |s|, 90th percentile over the clusters whose ranges differ enough
  int offset_clusters = 0;    // those clusters
};

ElevationClusters ClusterElevations(const LidarCloud& cloud, double gap_deg) {
  struct Return {
    double elevation_rad;
    double inverse_range;
  };
  std::vector<Return> returns;
  returns.reserve(cloud.size());
  for (const Eigen::Vector3f& p : cloud.points) {
    if (!p.allFinite() || p.squaredNorm() < 1e-12f) continue;
    const double horizontal = std::hypot(double(p.x()), double(p.y()));
    returns.push_back({std::atan2(double(p.z()), horizontal), 1.0 / p.cast<double>().norm()});
  }
  ElevationClusters clusters;
  if (returns.empty()) return clusters;
  std::sort(returns.begin(), returns.end(),
            [](const Return& a, const Return& b) { return a.elevation_rad < b.elevation_rad; });
  const double gap_rad = gap_deg * kDegToRad;
  std::vector<double> widths, centres, offsets;
  size_t first = 0;
  for (size_t i = 1; i <= returns.size(); ++i) {
    if (i < returns.size() && returns[i].elevation_rad - returns[i - 1].elevation_rad <= gap_rad)
      continue;
    const double low = returns[first].elevation_rad, high = returns[i - 1].elevation_rad;
    widths.push_back((high - low) * kRadToDeg);
    centres.push_back(0.5 * (high + low) * kRadToDeg);
    // How far the cluster's elevation spreads per unit of 1/r it spans: at most |s| for one
    // beam, 0 for rays from the origin (however far its ranges differ). Clusters whose ranges
    // span little of 1/r (0.02 /m: 5 m against 8 m) say nothing.
    double min_u = 1e9, max_u = 0;
    for (size_t k = first; k < i; ++k) {
      min_u = std::min(min_u, returns[k].inverse_range);
      max_u = std::max(max_u, returns[k].inverse_range);
    }
    if (i - first >= 20 && max_u - min_u > 0.02) offsets.push_back((high - low) / (max_u - min_u));
    first = i;
  }
  auto median = [](std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  std::vector<double> spacings;
  for (size_t i = 1; i < centres.size(); ++i) spacings.push_back(centres[i] - centres[i - 1]);
  clusters.count = static_cast<int>(centres.size());
  clusters.median_width_deg = median(widths);
  clusters.median_spacing_deg = median(spacings);
  // The 90th percentile: a mirror off the axis shows in the beams it offsets most (an offset
  // forwards and one upwards cancel for some beams), a central sensor in none.
  if (!offsets.empty()) {
    const size_t k = offsets.size() * 9 / 10;
    std::nth_element(offsets.begin(), offsets.begin() + k, offsets.end());
    clusters.ray_offset_m = offsets[k];
  }
  clusters.offset_clusters = static_cast<int>(offsets.size());
  return clusters;
}

}  // namespace

std::string LidarGeometryName(LidarGeometry geometry) {
  return NameIn(kLidarGeometryNames, geometry);
}

std::optional<LidarGeometry> ParseLidarGeometry(const std::string& name) {
  return ValueIn(kLidarGeometryNames, name);
}

std::string LidarGeometryNames() { return NamesIn(kLidarGeometryNames); }

bool RaysFromOrigin(LidarGeometry geometry) {
  return geometry == LidarGeometry::kSpinning || geometry == LidarGeometry::kNonRepetitive;
}

bool LidarGeometryOptions::Check(std::string* why) const {
  auto fail = [&](const char* message) {
    if (why) *why = message;
    return false;
  };
  if (!(max_segment_extent_m > 0)) return fail("max_segment_extent_m must be > 0 (metres)");
  if (!(ring_gap_deg > 0)) return fail("ring_gap_deg must be > 0 (degrees)");
  if (!(max_ring_width_fraction > 0 && max_ring_width_fraction < 1))
    return fail("max_ring_width_fraction must be in (0, 1)");
  if (min_rings < 2) return fail("min_rings must be >= 2");
  if (!(max_ray_offset_m > 0)) return fail("max_ray_offset_m must be > 0 (metres)");
  return true;
}

double AzimuthCoverageDeg(const LidarCloud& cloud) {
  constexpr double kCellDeg = 0.5;
  std::unordered_set<int> cells;
  for (const Eigen::Vector3f& p : cloud.points) {
    if (!p.allFinite() || p.squaredNorm() < 1e-12f) continue;
    cells.insert(static_cast<int>(
        std::floor((std::atan2(double(p.y()), double(p.x())) * kRadToDeg + 180.0) / kCellDeg)));
  }
  return std::min(360.0, static_cast<double>(cells.size()) * kCellDeg);
}

double CloudExtentM(const LidarCloud& cloud) {
  std::vector<float> axis[3];
  for (const Eigen::Vector3f& p : cloud.points) {
    if (!p.allFinite() || p.squaredNorm() < 1e-12f) continue;
    for (int k = 0; k < 3; ++k) axis[k].push_back(p[k]);
  }
  if (axis[0].empty()) return 0.0;
  Eigen::Vector3f centre;
  for (int k = 0; k < 3; ++k) {
    std::nth_element(axis[k].begin(), axis[k].begin() + axis[k].size() / 2, axis[k].end());
    centre[k] = axis[k][axis[k].size() / 2];
  }
  std::vector<float> distances;
  distances.reserve(axis[0].size());
  for (const Eigen::Vector3f& p : cloud.points)
    if (p.allFinite() && p.squaredNorm() >= 1e-12f) distances.push_back((p - centre).norm());
  const size_t k = distances.size() * 9 / 10;
  std::nth_element(distances.begin(), distances.begin() + k, distances.end());
  return distances[k];
}

LidarGeometryVerdict ClassifyLidarGeometry(const LidarCloud& cloud,
                                           const LidarGeometryOptions& options) {
  LidarGeometryVerdict verdict;
  char text[400];
  if (cloud.HasRing()) {
    verdict.geometry = LidarGeometry::kSpinning;
    verdict.why = "the cloud carries rings: rays from one centre";
    return verdict;
  }
  const double coverage = AzimuthCoverageDeg(cloud);
  const double extent_m = CloudExtentM(cloud);
  if (extent_m <= options.max_segment_extent_m) {
    std::snprintf(text, sizeof(text),
                  "no rings, and the returns lie within %.2f m of their centre (90%%; %.0f deg of "
                  "azimuth): a segment (the board cropped out of a scan), too little to tell how "
                  "its rays run",
                  extent_m, coverage);
    verdict.geometry = LidarGeometry::kSegment;
    verdict.why = text;
    return verdict;
  }
  const ElevationClusters clusters = ClusterElevations(cloud, options.ring_gap_deg);
  const bool cones =
      clusters.count >= options.min_rings &&
      clusters.median_width_deg < options.max_ring_width_fraction * clusters.median_spacing_deg;
  if (cones && clusters.ray_offset_m > options.max_ray_offset_m) {
    std::snprintf(text, sizeof(text),
                  "no rings; the returns lie on %d bands of elevation, but each band's elevation "
                  "moves with the range as from rays that start up to %.1f cm off the origin (90th "
                  "percentile over %d bands): a swept pattern whose rays do not meet at the "
                  "origin",
                  clusters.count, clusters.ray_offset_m * 100, clusters.offset_clusters);
    verdict.geometry = LidarGeometry::kSwept;
    verdict.why = text;
    return verdict;
  }
  if (cones) {
    std::snprintf(text, sizeof(text),
                  "no ring field, but the returns lie on %d cones of elevation (%.2f deg wide, "
                  "%.2f deg apart, median; rays within %.1f cm of the origin): rays from one "
                  "centre",
                  clusters.count, clusters.median_width_deg, clusters.median_spacing_deg,
                  clusters.ray_offset_m * 100);
    verdict.geometry = LidarGeometry::kSpinning;
    verdict.why = text;
    return verdict;
  }
  // A whole scan (returns metres apart) whose elevations run on no cones: one beam steered over
  // the field without rings (Livox-class prisms), or a line scanner's fan nodded through a tilt.
  // Its ranges are measured along rays from the sensor, as every time-of-flight sensor's are.
  std::snprintf(text, sizeof(text),
                "no rings, and the returns' elevations form no cones (%d clusters, %.2f deg wide, "
                "median) over a scan of %.0f deg of azimuth, %.1f m about its centre: a scan "
                "that follows no rings (a non-repetitive rosette, a nodding line scanner), "
                "ranges along rays from the origin",
                clusters.count, clusters.median_width_deg, coverage, extent_m);
  verdict.geometry = LidarGeometry::kNonRepetitive;
  verdict.why = text;
  return verdict;
}

bool LidarModelEvidenceOptions::Check(std::string* why) const {
  auto fail = [&](const char* message) {
    if (why) *why = message;
    return false;
  };
  if (folds < 2) return fail("lidar model evidence: folds must be >= 2");
  if (min_pairs < 3) return fail("lidar model evidence: min_pairs must be >= 3");
  if (!(tie_ratio >= 1)) return fail("lidar model evidence: tie_ratio must be >= 1");
  if (!(min_significance_z >= 0))
    return fail("lidar model evidence: min_significance_z must be >= 0");
  return true;
}

std::string LidarModelEvidence::Describe() const {
  if (candidates.size() < 2) return "";
  auto words = [](const LidarModelCandidate& c) {
    return c.along_rays ? "ranges along rays (" + LidarGeometryName(c.geometry) + ")"
                        : std::string("point-to-plane");
  };
  const LidarModelCandidate& best = candidates[0];
  const LidarModelCandidate& other = candidates[1];
  char text[600];
  if (tie)
    std::snprintf(text, sizeof(text),
                  "The held-out pairs cannot tell %s from %s (%.2fx, %.1f standard "
                  "errors, over %d pairs; median %.1f mm against %.1f mm): the cloud's look "
                  "decides (%s)",
                  words(best).c_str(), words(other).c_str(), margin, significance_z,
                  best.heldout_pairs, best.heldout_rms_m * 1e3, other.heldout_rms_m * 1e3,
                  LidarGeometryName(chosen).c_str());
  else
    std::snprintf(text, sizeof(text),
                  "Chosen by the held-out pairs: %s, their boards %.2fx closer to its "
                  "planes than with %s (%.1f standard errors, over %d pairs; median %.1f mm "
                  "against %.1f mm)",
                  words(best).c_str(), margin, words(other).c_str(), significance_z,
                  best.heldout_pairs, best.heldout_rms_m * 1e3, other.heldout_rms_m * 1e3);
  std::string out = text;
  if (switched_pairs > 0)
    out += "; " + std::to_string(switched_pairs) + " pair(s) refitted against the cloud's look";
  return out;
}

}  // namespace calibench
