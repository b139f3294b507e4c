#include "core/lidar/swept_origin.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/base/types.h"

namespace calibench {
namespace {

// The sampled returns in their scan's half-plane: distance from the axis and height.
struct HalfPlanePoints {
  std::vector<double> radial, height;
};

HalfPlanePoints Sample(const LidarCloud& cloud, int max_points) {
  HalfPlanePoints out;
  const size_t stride = std::max<size_t>(1, cloud.size() / std::max(1, max_points));
  for (size_t i = 0; i < cloud.size(); i += stride) {
    const Eigen::Vector3f& p = cloud.points[i];
    if (!p.allFinite()) continue;
    const double radial = std::hypot(double(p.x()), double(p.y()));
    if (radial < 0.5) continue;  // near the axis the half-plane's angle says little
    out.radial.push_back(radial);
    out.height.push_back(p.z());
  }
  return out;
}

// How concentrated the returns' directions seen from (radial_m, height_m) are: Σ n² / N² over a
// histogram of their slopes (height over distance, bins of `bin` ≈ radians near level; slopes
// beyond ±3 are left out). The slope rather than the angle: a division per return, not an atan2,
// and a fan's discrete beams are as discrete in either.
double Sharpness(const HalfPlanePoints& points, double radial_m, double height_m, double bin,
                 std::vector<int>* counts) {
  constexpr double kMaxSlope = 3.0;
  const int bins = static_cast<int>(std::ceil(2.0 * kMaxSlope / bin)) + 1;
  counts->assign(bins, 0);
  long used = 0;
  for (size_t i = 0; i < points.radial.size(); ++i) {
    const double along = points.radial[i] - radial_m;
    if (along <= 0.1) continue;
    const double slope = (points.height[i] - height_m) / along;
    if (std::abs(slope) >= kMaxSlope) continue;
    ++(*counts)[static_cast<int>((slope + kMaxSlope) / bin)];
    ++used;
  }
  if (used == 0) return 0.0;
  double sum = 0.0;
  for (const int n : *counts) sum += static_cast<double>(n) * n;
  return sum / (static_cast<double>(used) * used);
}

// The grid point of (centre ± half_width, step) where the directions are sharpest.
SweptOrigin BestOnGrid(const HalfPlanePoints& points, const SweptOrigin& centre, double half_width,
                       double step, double bin) {
  std::vector<int> counts;
  SweptOrigin best = centre;
  best.gain = -1.0;
  const int n = static_cast<int>(std::round(half_width / step));
  for (int i = -n; i <= n; ++i)
    for (int j = -n; j <= n; ++j) {
      const double radial = centre.radial_m + i * step, height = centre.height_m + j * step;
      const double sharpness = Sharpness(points, radial, height, bin, &counts);
      if (sharpness > best.gain) best = {radial, height, sharpness};
    }
  return best;
}

}  // namespace

bool SweptOriginOptions::Check(std::string* why) const {
  auto fail = [&](const char* text) {
    if (why) *why = text;
    return false;
  };
  if (!(search_m > 0 && search_m <= 1.0)) return fail("search_m must be in (0, 1] metres");
  if (!(coarse_step_m > 0 && fine_step_m > 0 && fine_step_m <= coarse_step_m))
    return fail("the steps must be > 0 metres, the fine one at most the coarse one");
  if (!(coarse_bin_deg > 0 && fine_bin_deg > 0)) return fail("the bins must be > 0 degrees");
  if (max_points < 100) return fail("max_points must be >= 100");
  if (!(min_gain >= 1.0)) return fail("min_gain must be >= 1");
  return true;
}

std::optional<SweptOrigin> EstimateSweptOrigin(const LidarCloud& cloud,
                                               const SweptOriginOptions& options) {
  const HalfPlanePoints points = Sample(cloud, options.max_points);
  if (points.radial.size() < 100) return std::nullopt;
  // The coarse grid (most of the work) on half as many returns: its wider bins need fewer.
  const SweptOrigin coarse = BestOnGrid(Sample(cloud, options.max_points / 2), {}, options.search_m,
                                        options.coarse_step_m, options.coarse_bin_deg * kDegToRad);
  SweptOrigin fine = BestOnGrid(points, coarse, 1.5 * options.coarse_step_m, options.fine_step_m,
                                options.fine_bin_deg * kDegToRad);
  std::vector<int> counts;
  const double at_origin = Sharpness(points, 0.0, 0.0, options.fine_bin_deg * kDegToRad, &counts);
  if (!(at_origin > 0)) return std::nullopt;
  fine.gain /= at_origin;
  if (fine.gain < options.min_gain) return std::nullopt;
  return fine;
}

std::vector<Eigen::Vector3f> SweptViewpoints(const LidarCloud& cloud, const SweptOrigin& origin) {
  std::vector<Eigen::Vector3f> viewpoints;
  viewpoints.reserve(cloud.size());
  for (const Eigen::Vector3f& p : cloud.points) {
    const double azimuth = std::atan2(double(p.y()), double(p.x()));
    viewpoints.emplace_back(static_cast<float>(origin.radial_m * std::cos(azimuth)),
                            static_cast<float>(origin.radial_m * std::sin(azimuth)),
                            static_cast<float>(origin.height_m));
  }
  return viewpoints;
}

std::string DescribeSweptOrigin(const SweptOrigin& origin) {
  char text[200];
  std::snprintf(text, sizeof(text),
                "its rays start %.1f cm from the stage's axis and %.1f cm up it (estimated: the "
                "beams' angles %.1fx sharper from there than from the origin)",
                origin.radial_m * 100, origin.height_m * 100, origin.gain);
  return text;
}

}  // namespace calibench
