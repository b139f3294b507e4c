#include "core/target/lidar_plane.h"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/ransac.h>
#include <pcl/sample_consensus/sac_model_plane.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>

namespace calibench {

bool LidarPlaneOptions::Check(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (!(ransac_threshold_m > 0)) return fail("ransac_threshold_m must be > 0 (metres)");
  if (ransac_iterations < 1) return fail("ransac_iterations must be >= 1");
  if (min_inliers < 4) return fail("min_inliers must be >= 4");
  if (!(min_inlier_fraction >= 0 && min_inlier_fraction <= 1))
    return fail("min_inlier_fraction must be in [0, 1]");
  if (!(grow_radius_m >= 0) || !std::isfinite(grow_radius_m))
    return fail("grow_radius_m must be >= 0 (metres; 0 = no growing)");
  if (!(sheet_size_m.minCoeff() >= 0) || !sheet_size_m.allFinite())
    return fail("sheet_size_m must be >= 0 (metres; 0 = unknown)");
  if (!edges.Check(why)) return false;
  if (!(ring_bias_sigma_m >= 0) || !std::isfinite(ring_bias_sigma_m))
    return fail("ring_bias_sigma_m must be >= 0 (metres; 0 = none)");
  return true;
}

double BoardGrowRadius(const BoardSpec& board) {
  return 1.05 * 0.5 * std::hypot(board.SheetWidth(), board.SheetHeight()) + 0.02;
}

namespace {

// The plane in coordinates centred on a ray's origin o (x' = x − o): n·x' + (d + n·o) = 0.
Plane SeenFrom(const Plane& plane, const Vec3& origin) {
  return Plane{plane.normal, plane.distance + plane.normal.dot(origin)};
}

// Range residual r − r̂ of a return against a plane (r̂ where its ray, from `origin`, meets the
// plane); nullopt for rays within ~1° of the plane.
std::optional<double> RangeResidual(const Plane& plane, const Vec3& x, const Vec3& origin) {
  const Vec3 ray = x - origin;
  const auto on_plane = RangeOnPlane(SeenFrom(plane, origin), ray);
  if (!on_plane) return std::nullopt;
  return ray.norm() - *on_plane;
}

// The range band for inliers: 3σ̂ of the fit, at least the RANSAC threshold and at most five
// times it (see FitBoardPlane).
double RangeBand(const LidarPlaneOptions& options, double rms_m) {
  return std::min(5.0 * options.ransac_threshold_m,
                  std::max(options.ransac_threshold_m, 3.0 * rms_m));
}

// Maximum-likelihood refit with the band re-drawn around each new plane, over `candidates`.
std::optional<LidarPlaneFit> RefineRangeMl(const LidarCloud& cloud,
                                           const std::vector<int>& candidates,
                                           const LidarPlaneFit& start,
                                           const LidarPlaneOptions& options) {
  std::optional<LidarPlaneFit> fit;
  std::vector<int> inliers = start.inliers;
  Plane plane = start.plane;
  for (int round = 0; round < 4; ++round) {
    auto ml = FitPlaneRangeMl(cloud, inliers, plane);
    if (!ml) break;
    fit = ml;
    const double band_m = RangeBand(options, ml->rms_m);
    std::vector<int> reselected;
    for (int i : candidates) {
      const auto residual =
          RangeResidual(ml->plane, cloud.points[i].cast<double>(), cloud.RayOrigin(i));
      if (residual && std::abs(*residual) <= band_m) reselected.push_back(i);
    }
    if (reselected == inliers || reselected.size() < 4) break;
    inliers = std::move(reselected);
    plane = ml->plane;
  }
  return fit;
}

// RefineRangeMl's counterpart for the isotropic model (swept lasers, segments): total least
// squares, the band redrawn around each plane by point-to-plane distance.
std::optional<LidarPlaneFit> RefineLeastSquares(const LidarCloud& cloud,
                                                const std::vector<int>& candidates,
                                                const LidarPlaneFit& start,
                                                const LidarPlaneOptions& options) {
  std::optional<LidarPlaneFit> fit;
  std::vector<int> inliers = start.inliers;
  for (int round = 0; round < 4; ++round) {
    auto ls = FitPlaneLeastSquares(cloud, inliers);
    if (!ls) break;
    fit = ls;
    const double band_m = RangeBand(options, ls->rms_m);
    std::vector<int> reselected;
    for (int i : candidates)
      if (std::abs(ls->plane.SignedDistance(cloud.points[i].cast<double>())) <= band_m)
        reselected.push_back(i);
    if (reselected == inliers || reselected.size() < 4) break;
    inliers = std::move(reselected);
  }
  return fit;
}

// Whether the cloud's rays are known: from the origin (a spinning or non-repetitive LiDAR's
// model), or from each return's own viewpoint where the cloud carries them (a swept scanner's
// mirror, core/lidar/cloud.h).
bool RaysKnown(const LidarPlaneOptions& options, const LidarCloud& cloud) {
  return RaysFromOrigin(options.geometry) || cloud.HasViewpoint();
}

// Whether the options fit ranges along those rays.
bool AlongRays(const LidarPlaneOptions& options, const LidarCloud& cloud) {
  return options.fit_ranges_ml && RaysKnown(options, cloud);
}

// Return i's residual against the plane in the options' model: along its ray, or (isotropic)
// along the normal; and where it lies on the plane.
std::optional<std::pair<double, Vec3>> ModelResidual(const Plane& plane, const LidarCloud& cloud,
                                                     size_t i, bool along_rays) {
  const Vec3 x = cloud.points[i].cast<double>();
  if (!along_rays) {
    const double distance = plane.SignedDistance(x);
    return std::make_pair(distance, Vec3(x - distance * plane.normal));
  }
  const Vec3 origin = cloud.RayOrigin(i);
  const auto residual = RangeResidual(plane, x, origin);
  if (!residual) return std::nullopt;
  return std::make_pair(*residual, Vec3(x - (x - origin).normalized() * *residual));
}

// Where the inliers meet the plane (along their rays, or projected), averaged: the board centre
// when the inliers cover it.
Vec3 InlierCentre(const LidarCloud& cloud, const LidarPlaneFit& fit, bool along_rays) {
  Vec3 sum = Vec3::Zero();
  int count = 0;
  for (int i : fit.inliers) {
    const Vec3 x = cloud.points[i].cast<double>();
    const Vec3 origin = cloud.RayOrigin(i);
    if (!along_rays) {
      sum += x - fit.plane.SignedDistance(x) * fit.plane.normal;
      ++count;
    } else if (const auto range = RangeOnPlane(SeenFrom(fit.plane, origin), x - origin)) {
      sum += origin + (x - origin).normalized() * *range;
      ++count;
    }
  }
  return sum / std::max(1, count);
}

// FitBoardPlane's growing step (LidarPlaneOptions::grow_radius_m): candidates are the returns in
// the band whose ray meets the plane inside the disc around the current centre; the centre moves
// to the grown inliers' mean and the disc is drawn again until it settles. Selection is by ray
// direction and the band only, as for the seed region, so that it does not bias the plane.
LidarPlaneFit GrowToBoard(const LidarCloud& cloud, LidarPlaneFit fit,
                          const LidarPlaneOptions& options) {
  const bool along_rays = AlongRays(options, cloud);
  Vec3 centre = InlierCentre(cloud, fit, along_rays);
  for (int round = 0; round < 4; ++round) {
    const double gate_m = 2.0 * RangeBand(options, fit.rms_m);
    std::vector<int> candidates;
    for (size_t i = 0; i < cloud.size(); ++i) {
      const auto residual = ModelResidual(fit.plane, cloud, i, along_rays);
      if (!residual || std::abs(residual->first) > gate_m) continue;
      if ((residual->second - centre).norm() <= options.grow_radius_m)
        candidates.push_back(static_cast<int>(i));
    }
    auto grown = along_rays ? RefineRangeMl(cloud, candidates, fit, options)
                            : RefineLeastSquares(cloud, candidates, fit, options);
    if (!grown || grown->inliers.size() < fit.inliers.size()) break;
    fit = *grown;
    fit.grown = true;
    const Vec3 next_centre = InlierCentre(cloud, fit, along_rays);
    const bool settled = (next_centre - centre).norm() < 0.005;
    centre = next_centre;
    if (settled) break;
  }
  return fit;
}

}  // namespace

std::vector<int> SelectSeedRegion(const LidarCloud& cloud, const LidarSeed& seed) {
  // A cone of rays around the seed's direction (the disc of `radius` seen from the LiDAR) and a
  // range gate, not a ball: a ball keeps or drops a return depending on its range noise, and on a
  // tilted board that selection biases the plane (near-side returns pushed away stay in, those
  // pulled closer drop out). Directions carry no range noise, like the brush on the LiDAR image.
  std::vector<int> indices;
  const double seed_range = seed.point.norm();
  if (!(seed_range > 0)) return indices;
  const Vec3 axis = seed.point / seed_range;
  const double cos_cone = std::cos(std::asin(std::min(1.0, seed.radius / seed_range)));
  const double range_gate = std::max(3.0 * seed.radius, 0.3);
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Vec3 x = cloud.points[i].cast<double>();
    const double range = x.norm();
    if (range <= 0 || std::abs(range - seed_range) > range_gate) continue;
    if (axis.dot(x) >= cos_cone * range) indices.push_back(static_cast<int>(i));
  }
  return indices;
}

