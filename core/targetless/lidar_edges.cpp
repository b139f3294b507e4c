#include "core/targetless/lidar_edges.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <optional>

namespace calibench {
namespace {

constexpr double kSqrt12 = 3.4641016151377544;

struct LineReturn {
  Vec3 point;
  Vec3 direction;  // unit
  double range = 0.0;
  double azimuth = 0.0;
  double intensity = 0.0;  // normalised: 1 = the cloud's 98th percentile
};

// Scan lines: rings when known, else elevation bands; each ordered by azimuth.
std::vector<std::vector<LineReturn>> ScanLines(const LidarCloud& cloud,
                                               const LidarEdgeOptions& options) {
  double intensity_scale = 1.0;
  if (cloud.HasIntensity()) {
    std::vector<float> sorted = cloud.intensity;
    const size_t k = static_cast<size_t>(0.98 * (sorted.size() - 1));
    std::nth_element(sorted.begin(), sorted.begin() + k, sorted.end());
    if (sorted[k] > 0) intensity_scale = 1.0 / sorted[k];
  }
  std::map<int, std::vector<LineReturn>> lines;
  const double band_rad = options.line_height_deg * kDegToRad;
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Vec3 p = cloud.points[i].cast<double>();
    const double range = p.norm();
    if (!std::isfinite(range) || range < 0.5 * options.min_range_m) continue;
    LineReturn r{p, p / range, range, std::atan2(p.y(), p.x()),
                 cloud.HasIntensity() ? cloud.intensity[i] * intensity_scale : 0.0};
    const int line = cloud.HasRing()
                         ? cloud.ring[i]
                         : static_cast<int>(std::floor(
                               std::asin(std::clamp(p.z() / range, -1.0, 1.0)) / band_rad));
    lines[line].push_back(r);
  }
  // Lines in order of elevation: rings count from the lowest beam, bands from the lowest band.
  std::vector<std::vector<LineReturn>> out;
  for (auto& [id, line] : lines) {
    if (line.size() < 8) continue;
    std::sort(line.begin(), line.end(),
              [](const LineReturn& a, const LineReturn& b) { return a.azimuth < b.azimuth; });
    out.push_back(std::move(line));
  }
  return out;
}

double MedianStep(const std::vector<LineReturn>& line) {
  std::vector<double> steps;
  steps.reserve(line.size());
  for (size_t i = 1; i < line.size(); ++i) {
    const double step = line[i].azimuth - line[i - 1].azimuth;
    if (step > 0) steps.push_back(step);
  }
  if (steps.empty()) return 0.0;
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  return steps[steps.size() / 2];
}

Vec3 AzimuthTangent(const Vec3& direction) {
  const Vec3 t = Vec3::UnitZ().cross(direction);
  return t.norm() > 1e-9 ? Vec3(t.normalized()) : Vec3::UnitY();
}

bool IsDepthJump(double near_range, double far_range, const LidarEdgeOptions& options) {
  return far_range - near_range >
         std::max(options.min_depth_jump_m, options.min_depth_jump_ratio * near_range);
}

// A depth edge between returns a (before) and b (after): a jump in inverse range much larger than
// the steps on either side of it. On a plane 1/range is linear along any line of returns, so a
// surface seen at a grazing angle (a floor across rings, a wall along the beam), whose range
// grows by metres from return to return, steps evenly and is not taken for a silhouette.
// `before` / `after`: the returns beyond a and beyond b on the same line (nullptr when none).
std::optional<SceneEdgePoint> DepthEdgeBetween(const LineReturn& a, const LineReturn& b,
                                               const LineReturn* before, const LineReturn* after,
                                               double gap_rad, const Vec3& spread_direction,
                                               const LidarEdgeOptions& options) {
  const LineReturn* near = nullptr;
  if (IsDepthJump(a.range, b.range, options)) near = &a;
  if (IsDepthJump(b.range, a.range, options)) near = &b;
  if (!near || near->range < options.min_range_m || near->range > options.max_range_m)
    return std::nullopt;
  if (!before && !after) return std::nullopt;
  // In inverse range, which is linear along any line of returns on a plane.
  const double jump = std::abs(1.0 / b.range - 1.0 / a.range);
  const double side = std::max(before ? std::abs(1.0 / a.range - 1.0 / before->range) : 0.0,
                               after ? std::abs(1.0 / after->range - 1.0 / b.range) : 0.0);
  if (jump < options.min_abruptness * side) return std::nullopt;
  // An occluding edge, not a fold: the near surface, continued past its last return to the far
  // ray (linearly in inverse range, as a plane is), must pass well in front of the far return. At
  // a concave corner (a wall meeting the ceiling between two rings) the far return lies on or in
  // front of that continuation: the surfaces meet between the rays, and the midpoint of the rays
  // at the near range is not where the image's edge is. Without a return beyond the near one
  // (the outermost ring) the two cannot be told apart, and the edge is left out.
  const LineReturn* near_beyond = near == &a ? before : after;
  const LineReturn& far = near == &a ? b : a;
  if (!near_beyond) return std::nullopt;
  const double continued_inverse = 2.0 / near->range - 1.0 / near_beyond->range;
  if (continued_inverse <= 0.0 || far.range - 1.0 / continued_inverse < options.min_depth_jump_m)
    return std::nullopt;
  // The silhouette lies somewhere between the two rays, at the near surface's range.
  const Vec3 direction = (a.direction + b.direction).normalized();
  return SceneEdgePoint{near->range * direction, gap_rad / kSqrt12, spread_direction,
                        SceneEdgeKind::kDepth};
}

void DepthEdges(const std::vector<LineReturn>& line, double max_gap,
                const LidarEdgeOptions& options, std::vector<SceneEdgePoint>* edges) {
  auto linked = [&](size_t i, size_t j) {
    const double gap = line[j].azimuth - line[i].azimuth;
    return gap > 0 && gap <= max_gap;
  };
  for (size_t i = 0; i + 1 < line.size(); ++i) {
    if (!linked(i, i + 1)) continue;
    const LineReturn* before = i > 0 && linked(i - 1, i) ? &line[i - 1] : nullptr;
    const LineReturn* after = i + 2 < line.size() && linked(i + 1, i + 2) ? &line[i + 2] : nullptr;
    const Vec3 direction = (line[i].direction + line[i + 1].direction).normalized();
    if (auto edge = DepthEdgeBetween(line[i], line[i + 1], before, after,
                                     line[i + 1].azimuth - line[i].azimuth,
                                     AzimuthTangent(direction), options))
      edges->push_back(*edge);
  }
}

void IntensityEdges(const std::vector<LineReturn>& line, double max_gap,
                    const LidarEdgeOptions& options, std::vector<SceneEdgePoint>* edges) {
  const size_t n = line.size();
  if (n < 6) return;
  // step[i]: the step between returns i and i+1, from two returns on each side; 0 where the four
  // returns are not one smooth surface without gaps.
  std::vector<double> step(n, 0.0);
  for (size_t i = 1; i + 2 < n; ++i) {
    bool smooth = true;
    for (size_t k = i - 1; k < i + 2 && smooth; ++k) {
      const double gap = line[k + 1].azimuth - line[k].azimuth;
      smooth = gap > 0 && gap <= max_gap &&
               !IsDepthJump(std::min(line[k].range, line[k + 1].range),
                            std::max(line[k].range, line[k + 1].range), options);
    }
    if (!smooth) continue;
    step[i] = 0.5 * (line[i + 1].intensity + line[i + 2].intensity) -
              0.5 * (line[i - 1].intensity + line[i].intensity);
  }
  for (size_t i = 1; i + 2 < n; ++i) {
    const double s = std::abs(step[i]);
    if (s < options.min_intensity_step || s < std::abs(step[i - 1]) || s <= std::abs(step[i + 1]))
      continue;
    const LineReturn& a = line[i];
    const LineReturn& b = line[i + 1];
    const double range = 0.5 * (a.range + b.range);
    if (range < options.min_range_m || range > options.max_range_m) continue;
    const Vec3 direction = (a.direction + b.direction).normalized();
    edges->push_back({range * direction, (b.azimuth - a.azimuth) / kSqrt12,
                      AzimuthTangent(direction), SceneEdgeKind::kIntensity});
  }
}

// The return of a line nearest in azimuth, nullptr when none lies within max_gap.
const LineReturn* NearestInLine(const std::vector<LineReturn>& line, double azimuth,
                                double max_gap) {
  if (line.empty()) return nullptr;
  const auto it =
      std::lower_bound(line.begin(), line.end(), azimuth,
                       [](const LineReturn& r, double value) { return r.azimuth < value; });
  const LineReturn* best = nullptr;
  if (it != line.end()) best = &*it;
  if (it != line.begin() && (!best || azimuth - std::prev(it)->azimuth < best->azimuth - azimuth))
    best = &*std::prev(it);
  return std::abs(best->azimuth - azimuth) <= max_gap ? best : nullptr;
}

// Depth edges between line l and line l + 1 (the top and bottom of objects): each return of the
// lower line against the upper line's return nearest in azimuth, lines l - 1 and l + 2 giving the
// steps on either side.
void CrossLineDepthEdges(const std::vector<std::vector<LineReturn>>& lines, size_t l,
                         double max_gap, const LidarEdgeOptions& options,
                         std::vector<SceneEdgePoint>* edges) {
  for (const LineReturn& a : lines[l]) {
    const LineReturn* b = NearestInLine(lines[l + 1], a.azimuth, max_gap);
    if (!b) continue;
    const LineReturn* before = l > 0 ? NearestInLine(lines[l - 1], a.azimuth, max_gap) : nullptr;
    const LineReturn* after =
        l + 2 < lines.size() ? NearestInLine(lines[l + 2], b->azimuth, max_gap) : nullptr;
    const double gap = std::acos(std::clamp(a.direction.dot(b->direction), -1.0, 1.0));
    const Vec3 direction = (a.direction + b->direction).normalized();
    // Across lines the edge's uncertainty runs along the elevation's tangent.
    const Vec3 d = b->direction - a.direction;
    const Vec3 along = d - direction * direction.dot(d);
    if (!(gap > 0) || along.norm() < 1e-12) continue;
    if (auto edge = DepthEdgeBetween(a, *b, before, after, gap, along.normalized(), options))
      edges->push_back(*edge);
  }
}

}  // namespace

