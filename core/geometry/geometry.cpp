#include "core/geometry/geometry.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace calibench {
namespace {
constexpr double kSmallAngle = 1e-8;
}  // namespace

Mat3 Skew(const Vec3& v) {
  Mat3 m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

Mat3 ExpSO3(const Vec3& phi) {
  const double theta = phi.norm();
  const Mat3 k = Skew(phi);
  if (theta < kSmallAngle) return Mat3::Identity() + k + 0.5 * k * k;
  return Mat3::Identity() + std::sin(theta) / theta * k +
         (1.0 - std::cos(theta)) / (theta * theta) * k * k;
}

Vec3 LogSO3(const Mat3& rotation) {
  const Eigen::AngleAxisd aa(rotation);
  Vec3 phi = aa.angle() * aa.axis();
  if (!phi.allFinite()) phi.setZero();
  return phi;
}

Mat3 LeftJacobianSO3(const Vec3& phi) {
  const double theta = phi.norm();
  const Mat3 k = Skew(phi);
  if (theta < kSmallAngle) return Mat3::Identity() + 0.5 * k + k * k / 6.0;
  const double t2 = theta * theta;
  return Mat3::Identity() + (1.0 - std::cos(theta)) / t2 * k +
         (theta - std::sin(theta)) / (t2 * theta) * k * k;
}

Mat3 LeftJacobianInverseSO3(const Vec3& phi) {
  const double theta = phi.norm();
  const Mat3 k = Skew(phi);
  if (theta < kSmallAngle) return Mat3::Identity() - 0.5 * k + k * k / 12.0;
  const double half = 0.5 * theta;
  const double cot_term = (1.0 - half * std::cos(half) / std::sin(half)) / (theta * theta);
  return Mat3::Identity() - 0.5 * k + cot_term * k * k;
}

Pose ExpSE3(const Vec6& xi) {
  const Vec3 rho = xi.head<3>();
  const Vec3 phi = xi.tail<3>();
  Pose pose = Pose::Identity();
  pose.linear() = ExpSO3(phi);
  pose.translation() = LeftJacobianSO3(phi) * rho;
  return pose;
}

Vec6 LogSE3(const Pose& pose) {
  const Vec3 phi = LogSO3(pose.linear());
  Vec6 xi;
  xi.head<3>() = LeftJacobianInverseSO3(phi) * pose.translation();
  xi.tail<3>() = phi;
  return xi;
}

Mat6 AdjointSE3(const Pose& pose) {
  const Mat3 r = pose.linear();
  Mat6 adj = Mat6::Zero();
  adj.topLeftCorner<3, 3>() = r;
  adj.topRightCorner<3, 3>() = Skew(pose.translation()) * r;
  adj.bottomRightCorner<3, 3>() = r;
  return adj;
}

Plane TransformPlane(const Pose& b_from_a, const Plane& plane_in_a) {
  Plane out;
  out.normal = b_from_a.linear() * plane_in_a.normal;
  out.distance = plane_in_a.distance - out.normal.dot(b_from_a.translation());
  return out;
}

std::optional<double> RangeOnPlane(const Plane& plane, const Vec3& point) {
  const double range = point.norm();
  if (!(range > 0)) return std::nullopt;
  const double cos_incidence = plane.normal.dot(point) / range;
  if (std::abs(cos_incidence) < 0.02) return std::nullopt;
  return -plane.distance / cos_incidence;
}

Plane OrientTowardsOrigin(const Plane& plane) {
  if (plane.distance >= 0) return plane;
  return Plane{-plane.normal, -plane.distance};
}

Eigen::Matrix<double, 3, 2> PlaneTangentBasis(const Vec3& normal) {
  Eigen::Matrix<double, 3, 2> basis;
  basis.col(0) = normal.unitOrthogonal();
  basis.col(1) = normal.cross(basis.col(0));
  return basis;
}

Eigen::Matrix<double, 4, 3> TangentToPlaneCoefficients(const Vec3& normal) {
  Eigen::Matrix<double, 4, 3> to_coefficients = Eigen::Matrix<double, 4, 3>::Zero();
  to_coefficients.topLeftCorner<3, 2>() = PlaneTangentBasis(normal);
  to_coefficients(3, 2) = 1.0;
  return to_coefficients;
}

Mat4 TangentToPlaneCovariance(const Mat3& tangent_covariance, const Vec3& normal) {
  const Eigen::Matrix<double, 4, 3> to_coefficients = TangentToPlaneCoefficients(normal);
  return to_coefficients * tangent_covariance * to_coefficients.transpose();
}

namespace {

// Point k of a plane fit's input is point_at(k): an Eigen 3-vector of doubles or an expression of
// one (single-precision LiDAR points cast on the fly); its weight is weight_at(k). Templates, so
// that each kind of input is evaluated as its own expressions.

// Σ = s² (Jᵀ W J)⁻¹ over the tangent-plane parameters (δ_n ∈ ℝ², δ_d) of fit->plane, mapped to
// (n, d) by n = n₀ + B δ_n; s² = Σ w r² / (N − 3). Also sets the unweighted RMS residual.
template <typename PointAt, typename WeightAt>
void SetPlaneCovariance(size_t count, const PointAt& point_at, const WeightAt& weight_at,
                        PlaneFit* fit) {
  const Eigen::Matrix<double, 3, 2> tangent = PlaneTangentBasis(fit->plane.normal);
  Mat3 normal_matrix = Mat3::Zero();
  double weighted_sq = 0.0, sum_sq = 0.0;
  for (size_t k = 0; k < count; ++k) {
    const double r = fit->plane.SignedDistance(point_at(k));
    weighted_sq += weight_at(k) * r * r;
    sum_sq += r * r;
    Eigen::RowVector3d j;
    j << point_at(k).transpose() * tangent, 1.0;
    normal_matrix += weight_at(k) * j.transpose() * j;
  }
  fit->rms_m = std::sqrt(sum_sq / count);
  const double dof = std::max<double>(1.0, static_cast<double>(count) - 3.0);
  const Mat3 local_cov = (weighted_sq / dof) * normal_matrix.inverse();
  fit->covariance = TangentToPlaneCovariance(local_cov, fit->plane.normal);
}

// Weighted total least squares: the plane through the weighted centroid normal to the smallest
// eigenvector of the weighted scatter.
template <typename PointAt, typename WeightAt>
std::optional<Plane> TlsPlane(size_t count, const PointAt& point_at, const WeightAt& weight_at) {
  if (count < 4) return std::nullopt;
  double weight_sum = 0.0;
  Vec3 centroid = Vec3::Zero();
  for (size_t k = 0; k < count; ++k) {
    weight_sum += weight_at(k);
    centroid += weight_at(k) * point_at(k);
  }
  centroid /= weight_sum;
  Mat3 scatter = Mat3::Zero();
  for (size_t k = 0; k < count; ++k) {
    const Vec3 p = point_at(k) - centroid;
    scatter += weight_at(k) * p * p.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Mat3> eigen(scatter);
  // Points on a line (e.g. a single LiDAR ring) leave two eigenvalues near zero.
  if (eigen.eigenvalues()[1] < 1e-6 * eigen.eigenvalues()[2] || eigen.eigenvalues()[1] <= 0)
    return std::nullopt;
  return OrientTowardsOrigin(
      Plane{eigen.eigenvectors().col(0), -eigen.eigenvectors().col(0).dot(centroid)});
}

template <typename PointAt, typename WeightAt>
std::optional<PlaneFit> FitPlaneTls(size_t count, const PointAt& point_at,
                                    const WeightAt& weight_at) {
  const std::optional<Plane> plane = TlsPlane(count, point_at, weight_at);
  if (!plane) return std::nullopt;
  PlaneFit fit;
  fit.plane = *plane;
  SetPlaneCovariance(count, point_at, weight_at, &fit);
  return fit;
}

}  // namespace

std::optional<PlaneFit> FitPlaneWeighted(const std::vector<Vec3>& points,
                                         const std::vector<double>& weights) {
  CALIBENCH_CHECK(weights.empty() || weights.size() == points.size());
  return FitPlaneTls(
      points.size(), [&](size_t k) -> const Vec3& { return points[k]; },
      [&](size_t k) { return weights.empty() ? 1.0 : weights[k]; });
}

std::optional<Plane> FitPlaneWeightedPlane(const std::vector<Vec3>& points,
                                           const std::vector<double>& weights) {
  CALIBENCH_CHECK(weights.empty() || weights.size() == points.size());
  return TlsPlane(
      points.size(), [&](size_t k) -> const Vec3& { return points[k]; },
      [&](size_t k) { return weights.empty() ? 1.0 : weights[k]; });
}

std::optional<PlaneFit> FitPlane(const std::vector<Eigen::Vector3f>& points,
                                 const std::vector<int>& indices) {
  return FitPlaneTls(
      indices.size(), [&](size_t k) { return points[indices[k]].cast<double>(); },
      [](size_t) { return 1.0; });
}

Vec4 PlaneToPlaneError(const Plane& plane_i, const Plane& plane_j) {
  Vec4 e;
  e.head<3>() = plane_i.normal - plane_j.normal;
  e[3] = plane_j.normal.dot(plane_j.ClosestPointToOrigin() - plane_i.ClosestPointToOrigin());
  return e;
}

Vec4 PlaneAlignmentResidual(const Pose& cam_from_lidar, const Plane& lidar_plane,
                            const Plane& camera_plane, Eigen::Matrix<double, 4, 6>* jacobian) {
  const Plane moved = TransformPlane(cam_from_lidar, lidar_plane);
  const Vec4 error = PlaneToPlaneError(moved, camera_plane);
  if (jacobian) {
    // Right perturbation X·Exp([rho; phi]) moves the LiDAR plane first:
    //   n1 = Exp(phi) n ≈ n − [n]x phi,  d1 = d − n1·(J_l(phi) rho) ≈ d − n·rho,
    // then X: n' = R n1, d' = d1 − n'·t. Hence
    //   dn'/drho = 0, dn'/dphi = −R [n]x, dd'/drho = −nᵀ, dd'/dphi = tᵀ R [n]x.
    const Mat3& rotation = cam_from_lidar.linear();
    const Vec3& t = cam_from_lidar.translation();
    const Mat3 r_skew_n = rotation * Skew(lidar_plane.normal);
    Eigen::Matrix<double, 4, 6> d_plane;  // d(n', d')/d(delta)
    d_plane.setZero();
    d_plane.block<3, 3>(0, 3) = -r_skew_n;
    d_plane.block<1, 3>(3, 0) = -lidar_plane.normal.transpose();
    d_plane.block<1, 3>(3, 3) = t.transpose() * r_skew_n;
    // Eq. (6) with pi_i = moved, pi_j = camera: e_n = n' − n_c,
    // e_d = n_c·(−n_c d_c + n' d') = d' (n_c·n') − d_c.
    Eigen::Matrix<double, 4, 4> d_error;  // d(e)/d(n', d')
    d_error.setZero();
    d_error.topLeftCorner<3, 3>().setIdentity();
    d_error.block<1, 3>(3, 0) = moved.distance * camera_plane.normal.transpose();
    d_error(3, 3) = camera_plane.normal.dot(moved.normal);
    *jacobian = d_error * d_plane;
  }
  return error;
}

double RotationAngle(const Mat3& a, const Mat3& b) { return LogSO3(a.transpose() * b).norm(); }

Mat3 NearestRotation(const Mat3& m) {
  Eigen::JacobiSVD<Mat3> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 d = Mat3::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

PoseError ComputePoseError(const Pose& estimate, const Pose& reference) {
  return {(estimate.translation() - reference.translation()).norm(),
          RotationAngle(estimate.linear(), reference.linear())};
}

}  // namespace calibench