std::vector<int> SelectBrushRegion(const LidarImage& image, const std::vector<int>& pixels) {
  std::vector<int> indices;
  for (int pixel : pixels) {
    if (pixel < 0 || pixel >= static_cast<int>(image.point_index.size())) continue;
    if (image.point_index[pixel] >= 0) indices.push_back(image.point_index[pixel]);
  }
  std::sort(indices.begin(), indices.end());
  indices.erase(std::unique(indices.begin(), indices.end()), indices.end());
  return indices;
}

namespace {
Vec3 Centroid(const LidarCloud& cloud, const std::vector<int>& indices) {
  Vec3 sum = Vec3::Zero();
  for (int i : indices) sum += cloud.points[i].cast<double>();
  return indices.empty() ? sum : Vec3(sum / static_cast<double>(indices.size()));
}
}  // namespace

std::optional<LidarPlaneFit> FitPlaneLeastSquares(const LidarCloud& cloud,
                                                  const std::vector<int>& indices) {
  // Unweighted: every return counts alike (FitPlaneRangeMl models the range noise instead).
  const std::optional<PlaneFit> plane_fit = FitPlane(cloud.points, indices);
  if (!plane_fit) return std::nullopt;
  LidarPlaneFit fit;
  fit.plane = plane_fit->plane;
  fit.covariance = plane_fit->covariance;
  fit.rms_m = plane_fit->rms_m;
  fit.inliers = indices;
  fit.inlier_centroid = Centroid(cloud, indices);
  fit.num_candidates = static_cast<int>(indices.size());
  return fit;
}

