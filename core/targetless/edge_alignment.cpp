#include "core/targetless/edge_alignment.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "core/base/parallel.h"
#include "core/geometry/geometry.h"

namespace calibench {
namespace {

using Row6 = Eigen::Matrix<double, 1, 6>;

// One LiDAR edge matched to an image edge at a pose: whitened residual and Jacobian.
struct Match {
  double z = 0.0;         // residual / σ
  Row6 j = Row6::Zero();  // ∂z/∂δ
  double weight = 1.0;    // Huber's
  long cluster = 0;
};

// The residual of one LiDAR edge at `cam_from_lidar`, matched within `radius_px`; false when it
// does not project into the image or has no image edge near.
bool MatchEdge(const SceneEdgePoint& edge, const ImageEdgeMap& image_edges,
               const CameraModel& camera, const Pose& cam_from_lidar, double radius_px,
               const EdgeAlignmentOptions& options, int cells_x, bool* projected, Match* match) {
  const Vec3 rotated = cam_from_lidar.linear() * edge.point;
  const Vec3 in_cam = rotated + cam_from_lidar.translation();
  Eigen::Matrix<double, 2, 3> d_pixel;
  const std::optional<Vec2> pixel = camera.Project(in_cam, &d_pixel);
  if (!pixel || !camera.InImage(*pixel, 2.0)) return false;
  *projected = true;
  const ImageEdge* nearest = image_edges.Nearest(*pixel, radius_px);
  if (!nearest) return false;
  const double r = nearest->normal.dot(*pixel - nearest->pixel);
  // The LiDAR edge's own spread between its two returns, seen along the image edge's normal.
  const Vec3 shift = cam_from_lidar.linear() * edge.spread_direction *
                     (edge.point.norm() * edge.angular_sigma_rad);
  const double spread_px = nearest->normal.dot(d_pixel * shift);
  const double sigma =
      std::sqrt(options.image_sigma_px * options.image_sigma_px + spread_px * spread_px);
  Eigen::Matrix<double, 3, 6> d_point;
  d_point.leftCols<3>() = Mat3::Identity();
  d_point.rightCols<3>() = -Skew(rotated);
  match->z = r / sigma;
  match->j = nearest->normal.transpose() * d_pixel * d_point / sigma;
  const double a = std::abs(match->z);
  match->weight = a <= options.huber_k ? 1.0 : options.huber_k / a;
  match->cluster = static_cast<long>(pixel->y() / options.cluster_px) * cells_x +
                   static_cast<long>(pixel->x() / options.cluster_px);
  return true;
}

struct FrameMatches {
  std::vector<Match> matches;
  int considered = 0;  // edges of the kinds taking part
  int projected = 0;
};

std::vector<FrameMatches> MatchAll(const std::vector<EdgeFrame>& frames, const CameraModel& camera,
                                   const Pose& pose, double radius_px,
                                   const EdgeAlignmentOptions& options) {
  std::vector<FrameMatches> out(frames.size());
  const int cells_x = static_cast<int>(std::ceil(camera.width / options.cluster_px)) + 1;
  ParallelFor(frames.size(), options.threads > 0 ? options.threads : DefaultThreads(),
              [&](size_t f) {
                for (const SceneEdgePoint& edge : frames[f].lidar_edges) {
                  if (!(edge.kind == SceneEdgeKind::kDepth ? options.use_depth_edges
                                                           : options.use_intensity_edges))
                    continue;
                  ++out[f].considered;
                  bool projected = false;
                  Match m;
                  if (MatchEdge(edge, frames[f].image_edges, camera, pose, radius_px, options,
                                cells_x, &projected, &m))
                    out[f].matches.push_back(m);
                  out[f].projected += projected;
                }
              });
  return out;
}

double HuberCost(double z, double k) {
  const double a = std::abs(z);
  return a <= k ? 0.5 * z * z : k * (a - 0.5 * k);
}

// The robust cost of matches at a radius: an edge without a match costs what a residual at the
// radius would, also one that leaves the image (else a pose that pushes edges out of view would
// look good).
double CostOf(const std::vector<FrameMatches>& all, double radius_px,
              const EdgeAlignmentOptions& options) {
  const double cap = HuberCost(radius_px / options.image_sigma_px, options.huber_k);
  double cost = 0.0;
  for (const FrameMatches& f : all) {
    for (const Match& m : f.matches) cost += std::min(cap, HuberCost(m.z, options.huber_k));
    cost += cap * (f.considered - static_cast<int>(f.matches.size()));
  }
  return cost;
}

}  // namespace

bool EdgeAlignmentOptions::Check(std::string* why) const {
  auto fail = [&](const char* text) {
    if (why) *why = text;
    return false;
  };
  if (!(search_deg >= 0) || !(search_m >= 0))
    return fail("the search window must be >= 0 degrees and >= 0 m");
  if (!(typical_depth_m > 0)) return fail("the typical depth must be > 0 m");
  if (!(final_radius_px > 0)) return fail("the final matching radius must be > 0 pixels");
  if (!(image_sigma_px > 0)) return fail("an image edge's sigma must be > 0 pixels");
  if (!(huber_k > 0)) return fail("Huber's k must be > 0");
  if (max_iterations_per_level < 1) return fail("at least one iteration per level");
  if (!(cluster_px >= 1)) return fail("the sandwich's cluster must be >= 1 pixel");
  return true;
}

Pose PerturbOnCameraAxes(const Pose& cam_from_lidar, const Vec6& delta) {
  Pose out = cam_from_lidar;
  out.linear() = ExpSO3(delta.tail<3>()) * cam_from_lidar.linear();
  out.translation() = cam_from_lidar.translation() + delta.head<3>();
  return out;
}

Vec6 DeltaOnCameraAxes(const Pose& from, const Pose& to) {
  Vec6 delta;
  delta.head<3>() = to.translation() - from.translation();
  delta.tail<3>() = LogSO3(to.linear() * from.linear().transpose());
  return delta;
}

double AlignmentCost(const std::vector<EdgeFrame>& frames, const CameraModel& camera,
                     const Pose& cam_from_lidar, const EdgeAlignmentOptions& options,
                     double radius_px) {
  const double radius = radius_px > 0 ? radius_px : options.final_radius_px;
  return CostOf(MatchAll(frames, camera, cam_from_lidar, radius, options), radius, options);
}

std::vector<double> AlignmentCostPerFrame(const std::vector<EdgeFrame>& frames,
                                          const CameraModel& camera, const Pose& cam_from_lidar,
                                          const EdgeAlignmentOptions& options) {
  const std::vector<FrameMatches> all =
      MatchAll(frames, camera, cam_from_lidar, options.final_radius_px, options);
  std::vector<double> costs;
  for (const FrameMatches& f : all) costs.push_back(CostOf({f}, options.final_radius_px, options));
  return costs;
}

namespace {

// What every level of one alignment shares.
struct AlignmentProblem {
  const std::vector<EdgeFrame>& frames;
  const CameraModel& camera;
  const EdgeAlignmentOptions& options;
  Pose prior_centre;
  Mat6 prior;  // the search window as information 1/σ² per axis
  double fx = 0.0;

