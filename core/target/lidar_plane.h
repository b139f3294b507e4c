// LiDAR side of a pair: pick the board region (a brush on the LiDAR image or a seed point with a
// radius), fit a plane by RANSAC (PCL), refit by least squares on the inliers, with covariance.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/board/board.h"
#include "core/geometry/geometry.h"
#include "core/lidar/cloud.h"
#include "core/lidar/lidar_geometry.h"
#include "core/lidar/lidar_image.h"
#include "core/target/board_edges.h"
#include "core/target/lidar_noise.h"
#include "core/target/ring_bias.h"

namespace calibench {

struct LidarPlaneOptions {
  // The sensor's geometry decides the noise model (core/lidar/lidar_geometry.h): a spinning
  // LiDAR's planes are fitted on the ranges along its rays (fit_ranges_ml), grown over the board
  // by ray, with ring biases and board edges (a ring's ends); a non-repetitive scan's the same
  // way, its edges where the beam's path crosses the sheet's border, no ring biases; a swept
  // laser's or a segment's by total least squares (isotropic point-to-plane, the plane's own
  // covariance), grown by distance to the plane, without ring biases or edges — unless the cloud
  // gives each return's ray origin (LidarCloud::viewpoint): then along those rays, as a spinning
  // LiDAR's without rings.
  LidarGeometry geometry = LidarGeometry::kSpinning;
  double ransac_threshold_m = 0.03;  // inlier distance; ~3σ of typical spinning-LiDAR range noise
  int ransac_iterations = 500;       // enough for > 50% inliers with a 1e-9 failure chance
  int min_inliers = 20;              // fewer inliers = no plane (a board needs a few rings)
  double min_inlier_fraction = 0.3;  // of the candidate points
  std::uint64_t seed = 1;            // RANSAC sampling order; same seed, same plane
  // Final fit by maximum likelihood on the ranges along the rays (FitPlaneRangeMl). LiDAR noise
  // lies along each ray, so the total-least-squares plane of a tilted board is biased (the bias
  // grows with σ² and the tilt); false keeps the total-least-squares refit.
  bool fit_ranges_ml = true;
  // Grow the fit from the selected region to the whole board: every return within the range band
  // of the plane whose ray meets the plane within this radius (metres) of the board centre found
  // from those returns. A brush or seed disc usually covers a third of the board; the returns it
  // leaves out carry the rest of the plane's information (the far boards' tilt above all).
  // 0 = keep the selected region. Set from the target by BoardGrowRadius.
  double grow_radius_m = 0.0;
  // The sheet's [width, height] in metres when known: the grown fit then also finds the rings'
  // crossings of the sheet's edges (LidarPlaneFit::edge_points). 0 = unknown, no edge points.
  Vec2 sheet_size_m = Vec2::Zero();
  BoardEdgeOptions edges;
  // A spinning LiDAR's lasers each keep a small range bias after their factory calibration
  // (metres, 1σ per ring; a few mm on a VLP-16). Such biases are common to a ring's returns, so
  // they do not average out over the points: a board seen by few rings (a strip) has a tilt about
  // the rings' direction that is far less certain than its fit's residuals say
  // (LidarPlaneFit::ring_bias_covariance). 0 = none.
  double ring_bias_sigma_m = 0.005;
  // The cloud is a board-only crop (judged a segment from its look), whatever model fits it: its
  // returns end where the crop did, not at the sheet's edges (no edge points), and where their
  // elevations fall into rings they carry the rings' range biases as a spinning scan's would.
  bool board_only_crop = false;
  bool Check(std::string* why) const;
};

// LidarPlaneFit::no_edge_search of a board-only crop's fit (LidarPlaneOptions::board_only_crop):
// how the result's model line tells a crop fitted along its rays.
inline constexpr const char* kBoardOnlyCropNoEdges =
    "the cloud is a board-only crop: its returns end where the crop did, not at the sheet's edges";

// The grow radius for a target: half the sheet's diagonal, 5% and 2 cm more so that the corners'
// returns stay in while the centre estimate settles.
double BoardGrowRadius(const BoardSpec& board);

struct LidarPlaneFit {
  Plane plane;                     // LiDAR frame, normal towards the LiDAR (d > 0)
  Mat4 covariance = Mat4::Zero();  // of (n, d) from the least-squares refit; rank 3
  std::vector<int> inliers;        // indices into the cloud
  // Each inlier's time after the cloud's stamp (LidarCloud::time_s), as `inliers`; empty when
  // the cloud has no per-point times (the board then counts as seen at the stamp).
  std::vector<float> inlier_times_s;
  Vec3 inlier_centroid = Vec3::Zero();  // mean of the inliers (LiDAR frame, metres)
  int num_candidates = 0;               // points in the brushed / seeded region
  bool grown = false;                   // inliers extend beyond the region (grow_radius_m)
  // How the fitted (n, d) moves per metre of a range offset added to every return (FitPlaneRangeMl
  // only; zero = unknown): the solver's handle on a LiDAR range offset.
  Vec4 range_offset_jacobian = Vec4::Zero();
  // The range residuals' sums against the angular term's leverage (FitPlaneRangeMl only; count 0
  // otherwise), from which the dataset's angular noise is learned (core/target/lidar_noise.h).
  RangeResidualMoments range_moments;
  // Where the rings leave the board (LidarPlaneOptions::sheet_size_m), with that sheet size.
  std::vector<LidarEdgePoint> edge_points;
  BoardEdgeEnds edge_ends;     // what the rings' ends said (why some gave no edge point)
  std::string no_edge_search;  // why the edges were not looked for ("" when they were)
  Vec2 sheet_size_m = Vec2::Zero();
  // The covariance of (n, d) that per-ring range biases (LidarPlaneOptions::ring_bias_sigma_m)
  // give the fit, on top of `covariance`: large for a strip's tilt across its few rings, small for
  // a board that many rings cross. Rings are the cloud's own, else clusters of elevation.
  Mat4 ring_bias_covariance = Mat4::Zero();
  LidarGeometryVerdict lidar_model;  // the noise model it was fitted with, and why
  double rms_m = 0.0;                // point-to-plane RMS of the inliers
  int num_rings = 0;  // distinct rings among the inliers (0 = the cloud has no rings)
  // The same region fitted under the other candidate noise model (along rays / point-to-plane),
  // for a ring-less cloud whose model the data choose (core/lidar_camera/lidar_model_evidence.h);
  // null otherwise.
  std::shared_ptr<const LidarPlaneFit> alternative;
};

// Points on rays within the cone that a disc of `seed.radius` (metres) around `seed.point`
// subtends from the LiDAR, and within max(3 radius, 0.3 m) of its range.
std::vector<int> SelectSeedRegion(const LidarCloud& cloud, const LidarSeed& seed);

// Points under brushed LiDAR-image pixels (indices into image.point_index).
std::vector<int> SelectBrushRegion(const LidarImage& image, const std::vector<int>& pixels);

// RANSAC + least-squares refit over the candidate points. nullopt with *why when the region is
// empty, too small, or holds no plane with enough inliers.
std::optional<LidarPlaneFit> FitBoardPlane(const LidarCloud& cloud,
                                           const std::vector<int>& candidates,
                                           const LidarPlaneOptions& options, std::string* why);

// Least-squares (total least squares) plane through points with its (n, d) covariance, the
// residual variance estimated from the fit. Needs >= 4 points not on a line.
std::optional<LidarPlaneFit> FitPlaneLeastSquares(const LidarCloud& cloud,
                                                  const std::vector<int>& indices);

// Maximum likelihood plane under range noise along the rays from the LiDAR origin: minimises
// Σ (r_i − r̂_i)², r_i = |x_i|, r̂_i = −d / (n·u_i) the range at which ray u_i = x_i/|x_i| meets
// the plane (Gauss-Newton on n's tangent plane and d, started at `initial`). Covariance
// σ̂² (JᵀJ)⁻¹ with σ̂² from the range residuals; rms_m is the range RMS. nullopt when fewer than 4
// points, a ray parallel to the plane, or no convergence.
std::optional<LidarPlaneFit> FitPlaneRangeMl(const LidarCloud& cloud,
                                             const std::vector<int>& indices, const Plane& initial);

}  // namespace calibench
