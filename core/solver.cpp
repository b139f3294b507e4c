#include "core/solver.h"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace calibench {

bool SolverOptions::Check(std::string* why) const {
  auto fail = [&](const std::string& message) {
    if (why) *why = message;
    return false;
  };
  if (!(huber_delta > 0)) return fail("huber_delta must be > 0");
  if (max_iterations < 1) return fail("max_iterations must be >= 1");
  if (!(step_tolerance > 0)) return fail("step_tolerance must be > 0");
  if (!(weak_eigenvalue_ratio > 0 && weak_eigenvalue_ratio < 1))
    return fail("weak_eigenvalue_ratio must be in (0, 1)");
  return true;
}

std::optional<Pose> InitialGuessFromPlanes(const std::vector<PlanePair>& pairs, std::string* why) {
  if (pairs.size() < 2) {
    if (why)
      *why =
          "need at least 2 plane pairs for an initial guess, got " + std::to_string(pairs.size());
    return std::nullopt;
  }
  // Rotation: argmax sum n_c · R n_l (Kabsch on the normals).
  Mat3 correlation = Mat3::Zero();
  for (const PlanePair& p : pairs)
    correlation += p.camera_plane.normal * p.lidar_plane.normal.transpose();
  Eigen::JacobiSVD<Mat3> svd(correlation, Eigen::ComputeFullU | Eigen::ComputeFullV);
  if (svd.singularValues()[1] < 1e-6 * svd.singularValues()[0]) {
    if (why) *why = "all board normals are parallel: the rotation is not determined";
    return std::nullopt;
  }
  Pose cam_from_lidar = Pose::Identity();
  cam_from_lidar.linear() = NearestRotation(correlation);
  // Translation: d_c = d_l − n_c·t  =>  n_cᵀ t = d_l − d_c.
  Eigen::MatrixXd a(pairs.size(), 3);
  Eigen::VectorXd b(pairs.size());
  for (size_t i = 0; i < pairs.size(); ++i) {
    a.row(i) = pairs[i].camera_plane.normal.transpose();
    b[i] = pairs[i].lidar_plane.distance - pairs[i].camera_plane.distance;
  }
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(a);
  cod.setThreshold(1e-3);  // minimum-norm along directions the normals do not span
  cam_from_lidar.translation() = cod.solve(b);
  return cam_from_lidar;
}

ObservabilityReport AnalyseObservability(const Mat6& information, const Pose& cam_from_lidar,
                                         double weak_eigenvalue_ratio) {
  ObservabilityReport report;
  Eigen::SelfAdjointEigenSolver<Mat6> eigen(information);
  report.eigenvalues = eigen.eigenvalues();
  const double largest = std::max(report.eigenvalues[5], 1e-300);
  int num_weak = 0;
  while (num_weak < 6 && report.eigenvalues[num_weak] < weak_eigenvalue_ratio * largest) ++num_weak;
  if (num_weak == 0) {
    report.well_constrained = true;
    return report;
  }
  // Weak eigenvalues are often (nearly) repeated, so single eigenvectors are arbitrary mixtures.
  // Name instead each camera-frame axis motion that lies mostly inside the weak subspace; the
  // perturbation acts on the right, so a camera-frame direction a is rho (or phi) = Rᵀ a.
  const Eigen::MatrixXd weak_basis = eigen.eigenvectors().leftCols(num_weak);
  const Mat3& rotation = cam_from_lidar.linear();
  static const char* kAxisNames[3] = {"x (right)", "y (down)", "z (forward)"};
  for (int kind = 0; kind < 2; ++kind) {
    for (int axis = 0; axis < 3; ++axis) {
      Vec6 motion = Vec6::Zero();
      motion.segment<3>(3 * kind) = rotation.transpose() * Vec3::Unit(axis);
      if ((weak_basis.transpose() * motion).squaredNorm() < 0.5) continue;
      report.weak_directions.push_back(
          std::string(kind == 0 ? "translation along camera " : "rotation about camera ") +
          kAxisNames[axis] + (kind == 1 ? " through the LiDAR origin" : ""));
    }
  }
  for (int i = 0; i < num_weak && report.weak_directions.size() < static_cast<size_t>(num_weak);
       ++i) {
    // A weak direction that is no single axis: describe the eigenvector itself.
    const Vec6 v = eigen.eigenvectors().col(i);
    const Vec3 t = rotation * v.head<3>();
    const Vec3 r = rotation * v.tail<3>();
    char text[160];
    std::snprintf(text, sizeof(text),
                  "combined motion: translation [%.2f, %.2f, %.2f] with rotation [%.2f, %.2f, "
                  "%.2f] (camera frame, eigenvalue ratio %.1e)",
                  t.x(), t.y(), t.z(), r.x(), r.y(), r.z(), report.eigenvalues[i] / largest);
    report.weak_directions.push_back(text);
  }
  report.well_constrained = false;
  return report;
}

PlaneAlignmentSolver::PlaneAlignmentSolver(std::vector<PlanePair> pairs,
                                           const SolverOptions& options,
                                           const Pose& initial_cam_from_lidar)
    : pairs_(std::move(pairs)), options_(options), cam_from_lidar_(initial_cam_from_lidar) {
  std::string why;
  CALIBENCH_CHECK(options_.Check(&why));
  CALIBENCH_CHECK(!pairs_.empty());
  history_.push_back({0, Linearize(cam_from_lidar_).cost, 0.0, cam_from_lidar_});
}

