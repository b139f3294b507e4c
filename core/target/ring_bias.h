// Rings and their range biases in a cloud, with or without a ring field: each laser of a
// spinning LiDAR keeps a small range bias common to its ring's returns, which the number of
// returns does not average away (LidarPlaneOptions::ring_bias_sigma_m).
#pragma once

#include <vector>

#include "core/geometry/geometry.h"
#include "core/lidar/cloud.h"

namespace calibench {

// The group of each of `indices` when the returns' elevations are split at gaps over 0.15°: the
// rings of a cloud that lost its ring field.
std::vector<int> ElevationGroups(const LidarCloud& cloud, const std::vector<int>& indices);

// How many rings the returns' elevations show: groups of at least 3 returns, counted only when
// such groups hold 90 % of the returns (a scan without rings leaves scattered stragglers); 0
// otherwise.
int ElevationRings(const LidarCloud& cloud, const std::vector<int>& indices);

// The (n, d) covariance that a range bias common to each ring's returns (b_r ~ N(0, σ²) along the
// rays, independent between rings) gives the least-squares plane through `indices`: the sandwich
// σ² (AᵀA)⁻¹ (Σ_r s_r s_rᵀ) (AᵀA)⁻¹ over the point-to-plane rows a_i, s_r = Σ_{i∈r} a_i (n·u_i).
// Rings: the cloud's own, else the returns' elevations split at gaps over 0.15°.
Mat4 RingBiasCovariance(const LidarCloud& cloud, const std::vector<int>& indices,
                        const Plane& plane, double ring_bias_sigma_m);

}  // namespace calibench
