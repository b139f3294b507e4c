// FitPlaneRangeMl (core/target/lidar_plane.h): a board's plane by maximum likelihood on the
// ranges along each return's ray, from the LiDAR's origin or from the viewpoint the cloud gives
// the return (docs/architecture.md, "A ray's origin is given, never assumed").
#include <cmath>

#include "core/geometry/geometry.h"
#include "core/target/lidar_plane.h"

namespace calibench {

namespace {

// The range residuals of FitPlaneRangeMl: each return's ray (unit), measured range and the
// ray's origin (empty: all at the LiDAR's origin).
struct RangeResiduals {
  std::vector<Vec3> rays;
  std::vector<double> ranges;
  std::vector<Vec3> origins;

  // d_k = d + n·o_k: the plane's distance seen from return k's ray origin.
  double DistanceFrom(const Plane& p, size_t k) const {
    return origins.empty() ? p.distance : p.distance + p.normal.dot(origins[k]);
  }

  // Gauss-Newton's normal matrix JᵀJ, gradient Jᵀe and Σe² at plane p, over θ = (δ, δ_d) with
  // n ← n + B δ, d ← d + δ_d; *sum_jacobian = Σ ∂e_i/∂θ. Residual e_i = r_i − r̂_i, the ray
  // from o_i meeting the plane at r̂_i = −d_i/(n·u_i), d_i = d + n·o_i (the plane seen from o_i):
  // ∂r̂/∂δ = d_i (u_iᵀ B)/(n·u_i)² − (o_iᵀ B)/(n·u_i), ∂r̂/∂δ_d = −1/(n·u_i); ∂e/∂· = −∂r̂/∂·.
  // False when a ray grazes the plane (|cos| < 0.02, beyond 88.9°): no finite predicted range.
  bool Linearize(const Plane& p, Mat3* normal_matrix, Vec3* gradient, double* sum_sq,
                 Vec3* sum_jacobian) const {
    const Eigen::Matrix<double, 3, 2> b = PlaneTangentBasis(p.normal);
    *normal_matrix = Mat3::Zero();
    *gradient = Vec3::Zero();
    *sum_sq = 0.0;
    sum_jacobian->setZero();
    for (size_t k = 0; k < rays.size(); ++k) {
      const double cos_incidence = p.normal.dot(rays[k]);
      if (std::abs(cos_incidence) < 0.02) return false;
      const double distance = DistanceFrom(p, k);
      const double e = ranges[k] + distance / cos_incidence;
      Eigen::RowVector3d j;
      j.head<2>() = -distance * rays[k].transpose() * b / (cos_incidence * cos_incidence);
      if (!origins.empty()) j.head<2>() += origins[k].transpose() * b / cos_incidence;
      j(2) = 1.0 / cos_incidence;
      *normal_matrix += j.transpose() * j;
      *gradient += j.transpose() * e;
      *sum_sq += e * e;
      *sum_jacobian += j.transpose();
    }
    return true;
  }
};

}  // namespace

std::optional<LidarPlaneFit> FitPlaneRangeMl(const LidarCloud& cloud,
                                             const std::vector<int>& indices,
                                             const Plane& initial) {
  if (indices.size() < 4) return std::nullopt;
  RangeResiduals residuals;
  residuals.rays.reserve(indices.size());
  residuals.ranges.reserve(indices.size());
  if (cloud.HasViewpoint()) residuals.origins.reserve(indices.size());
  for (int i : indices) {
    const Vec3 origin = cloud.RayOrigin(i);
    const Vec3 ray = cloud.points[i].cast<double>() - origin;
    const double r = ray.norm();
    if (r <= 0) return std::nullopt;
    residuals.rays.push_back(ray / r);
    residuals.ranges.push_back(r);
    if (cloud.HasViewpoint()) residuals.origins.push_back(origin);
  }
  Plane plane = OrientTowardsOrigin(initial);
  Mat3 normal_matrix;
  Vec3 gradient, sum_jacobian;  // Σ ∂e_i/∂θ at the last linearisation
  double sum_sq = 0.0;
  bool converged = false;
  for (int iteration = 0; iteration < 20 && !converged; ++iteration) {
    if (!residuals.Linearize(plane, &normal_matrix, &gradient, &sum_sq, &sum_jacobian))
      return std::nullopt;
    const Vec3 step = normal_matrix.ldlt().solve(-gradient);
    if (!step.allFinite()) return std::nullopt;
    plane.normal = (plane.normal + PlaneTangentBasis(plane.normal) * step.head<2>()).normalized();
    plane.distance += step(2);
    converged = step.norm() < 1e-12;
  }
  if (!converged || !residuals.Linearize(plane, &normal_matrix, &gradient, &sum_sq, &sum_jacobian))
    return std::nullopt;
  LidarPlaneFit fit;
  fit.plane = OrientTowardsOrigin(plane);
  fit.inliers = indices;
  fit.inlier_centroid = Vec3::Zero();
  for (int i : indices) fit.inlier_centroid += cloud.points[i].cast<double>();
  fit.inlier_centroid /= static_cast<double>(indices.size());
  fit.num_candidates = static_cast<int>(indices.size());
  fit.rms_m = std::sqrt(sum_sq / indices.size());
  for (size_t k = 0; k < residuals.rays.size(); ++k) {
    // z = r² tan² α (core/target/lidar_noise.h): how far an angular jitter moves the range.
    const double cos_incidence = plane.normal.dot(residuals.rays[k]);
    const double r = residuals.ranges[k];
    const double tan2 = (1.0 - cos_incidence * cos_incidence) / (cos_incidence * cos_incidence);
    const double distance = residuals.DistanceFrom(plane, k);
    fit.range_moments.Add(r * r * tan2, r + distance / cos_incidence);
  }
  const double dof = std::max<double>(1.0, static_cast<double>(indices.size()) - 3.0);
  fit.covariance = TangentToPlaneCovariance((sum_sq / dof) * normal_matrix.inverse(), plane.normal);
  // A range offset b adds b to every residual; the Gauss-Newton solution then moves by
  // −(JᵀJ)⁻¹ Jᵀ 1 per metre of b.
  fit.range_offset_jacobian =
      TangentToPlaneCoefficients(plane.normal) * (-normal_matrix.ldlt().solve(sum_jacobian));
  return fit;
}

}  // namespace calibench