  double Cost(const Pose& pose, double radius, std::vector<FrameMatches>* matches) const {
    *matches = MatchAll(frames, camera, pose, radius, options);
    const Vec6 d = DeltaOnCameraAxes(prior_centre, pose);
    return CostOf(*matches, radius, options) + 0.5 * d.dot(prior * d);
  }
};

// One level of the coarse-to-fine schedule: iterates from *pose at this matching radius; leaves
// the pose reached and its matches (always the matches of that pose). True when it converged.
//
// Levenberg–Marquardt on the coarse levels: a step is kept only when the robust cost at this
// radius (an edge without a match, or out of view, at the cap) with the prior falls. Without that
// test a direction the edges barely fix drifts with the correspondences' noise, iteration after
// iteration, until the edges slide off each other. The final radius takes Gauss–Newton's steps as
// they come: correspondences within a few pixels change from step to step, and a cost test there
// stops short of the minimum.
bool SolveLevel(const AlignmentProblem& problem, double radius, bool final_level, Pose* pose,
                std::vector<FrameMatches>* matches) {
  const EdgeAlignmentOptions& options = problem.options;
  // Coarse levels only bring the edges near: fewer iterations, a looser stop. The final stop
  // (0.1 mm, 0.0006 deg) lies far below any σ the edges give.
  const int iterations = final_level ? options.max_iterations_per_level
                                     : std::min(15, options.max_iterations_per_level);
  const double stop_m = final_level ? 1e-4 : 1e-3, stop_rad = final_level ? 1e-5 : 1e-4;
  double cost = problem.Cost(*pose, radius, matches);
  double lambda = 1e-4;
  for (int it = 0; it < iterations; ++it) {
    Mat6 h = problem.prior;
    Vec6 g = problem.prior * DeltaOnCameraAxes(problem.prior_centre, *pose);
    int n = 0;
    for (const FrameMatches& f : *matches) {
      for (const Match& m : f.matches) {
        h += m.weight * m.j.transpose() * m.j;
        g += m.weight * m.j.transpose() * m.z;
        ++n;
      }
    }
    if (n < 12) return false;
    Mat6 damped = h;
    damped.diagonal() *= 1.0 + lambda;
    Vec6 delta = -damped.ldlt().solve(g);
    if (!delta.allFinite()) return false;
    // A step never moves the edges farther than the matching radius: beyond it the matches it
    // was computed from say nothing.
    const double reach = radius / problem.fx;
    delta /= std::max({1.0, delta.tail<3>().norm() / reach,
                       delta.head<3>().norm() / (reach * options.typical_depth_m)});
    const bool small = delta.head<3>().norm() < stop_m && delta.tail<3>().norm() < stop_rad;
    const Pose candidate = PerturbOnCameraAxes(*pose, delta);
    std::vector<FrameMatches> candidate_matches;
    const double candidate_cost = problem.Cost(candidate, radius, &candidate_matches);
    if (candidate_cost <= cost || final_level) {
      *pose = candidate, *matches = std::move(candidate_matches), cost = candidate_cost;
      lambda = std::max(1e-7, lambda / 3);
      if (small) return true;
    } else {
      lambda *= 10;
      // No smaller step lowers the cost: this is the minimum at this radius.
      if (small || lambda > 1e4) return true;
    }
  }
  return false;
}

// The figures of an alignment from the final radius' matches: counts, the information and the
// cluster-robust sandwich covariance, the prior counted as one more observation.
void Summarise(const std::vector<FrameMatches>& matches, const Mat6& prior, EdgeAlignment* out) {
  std::unordered_map<long, Vec6> per_cluster;
  double sum_sq = 0.0;
  for (const FrameMatches& f : matches) {
    out->points_projected += f.projected;
    out->matched_per_frame.push_back(static_cast<int>(f.matches.size()));
    for (const Match& m : f.matches) {
      out->information += m.weight * m.j.transpose() * m.j;
      auto [it, inserted] = per_cluster.try_emplace(m.cluster, Vec6::Zero());
      it->second += m.weight * m.j.transpose() * m.z;
      sum_sq += m.z * m.z;
      ++out->points_matched;
    }
  }
  out->clusters = static_cast<int>(per_cluster.size());
  out->rms_sigma = out->points_matched > 0 ? std::sqrt(sum_sq / out->points_matched) : 0.0;
  if (out->clusters <= 6) return;
  Mat6 meat = Mat6::Zero();
  for (const auto& [cluster, g] : per_cluster) meat += g * g.transpose();
  meat *= static_cast<double>(out->clusters) / (out->clusters - 6);
  meat += prior;
  out->information += prior;
  const Mat6 h_inv = out->information.inverse();
  out->covariance = h_inv * meat * h_inv.transpose();
  out->covariance = 0.5 * (out->covariance + out->covariance.transpose());
}

}  // namespace

EdgeAlignment AlignEdges(const std::vector<EdgeFrame>& frames, const CameraModel& camera,
                         const Pose& start, const EdgeAlignmentOptions& options,
                         double first_radius_px, const Pose* prior_centre) {
  // The search window as a prior about R (information 1/σ² per axis): a direction the edges do
  // not constrain stays where the calibration put it, with the window as its σ, instead of
  // running off.
  Vec6 prior_information;
  prior_information << Vec3::Constant(1.0 / std::pow(std::max(options.search_m, 1e-4), 2)),
      Vec3::Constant(1.0 / std::pow(std::max(options.search_deg, 1e-3) * kDegToRad, 2));
  const AlignmentProblem problem{frames,
                                 camera,
                                 options,
                                 prior_centre ? *prior_centre : start,
                                 prior_information.asDiagonal(),
                                 std::max(camera.fx, camera.fy)};
  // Coarse to fine: the first radius covers the search window's reach in the image.
  double radius =
      std::max(options.final_radius_px,
               first_radius_px > 0 ? first_radius_px
                                   : problem.fx * (options.search_deg * kDegToRad +
                                                   options.search_m / options.typical_depth_m));
  EdgeAlignment out;
  Pose pose = start;
  std::vector<FrameMatches> matches;
  while (true) {
    const bool final_level = radius <= options.final_radius_px * 1.0001;
    const bool converged = SolveLevel(problem, radius, final_level, &pose, &matches);
    if (final_level) {
      out.converged = converged;
      break;
    }
    radius = std::max(options.final_radius_px, 0.5 * radius);
  }
  // `matches` are the final radius' at `pose`.
  out.cam_from_lidar = pose;
  Summarise(matches, problem.prior, &out);
  return out;
}

}  // namespace calibench
