// The LiDAR's noise learned from the boards' own returns: a range term along each ray and an
// angular term across it, the second estimated over the whole dataset (docs/architecture.md,
// "Noise learned from the data").
//
// A return's range residual against its board's plane (the fit along the rays, FitPlaneRangeMl)
// has variance
//     v_i = σ_r² + σ_θ² z_i,   z_i = r_i² tan² α_i,
// where r_i is its range, α_i the angle between its ray and the plane's normal and σ_θ the beam's
// angular jitter per axis: a ray turned by δ across itself lands r δ tan α further along the ray
// within the plane of incidence, and not at all across it. σ_θ² is the slope of the squared
// residuals over z, σ_r² their intercept, over every board's returns: the boards' different tilts
// and ranges inform it far more than the spread within one board does (a regression with one
// intercept per board resolved no term below about 0.4° on a VLP-16 set). A range noise that grows
// with the incidence (weak returns off an oblique sheet) reads as angular noise too: for the
// weights it is the same thing. Each board's own σ_r is then its mean e² less the angular share.
#pragma once

#include <limits>
#include <string>
#include <vector>

namespace calibench {

// What one board's fit contributes: sums over its returns of the range residual e and of z.
struct RangeResidualMoments {
  int count = 0;
  double sum_z = 0.0;     // Σ z_i (m²)
  double sum_zz = 0.0;    // Σ z_i²
  double sum_e2 = 0.0;    // Σ e_i² (m²)
  double sum_z_e2 = 0.0;  // Σ z_i e_i²
  double min_z = std::numeric_limits<double>::infinity();
  double max_z = 0.0;
  void Add(double z, double residual_m);
};

struct LidarNoiseEstimate {
  int boards = 0;
  int returns = 0;
  // Each board's range σ (its intercept), over the boards: median, smallest, largest (metres).
  double range_sigma_median_m = 0.0;
  double range_sigma_min_m = 0.0;
  double range_sigma_max_m = 0.0;
  // σ_θ (radians, per axis across the ray), and its 95 % upper bound: σ_θ at the slope σ_θ² plus
  // 1.96 of its standard errors (infinite when the boards' z do not vary).
  double angular_sigma_rad = 0.0;
  double angular_sigma_upper_rad = 0.0;
  // The slope exceeds twice its standard error: the data show an angular term.
  bool angular_resolved = false;
  // The smallest, over the boards, of Kantorovich's bound on the efficiency of equal weights
  // against weights 1/v_i: 4κ/(1+κ)², κ the board's largest over smallest v_i. Near 1, the fits
  // along the rays (equal weights) lose nothing by leaving the angular term out of their weights.
  double equal_weight_efficiency_min = 1.0;
};

// From the boards' moments (one per board fitted along its rays). Boards with fewer than 10
// returns are left out. `boards` is 0 when none is left.
LidarNoiseEstimate EstimateLidarNoise(const std::vector<RangeResidualMoments>& boards);

// One line for a person: "LiDAR noise learned from N returns on M boards: range σ 9.8 mm (per
// board 7.1-12.4 mm), angular σ 0.051 deg ± 0.006 ...", or why the angular term is not resolved.
std::string DescribeLidarNoise(const LidarNoiseEstimate& estimate);

}  // namespace calibench