namespace {

// Rings among the points (0 when the cloud has none).
int DistinctRings(const LidarCloud& cloud, const std::vector<int>& indices) {
  if (!cloud.HasRing()) return 0;
  std::set<int> rings;
  for (int i : indices) rings.insert(cloud.ring[i]);
  return static_cast<int>(rings.size());
}

// The fit's extent as the sensor shows it: the rings' crossings of the sheet's edges (or why they
// were not looked for), its rings and their range biases' covariance (spinning LiDARs only).
void AddBoardExtent(const LidarCloud& cloud, const LidarPlaneOptions& options, LidarPlaneFit* fit) {
  const bool spinning = options.geometry == LidarGeometry::kSpinning;
  // A ring-less scan crosses the sheet's border along its beam's path (a rosette's strokes, a
  // nodding fan's lines): where the cloud keeps its firing order, each crossing is an edge point.
  const bool beam_path = options.geometry == LidarGeometry::kNonRepetitive;
  // Edge points need the whole board's returns (the ends of a brushed patch are not its edges)
  // and rings, or a beam's path, whose ends they are.
  if (options.board_only_crop) {
    fit->no_edge_search = kBoardOnlyCropNoEdges;
  } else if (!spinning && !beam_path) {
    fit->no_edge_search =
        "the LiDAR model is " + LidarGeometryName(options.geometry) + ": no rings to end on it";
  } else if (fit->grown && options.sheet_size_m.minCoeff() > 0) {
    fit->edge_points =
        spinning ? ExtractBoardEdgePoints(cloud, fit->inliers, fit->plane, options.edges,
                                          &fit->edge_ends)
                 : ExtractBeamCrossingEdgePoints(cloud, fit->inliers, fit->plane, options.edges,
                                                 &fit->edge_ends, &fit->no_edge_search);
    fit->sheet_size_m = options.sheet_size_m;
  } else {
    fit->no_edge_search = options.sheet_size_m.minCoeff() > 0
                              ? "the plane's fit did not grow beyond its selected region"
                              : "the target gives no sheet size";
  }
  fit->num_rings = DistinctRings(cloud, fit->inliers);
  // A board-only segment cut from a spinning LiDAR's scan still carries its rings' range biases,
  // though its ring field is gone: where the returns' elevations fall into rings, they widen the
  // plane as on the whole scan (the real ACFR segments scatter about twice their point-to-plane
  // σ without it; docs/results.md).
  const bool segment_with_rings =
      (options.geometry == LidarGeometry::kSegment || options.board_only_crop) &&
      ElevationRings(cloud, fit->inliers) >= 3;
  if (options.ring_bias_sigma_m > 0 && (spinning || segment_with_rings))
    fit->ring_bias_covariance =
        RingBiasCovariance(cloud, fit->inliers, fit->plane, options.ring_bias_sigma_m);
}

}  // namespace

