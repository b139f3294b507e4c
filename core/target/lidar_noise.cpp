#include "core/target/lidar_noise.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/base/statistics.h"
#include "core/base/types.h"

namespace calibench {

void RangeResidualMoments::Add(double z, double residual_m) {
  const double e2 = residual_m * residual_m;
  ++count;
  sum_z += z;
  sum_zz += z * z;
  sum_e2 += e2;
  sum_z_e2 += z * e2;
  min_z = std::min(min_z, z);
  max_z = std::max(max_z, z);
}

namespace {

constexpr int kMinReturns = 10;

}  // namespace

LidarNoiseEstimate EstimateLidarNoise(const std::vector<RangeResidualMoments>& boards) {
  LidarNoiseEstimate estimate;
  // The regression of e² on z over every return: Sxx = Σ (z − z̄)², Sxy = Σ (z − z̄) e².
  double n = 0.0, sum_z = 0.0, sum_zz = 0.0, sum_e2 = 0.0, sum_z_e2 = 0.0;
  std::vector<const RangeResidualMoments*> used;
  for (const RangeResidualMoments& b : boards) {
    if (b.count < kMinReturns) continue;
    used.push_back(&b);
    n += b.count;
    sum_z += b.sum_z;
    sum_zz += b.sum_zz;
    sum_e2 += b.sum_e2;
    sum_z_e2 += b.sum_z_e2;
  }
  estimate.boards = static_cast<int>(used.size());
  estimate.returns = static_cast<int>(n);
  if (used.empty()) return estimate;
  const double mean_z = sum_z / n;
  const double sxx = sum_zz - sum_z * sum_z / n;
  const double sxy = sum_z_e2 - sum_z * sum_e2 / n;
  // Boards that all face the sensor alike at one range inform no slope: the term is then not
  // resolved and no bound is claimed beyond what the spread allows (an infinite one).
  const double slope = sxx > 0 ? sxy / sxx : 0.0;
  // Var(e²) = 2 v² for a Gaussian residual of variance v; v taken as the board's mean e².
  double slope_variance = 0.0;
  for (const RangeResidualMoments* b : used) {
    const double v = b->sum_e2 / b->count;
    const double spread = b->sum_zz - 2.0 * mean_z * b->sum_z + b->count * mean_z * mean_z;
    slope_variance += 2.0 * v * v * spread;
  }
  const double se =
      sxx > 0 ? std::sqrt(slope_variance) / sxx : std::numeric_limits<double>::infinity();
  estimate.angular_sigma_rad = std::sqrt(std::max(slope, 0.0));
  estimate.angular_sigma_upper_rad = std::sqrt(std::max(slope + 1.96 * se, 0.0));
  estimate.angular_resolved = slope > 2.0 * se;
  const double angular_variance = std::max(slope, 0.0);
  std::vector<double> range_sigmas;
  for (const RangeResidualMoments* b : used) {
    // The board's intercept: its mean e² less the angular term's share, never below a tenth of it.
    const double mean_e2 = b->sum_e2 / b->count;
    const double range_variance =
        std::max(mean_e2 - angular_variance * b->sum_z / b->count, 0.1 * mean_e2);
    range_sigmas.push_back(std::sqrt(range_variance));
    const double kappa = (range_variance + angular_variance * b->max_z) /
                         (range_variance + angular_variance * std::max(b->min_z, 0.0));
    estimate.equal_weight_efficiency_min = std::min(estimate.equal_weight_efficiency_min,
                                                    4.0 * kappa / ((1.0 + kappa) * (1.0 + kappa)));
  }
  estimate.range_sigma_median_m = Median(range_sigmas);
  estimate.range_sigma_min_m = *std::min_element(range_sigmas.begin(), range_sigmas.end());
  estimate.range_sigma_max_m = *std::max_element(range_sigmas.begin(), range_sigmas.end());
  return estimate;
}

std::string DescribeLidarNoise(const LidarNoiseEstimate& e) {
  if (e.boards == 0) return "";
  char line[512];
  int n = std::snprintf(line, sizeof(line),
                        "LiDAR noise learned from %d returns on %d boards: range sigma %.1f mm "
                        "(per board %.1f-%.1f mm); ",
                        e.returns, e.boards, e.range_sigma_median_m * 1e3,
                        e.range_sigma_min_m * 1e3, e.range_sigma_max_m * 1e3);
  if (e.angular_resolved)
    std::snprintf(line + n, sizeof(line) - n,
                  "angular sigma %.3f deg across the ray (95%% up to %.3f); equal weights along "
                  "the rays keep >= %.0f%% of the efficiency weighting by it would give",
                  e.angular_sigma_rad * kRadToDeg, e.angular_sigma_upper_rad * kRadToDeg,
                  100.0 * e.equal_weight_efficiency_min);
  else if (std::isfinite(e.angular_sigma_upper_rad))
    std::snprintf(line + n, sizeof(line) - n,
                  "no angular term resolved (below %.3f deg across the ray, 95%%)",
                  e.angular_sigma_upper_rad * kRadToDeg);
  else
    std::snprintf(line + n, sizeof(line) - n,
                  "no angular term: the boards' incidences and ranges do not vary enough to tell");
  return line;
}

}  // namespace calibench