bool LidarEdgeOptions::Check(std::string* why) const {
  auto fail = [&](const char* text) {
    if (why) *why = text;
    return false;
  };
  if (!(min_depth_jump_m > 0) || !(min_depth_jump_ratio >= 0))
    return fail("the depth jump of an edge must be > 0 m");
  if (!(min_intensity_step > 0)) return fail("the intensity step of an edge must be > 0");
  if (!(min_range_m >= 0) || !(max_range_m > min_range_m))
    return fail("the edges' range window must satisfy 0 <= min < max");
  if (!(min_abruptness >= 1)) return fail("a depth edge's abruptness must be >= 1");
  if (!(max_gap_steps >= 1)) return fail("a scan line's gap must be at least one step");
  if (!(line_height_deg > 0)) return fail("a scan line's height must be > 0 degrees");
  return true;
}

std::vector<SceneEdgePoint> ExtractLidarEdges(const LidarCloud& cloud,
                                              const LidarEdgeOptions& options) {
  std::vector<SceneEdgePoint> edges;
  const std::vector<std::vector<LineReturn>> lines = ScanLines(cloud, options);
  for (size_t l = 0; l < lines.size(); ++l) {
    const double max_gap = options.max_gap_steps * MedianStep(lines[l]);
    if (!(max_gap > 0)) continue;
    if (options.depth_edges) DepthEdges(lines[l], max_gap, options, &edges);
    if (options.intensity_edges && cloud.HasIntensity())
      IntensityEdges(lines[l], max_gap, options, &edges);
    if (options.depth_edges && l + 1 < lines.size())
      CrossLineDepthEdges(lines, l, max_gap, options, &edges);
  }
  return edges;
}

}  // namespace calibench