double PlaneAlignmentSolver::HuberWeight(double error_norm) const {
  return error_norm <= options_.huber_delta ? 1.0 : options_.huber_delta / error_norm;
}

double PlaneAlignmentSolver::HuberCost(double error_norm) const {
  const double delta = options_.huber_delta;
  return error_norm <= delta ? 0.5 * error_norm * error_norm : delta * (error_norm - 0.5 * delta);
}

PlaneAlignmentSolver::Linearization PlaneAlignmentSolver::Linearize(
    const Pose& cam_from_lidar) const {
  Linearization lin;
  Eigen::Matrix<double, 4, 6> jacobian;
  for (const PlanePair& pair : pairs_) {
    const Vec4 e =
        PlaneAlignmentResidual(cam_from_lidar, pair.lidar_plane, pair.camera_plane, &jacobian);
    const double norm = e.norm();
    const double w = HuberWeight(norm);  // Eq. (14) by iteratively reweighted least squares
    lin.information += w * jacobian.transpose() * jacobian;
    lin.gradient += w * jacobian.transpose() * e;
    lin.cost += HuberCost(norm);
    lin.weighted_squared_error += w * e.squaredNorm();
  }
  return lin;
}

bool PlaneAlignmentSolver::Step() {
  if (done_) return false;
  const Linearization lin = Linearize(cam_from_lidar_);
  // Normal equations of Eq. (13)–(14); an LDLT with a tiny damping keeps rank-deficient
  // (degenerate) problems finite: unobservable directions then simply do not move.
  Mat6 damped = lin.information;
  damped.diagonal().array() += 1e-12 * std::max(1.0, lin.information.diagonal().maxCoeff());
  Vec6 delta = -damped.ldlt().solve(lin.gradient);
  Pose candidate = cam_from_lidar_ * ExpSE3(delta);
  double cost = Linearize(candidate).cost;
  // Backtracking keeps Gauss-Newton monotone far from the solution (robust weights change).
  for (int halvings = 0; cost > lin.cost && halvings < 10; ++halvings) {
    delta *= 0.5;
    candidate = cam_from_lidar_ * ExpSE3(delta);
    cost = Linearize(candidate).cost;
  }
  if (cost <= lin.cost) cam_from_lidar_ = candidate;
  const double step_norm = cost <= lin.cost ? delta.norm() : 0.0;
  history_.push_back(
      {static_cast<int>(history_.size()), std::min(cost, lin.cost), step_norm, cam_from_lidar_});
  converged_ = step_norm < options_.step_tolerance ||
               (lin.cost - cost >= 0 && lin.cost - cost <= 1e-15 * std::max(1.0, lin.cost));
  done_ = converged_ || static_cast<int>(history_.size()) > options_.max_iterations;
  return !done_;
}

SolverResult PlaneAlignmentSolver::Run(
    const std::function<void(const IterationReport&)>& on_iteration) {
  if (on_iteration && history_.size() == 1) on_iteration(history_.front());
  while (Step()) {
    if (on_iteration) on_iteration(history_.back());
  }
  if (on_iteration && history_.size() > 1) on_iteration(history_.back());
  return Summarize();
}

SolverResult PlaneAlignmentSolver::Summarize() const {
  SolverResult result;
  result.cam_from_lidar = cam_from_lidar_;
  result.converged = converged_;
  result.iterations = static_cast<int>(history_.size()) - 1;
  for (const IterationReport& it : history_) result.cost_history.push_back(it.cost);
  for (const PlanePair& pair : pairs_) {
    const Vec4 e =
        PlaneAlignmentResidual(cam_from_lidar_, pair.lidar_plane, pair.camera_plane, nullptr);
    result.residuals.push_back(e);
    result.robust_weights.push_back(HuberWeight(e.norm()));
  }
  const Linearization lin = Linearize(cam_from_lidar_);
  // The paper's residual carries no noise model: scale the inverse information by the
  // a-posteriori variance factor of the 4 residuals per pair (6 parameters estimated).
  const int redundancy = 4 * static_cast<int>(pairs_.size()) - 6;
  const double variance_factor = redundancy > 0 ? lin.weighted_squared_error / redundancy : 0.0;
  Eigen::SelfAdjointEigenSolver<Mat6> eigen(lin.information);
  Vec6 inverse_eigenvalues;
  for (int i = 0; i < 6; ++i) {
    const double lambda = eigen.eigenvalues()[i];
    inverse_eigenvalues[i] = lambda > 1e-12 * eigen.eigenvalues()[5] ? 1.0 / lambda : 1e12;
  }
  result.covariance = variance_factor * eigen.eigenvectors() * inverse_eigenvalues.asDiagonal() *
                      eigen.eigenvectors().transpose();
  result.observability =
      AnalyseObservability(lin.information, cam_from_lidar_, options_.weak_eigenvalue_ratio);
  if (redundancy <= 0) {
    result.observability.well_constrained = false;
    result.observability.weak_directions.push_back(
        "fewer than 2 redundant residuals: at least 2 pairs are needed, 3 for all six degrees of "
        "freedom");
  }
  return result;
}

}  // namespace calibench
