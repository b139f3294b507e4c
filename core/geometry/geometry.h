// SE(3) exponential/logarithm (right perturbation), planes and the plane-to-plane error of
// Ca²Lib (Eq. (5)–(6)) with its analytic Jacobian.
//
// Tangent-space order for 6-vectors is [rho (translation, m); phi (rotation, rad)].
// Perturbations are applied on the right: T · Exp(delta).
#pragma once

#include <optional>
#include <vector>

#include "core/base/types.h"

namespace calibench {

// [v]_x, so that Skew(a) * b = a.cross(b).
Mat3 Skew(const Vec3& v);

// Rodrigues' formula; phi is an axis-angle vector in radians.
Mat3 ExpSO3(const Vec3& phi);
// Inverse of ExpSO3, |result| in [0, pi].
Vec3 LogSO3(const Mat3& rotation);
// Left Jacobian of SO(3), the V matrix of SE(3) exp: Exp([rho;phi]).t = LeftJacobianSO3(phi)*rho.
Mat3 LeftJacobianSO3(const Vec3& phi);
Mat3 LeftJacobianInverseSO3(const Vec3& phi);

// Exp: se(3) -> SE(3), xi = [rho; phi].
Pose ExpSE3(const Vec6& xi);
// Log: SE(3) -> se(3), returns [rho; phi].
Vec6 LogSE3(const Pose& pose);
// Adjoint of SE(3) in [rho; phi] order: Exp(Ad(T) xi) = T Exp(xi) T^-1.
Mat6 AdjointSE3(const Pose& pose);

// A plane pi = (n, d), |n| = 1; points x on it satisfy n·x + d = 0 (metres).
struct Plane {
  Vec3 normal = Vec3::UnitZ();
  double distance = 0.0;

  Vec4 Coefficients() const { return Vec4(normal.x(), normal.y(), normal.z(), distance); }
  static Plane FromCoefficients(const Vec4& c) { return Plane{c.head<3>(), c[3]}; }
  // Signed distance of a point to the plane (metres), positive on the side the normal points to.
  double SignedDistance(const Vec3& x) const { return normal.dot(x) + distance; }
  // Eq. (5): the point of the plane closest to the origin, p = -n d.
  Vec3 ClosestPointToOrigin() const { return -normal * distance; }
};

// Plane expressed in frame b, given b_from_a and the plane in frame a:
// n_b = R n_a, d_b = d_a - n_b·t (docs/architecture.md, "Conventions and file contracts").
Plane TransformPlane(const Pose& b_from_a, const Plane& plane_in_a);

// Flips (n, d) so that the normal points towards the origin of its frame (d > 0): the convention of
// orientation of board planes in both sensor frames (docs/architecture.md, "Conventions and file
// contracts").
Plane OrientTowardsOrigin(const Plane& plane);

// The range at which the ray from the frame's origin through `point` meets the plane, r̂ =
// −d / (n·u) with u the ray's unit direction; nullopt at the origin and for rays within ~1° of
// the plane (|n·u| < 0.02), whose range is unbounded.
std::optional<double> RangeOnPlane(const Plane& plane, const Vec3& point);

// A plane normal's two degrees of freedom: n = n₀ + B δ, δ ∈ ℝ², B = PlaneTangentBasis(n₀)
// (orthonormal, perpendicular to n₀).
Eigen::Matrix<double, 3, 2> PlaneTangentBasis(const Vec3& normal);
// A covariance over the tangent parameters (δ, δ_d) mapped to the plane's (n, d) coefficients.
Mat4 TangentToPlaneCovariance(const Mat3& tangent_covariance, const Vec3& normal);
// The map itself: (n, d) = J (δ, δ_d), a 4×3 matrix.
Eigen::Matrix<double, 4, 3> TangentToPlaneCoefficients(const Vec3& normal);

// A total-least-squares plane with the covariance of its coefficients.
struct PlaneFit {
  Plane plane;                     // normal towards the frame's origin (d > 0)
  Mat4 covariance = Mat4::Zero();  // of (n, d); rank 3 (n moves in its tangent plane only)
  double rms_m = 0.0;              // unweighted RMS point-to-plane distance (metres)
};

// Weighted total least squares through `points` (metres, any frame) with weights w_i (empty: all
// 1), and the (n, d) covariance: residual r_i = n·x_i + d with n perturbed in its tangent plane
// (basis B), J_i = [x_iᵀ B, 1], Σ = s² (Jᵀ W J)⁻¹ with s² = Σ w r² / (N − 3) from the residuals.
// nullopt for fewer than 4 points, or points on a line (they do not define a plane).
std::optional<PlaneFit> FitPlaneWeighted(const std::vector<Vec3>& points,
                                         const std::vector<double>& weights = {});
// Its plane alone (bit for bit), without the covariance's pass over the points: for iterations that
// only need the plane.
std::optional<Plane> FitPlaneWeightedPlane(const std::vector<Vec3>& points,
                                           const std::vector<double>& weights = {});
// The same, unweighted, over points[indices] of single-precision points (a LiDAR cloud's).
std::optional<PlaneFit> FitPlane(const std::vector<Eigen::Vector3f>& points,
                                 const std::vector<int>& indices);

// Eq. (6): e = [n_i - n_j ; n_j·(p(pi_j) - p(pi_i))], 4-vector, first three unitless, last metres.
Vec4 PlaneToPlaneError(const Plane& plane_i, const Plane& plane_j);

// Residual of one correspondence for the estimate cam_from_lidar:
// e = PlaneToPlaneError(TransformPlane(cam_from_lidar, lidar_plane), camera_plane),
// and, if jacobian != nullptr, de/d(delta) for the right perturbation cam_from_lidar·Exp(delta)
// (4x6, [rho; phi] columns). This is our convention's counterpart of the paper's Eq. (3).
Vec4 PlaneAlignmentResidual(const Pose& cam_from_lidar, const Plane& lidar_plane,
                            const Plane& camera_plane, Eigen::Matrix<double, 4, 6>* jacobian);

// Rotation angle between two rotations (radians) and translation distance (metres).
double RotationAngle(const Mat3& a, const Mat3& b);

// The nearest rotation matrix (Frobenius) to an arbitrary 3x3 matrix, det = +1.
Mat3 NearestRotation(const Mat3& m);

// Translation (metres) and rotation (radians) error of an estimate against a reference.
struct PoseError {
  double translation_m = 0.0;
  double rotation_rad = 0.0;
};
PoseError ComputePoseError(const Pose& estimate, const Pose& reference);

}  // namespace calibench