namespace {

// The plane through the returns' centroid that holds their principal direction and faces the
// origin as squarely as that allows: a board seen along one stroke of the scan.
std::optional<Plane> FacingPlane(const LidarCloud& cloud, const std::vector<int>& indices) {
  if (indices.size() < 4) return std::nullopt;
  const Vec3 centroid = Centroid(cloud, indices);
  Mat3 scatter = Mat3::Zero();
  for (int i : indices) {
    const Vec3 d = cloud.points[i].cast<double>() - centroid;
    scatter += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Mat3> eigen(scatter);
  const Vec3 along = eigen.eigenvectors().col(2);
  const Vec3 towards = -centroid.normalized();
  Vec3 normal = towards - towards.dot(along) * along;
  if (!(normal.norm() > 1e-6)) return std::nullopt;
  normal.normalize();
  return Plane{normal, -normal.dot(centroid)};
}

// The unbiased estimate (see LidarPlaneOptions::fit_ranges_ml) from the point-to-plane `fit`. The
// inlier band is re-drawn around the maximum-likelihood plane in range units
// (|r − r̂| ≤ max(threshold, 3σ̂_r)): a band around the biased least-squares plane would truncate
// the range noise on one side and carry the bias into the ML fit.
// The point-to-plane start takes the returns' thinnest direction for the normal. On a few strokes
// of a non-repetitive scan (returns along a curve, range noise wider than the curve) that lies
// across the strokes: a plane holding the rays, whose ML fit stays in its own basin. Started again
// from the plane that faces the sensor through the strokes, the ML fit that keeps more returns
// within the band (then the smaller RMS) is the board.
std::optional<LidarPlaneFit> RefineAlongRays(const LidarCloud& cloud,
                                             const std::vector<int>& candidates,
                                             const LidarPlaneFit& fit,
                                             const LidarPlaneOptions& options) {
  std::optional<LidarPlaneFit> ml = RefineRangeMl(cloud, candidates, fit, options);
  const std::optional<Plane> facing = FacingPlane(cloud, fit.inliers);
  if (!facing) return ml;
  LidarPlaneFit start = fit;
  start.plane = *facing;
  std::optional<LidarPlaneFit> again = RefineRangeMl(cloud, candidates, start, options);
  if (again && (!ml || again->inliers.size() > ml->inliers.size() ||
                (again->inliers.size() == ml->inliers.size() && again->rms_m < 0.99 * ml->rms_m)))
    return again;
  return ml;
}

}  // namespace

std::optional<LidarPlaneFit> FitBoardPlane(const LidarCloud& cloud,
                                           const std::vector<int>& candidates,
                                           const LidarPlaneOptions& options, std::string* why) {
  auto fail = [&](const std::string& m) -> std::optional<LidarPlaneFit> {
    if (why) *why = m;
    return std::nullopt;
  };
  if (candidates.empty()) return fail("the selected LiDAR region holds no points");
  if (static_cast<int>(candidates.size()) < options.min_inliers)
    return fail("the selected LiDAR region holds only " + std::to_string(candidates.size()) +
                " points (need " + std::to_string(options.min_inliers) + ")");

  // PCL's RANSAC draws from a fixed internal seed; shuffling the candidates with our own seed
  // makes the sampling depend on options.seed and on nothing else.
  std::vector<int> order = candidates;
  std::mt19937_64 rng(options.seed);
  std::shuffle(order.begin(), order.end(), rng);
  pcl::PointCloud<pcl::PointXYZ>::Ptr points(new pcl::PointCloud<pcl::PointXYZ>);
  points->reserve(order.size());
  for (int i : order)
    points->push_back(pcl::PointXYZ(cloud.points[i].x(), cloud.points[i].y(), cloud.points[i].z()));
  pcl::SampleConsensusModelPlane<pcl::PointXYZ>::Ptr model(
      new pcl::SampleConsensusModelPlane<pcl::PointXYZ>(points, false));
  pcl::RandomSampleConsensus<pcl::PointXYZ> ransac(model, options.ransac_threshold_m);
  ransac.setMaxIterations(options.ransac_iterations);
  if (!ransac.computeModel()) return fail("RANSAC found no plane in the selected LiDAR region");
  std::vector<int> local_inliers;
  ransac.getInliers(local_inliers);

  // Least-squares refit on the inliers, then one re-selection with the refined plane.
  std::vector<int> inliers;
  for (int k : local_inliers) inliers.push_back(order[k]);
  std::optional<LidarPlaneFit> fit = FitPlaneLeastSquares(cloud, inliers);
  if (!fit) return fail("the RANSAC inliers lie on a line (a single ring?): no plane");
  // Re-selection with an inlier band that adapts to the sensor: max(threshold, 3σ̂) with σ̂ the
  // RMS of the current inliers. A fixed band narrower than ~3σ truncates the noise (a 30 mm band
  // keeps 87% of 20 mm noise and shrinks its RMS by a quarter), which biases the covariance low;
  // the band grows until it holds the noise, capped at 5x the RANSAC threshold.
  double band = options.ransac_threshold_m;
  for (int round = 0; round < 4; ++round) {
    std::vector<int> refined;
    for (int i : candidates)
      if (std::abs(fit->plane.SignedDistance(cloud.points[i].cast<double>())) <= band)
        refined.push_back(i);
    if (refined.size() < 4) break;
    auto again = FitPlaneLeastSquares(cloud, refined);
    if (!again) break;
    fit = again;
    const double next_band = std::min(5.0 * options.ransac_threshold_m,
                                      std::max(options.ransac_threshold_m, 3.0 * fit->rms_m));
    if (next_band <= band * 1.05) break;
    band = next_band;
  }
  if (AlongRays(options, cloud)) {
    if (auto ml = RefineAlongRays(cloud, candidates, *fit, options)) fit = ml;
  }
  fit->num_candidates = static_cast<int>(candidates.size());
  const int n = static_cast<int>(fit->inliers.size());
  if (n < options.min_inliers)
    return fail("plane has only " + std::to_string(n) + " inliers (need " +
                std::to_string(options.min_inliers) + ")");
  if (n < options.min_inlier_fraction * candidates.size())
    return fail("plane explains only " + std::to_string(n) + " of " +
                std::to_string(candidates.size()) + " selected points");
  if (options.grow_radius_m > 0 && (options.fit_ranges_ml || !RaysKnown(options, cloud)))
    fit = GrowToBoard(cloud, *fit, options);
  AddBoardExtent(cloud, options, &*fit);
  if (cloud.HasTime()) {
    fit->inlier_times_s.reserve(fit->inliers.size());
    for (const int i : fit->inliers) fit->inlier_times_s.push_back(cloud.time_s[i]);
  }
  return fit;
}

}  // namespace calibench
