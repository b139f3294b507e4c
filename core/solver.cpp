#include "core/solver.h"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace calibench {

std::string SolverMethodName(SolverMethod method) {
  switch (method) {
    case SolverMethod::kCa2libGn:
      return "ca2lib-gn";
    case SolverMethod::kWeightedMl:
      return "weighted-ml";
    case SolverMethod::kKim:
      return "kim";
  }
  return "unknown";
}

std::optional<SolverMethod> ParseSolverMethod(const std::string& name) {
  if (name == "ca2lib-gn") return SolverMethod::kCa2libGn;
  if (name == "weighted-ml") return SolverMethod::kWeightedMl;
  if (name == "kim") return SolverMethod::kKim;
  return std::nullopt;
}

bool SolverOptions::Check(std::string* why) const {
  auto fail = [&](const std::string& message) {
    if (why) *why = message;
    return false;
  };
  if (!(huber_delta > 0)) return fail("huber_delta must be > 0");
  if (!(whitened_huber_delta > 0)) return fail("whitened_huber_delta must be > 0 (sigmas)");
  if (max_iterations < 1) return fail("max_iterations must be >= 1");
  if (!(step_tolerance > 0)) return fail("step_tolerance must be > 0");
  if (!(outlier_gate == 0 || outlier_gate >= 2))
    return fail("outlier_gate must be 0 (off) or at least 2 robust scales");
  if (!(weak_eigenvalue_ratio > 0 && weak_eigenvalue_ratio < 1))
    return fail("weak_eigenvalue_ratio must be in (0, 1)");
  return true;
}

namespace {

// The weighted method's minimal residual for one pair at cam_from_lidar (3-vector):
//   r = [ B_cᵀ (n' − n_c) ; d' − d_c ],  (n', d') = TransformPlane(cam_from_lidar, lidar plane),
// B_c an orthonormal basis of the camera normal's tangent plane (the normals' two free
// directions; Eq. (6)'s 4-vector has a rank-3 covariance). Its covariance propagates both
// planes' covariances; the Jacobian is w.r.t. the right perturbation [rho; phi].
struct WeightedResidual {
  Vec3 residual;
  Eigen::Matrix<double, 3, 6> jacobian;
  Mat3 covariance;
};

WeightedResidual ComputeWeightedResidual(const Pose& cam_from_lidar, const PlanePair& pair) {
  const Mat3& r = cam_from_lidar.linear();
  const Vec3& t = cam_from_lidar.translation();
  const Plane moved = TransformPlane(cam_from_lidar, pair.lidar_plane);
  const Vec3& n_c = pair.camera_plane.normal;
  Eigen::Matrix<double, 3, 2> basis;
  basis.col(0) = n_c.unitOrthogonal();
  basis.col(1) = n_c.cross(basis.col(0));
  WeightedResidual out;
  out.residual.head<2>() = basis.transpose() * (moved.normal - n_c);
  out.residual[2] = moved.distance - pair.camera_plane.distance;
  // d/d(delta), as in PlaneAlignmentResidual: dn'/dphi = −R[n]x, dd'/drho = −nᵀ, dd'/dphi =
  // tᵀR[n]x.
  const Mat3 r_skew_n = r * Skew(pair.lidar_plane.normal);
  out.jacobian.setZero();
  out.jacobian.block<2, 3>(0, 3) = -basis.transpose() * r_skew_n;
  out.jacobian.block<1, 3>(2, 0) = -pair.lidar_plane.normal.transpose();
  out.jacobian.block<1, 3>(2, 3) = t.transpose() * r_skew_n;
  // d r / d(n_l, d_l) and d r / d(n_c, d_c).
  Eigen::Matrix<double, 3, 4> d_lidar = Eigen::Matrix<double, 3, 4>::Zero();
  d_lidar.block<2, 3>(0, 0) = basis.transpose() * r;
  d_lidar.block<1, 3>(2, 0) = -t.transpose() * r;
  d_lidar(2, 3) = 1.0;
  Eigen::Matrix<double, 3, 4> d_camera = Eigen::Matrix<double, 3, 4>::Zero();
  d_camera.block<2, 3>(0, 0) = -basis.transpose();
  d_camera(2, 3) = -1.0;
  out.covariance = d_lidar * pair.lidar_covariance * d_lidar.transpose() +
                   d_camera * pair.camera_covariance * d_camera.transpose();
  // Floor: 1e-5 rad and 0.1 mm, so that a pair with an unknown (zero) covariance stays finite.
  out.covariance.diagonal() += Vec3(1e-10, 1e-10, 1e-8);
  return out;
}

}  // namespace

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
  gated_.assign(pairs_.size(), 0);
  iteration_budget_ = options_.max_iterations;
  history_.push_back({0, Linearize(cam_from_lidar_).cost, 0.0, cam_from_lidar_});
  // Kim et al.'s estimate is the closed form itself: nothing to iterate.
  if (options_.method == SolverMethod::kKim) done_ = converged_ = true;
}

double PlaneAlignmentSolver::HuberDelta() const {
  return options_.method == SolverMethod::kWeightedMl ? options_.whitened_huber_delta
                                                      : options_.huber_delta;
}

double PlaneAlignmentSolver::RobustWeight(double error_norm) const {
  const double delta = HuberDelta();
  return error_norm <= delta ? 1.0 : delta / error_norm;
}

double PlaneAlignmentSolver::RobustCost(double error_norm) const {
  const double delta = HuberDelta();
  return error_norm <= delta ? 0.5 * error_norm * error_norm : delta * (error_norm - 0.5 * delta);
}

PlaneAlignmentSolver::Linearization PlaneAlignmentSolver::Linearize(
    const Pose& cam_from_lidar) const {
  Linearization lin;
  if (options_.method == SolverMethod::kWeightedMl) {
    for (size_t i = 0; i < pairs_.size(); ++i) {
      if (gated_[i]) continue;
      const WeightedResidual w = ComputeWeightedResidual(cam_from_lidar, pairs_[i]);
      const Mat3 information = w.covariance.inverse();
      const double mahalanobis = std::sqrt(w.residual.dot(information * w.residual));
      const double weight = RobustWeight(mahalanobis);
      lin.information += weight * w.jacobian.transpose() * information * w.jacobian;
      lin.gradient += weight * w.jacobian.transpose() * information * w.residual;
      lin.cost += RobustCost(mahalanobis);
      lin.weighted_squared_error += weight * mahalanobis * mahalanobis;
    }
    return lin;
  }
  Eigen::Matrix<double, 4, 6> jacobian;
  for (const PlanePair& pair : pairs_) {
    const Vec4 e =
        PlaneAlignmentResidual(cam_from_lidar, pair.lidar_plane, pair.camera_plane, &jacobian);
    const double norm = e.norm();
    const double w = RobustWeight(norm);  // Eq. (14) by iteratively reweighted least squares
    lin.information += w * jacobian.transpose() * jacobian;
    lin.gradient += w * jacobian.transpose() * e;
    lin.cost += RobustCost(norm);
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
  done_ = converged_ || static_cast<int>(history_.size()) > iteration_budget_;
  if (done_ && GateOutliers()) {
    // Continue from here without the gated pairs, with a fresh iteration budget; costs before
    // and after are not comparable.
    history_.back().cost = Linearize(cam_from_lidar_).cost;
    done_ = converged_ = false;
    iteration_budget_ = static_cast<int>(history_.size()) + options_.max_iterations;
  }
  return !done_;
}

bool PlaneAlignmentSolver::GateOutliers() {
  // Up to three rounds, each judged afresh at the current estimate: a gross outlier drags the
  // first estimate, so good pairs may look bad until it is gone, and come back then.
  if (gating_rounds_ >= 3 || options_.method != SolverMethod::kWeightedMl ||
      options_.outlier_gate <= 0)
    return false;
  ++gating_rounds_;
  std::vector<double> norms;
  for (const PlanePair& pair : pairs_) {
    const WeightedResidual w = ComputeWeightedResidual(cam_from_lidar_, pair);
    norms.push_back(std::sqrt(w.residual.dot(w.covariance.inverse() * w.residual)));
  }
  std::vector<double> sorted = norms;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  // The median of a χ(3) variable is 1.538.
  const double scale = std::max(1.0, sorted[sorted.size() / 2] / 1.538);
  // Only the worst pair beyond the gate goes per round: it is the one most likely to be the
  // cause of the others' residuals.
  std::vector<char> gated = gated_;
  for (size_t i = 0; i < pairs_.size(); ++i)
    if (gated[i] && norms[i] <= options_.outlier_gate * scale) gated[i] = 0;  // back in
  int worst = -1;
  for (size_t i = 0; i < pairs_.size(); ++i)
    if (!gated[i] && norms[i] > options_.outlier_gate * scale &&
        (worst < 0 || norms[i] > norms[worst]))
      worst = static_cast<int>(i);
  if (worst >= 0) gated[worst] = 1;
  // Never gate so much that the problem loses its redundancy.
  if (std::count(gated.begin(), gated.end(), 0) < 3) return false;
  const bool changed = gated != gated_;
  gated_ = gated;
  return changed;
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

Mat6 WeightedPlaneInformation(const std::vector<PlanePair>& pairs, const Pose& cam_from_lidar) {
  Mat6 information = Mat6::Zero();
  for (const PlanePair& pair : pairs) {
    const WeightedResidual w = ComputeWeightedResidual(cam_from_lidar, pair);
    information += w.jacobian.transpose() * w.covariance.inverse() * w.jacobian;
  }
  return information;
}

SolverResult PlaneAlignmentSolver::Summarize() const {
  SolverResult result;
  result.cam_from_lidar = cam_from_lidar_;
  result.converged = converged_;
  result.iterations = static_cast<int>(history_.size()) - 1;
  for (const IterationReport& it : history_) result.cost_history.push_back(it.cost);
  const bool weighted = options_.method == SolverMethod::kWeightedMl;
  for (const PlanePair& pair : pairs_) {
    const Vec4 e =
        PlaneAlignmentResidual(cam_from_lidar_, pair.lidar_plane, pair.camera_plane, nullptr);
    result.residuals.push_back(e);
    if (weighted) {
      const WeightedResidual w = ComputeWeightedResidual(cam_from_lidar_, pair);
      const bool gated = gated_[&pair - pairs_.data()];
      result.robust_weights.push_back(
          gated ? 0.0
                : RobustWeight(std::sqrt(w.residual.dot(w.covariance.inverse() * w.residual))));
    } else {
      result.robust_weights.push_back(RobustWeight(e.norm()));
    }
  }
  const Linearization lin = Linearize(cam_from_lidar_);
  // The inverse information scaled by the a-posteriori variance factor: for the paper's residual,
  // which has no noise model, that is the noise estimate itself (4 residuals per pair); for the
  // weighted residual (3 per pair) it absorbs what the feature covariances miss on real sensors.
  const int per_pair = weighted ? 3 : 4;
  const int used_pairs = static_cast<int>(pairs_.size()) -
                         static_cast<int>(std::count(gated_.begin(), gated_.end(), 1));
  const int redundancy = per_pair * used_pairs - 6;
  const double variance_factor = redundancy > 0 ? lin.weighted_squared_error / redundancy : 0.0;
  Eigen::SelfAdjointEigenSolver<Mat6> eigen(lin.information);
  Vec6 inverse_eigenvalues;
  for (int i = 0; i < 6; ++i) {
    const double lambda = eigen.eigenvalues()[i];
    inverse_eigenvalues[i] = lambda > 1e-12 * eigen.eigenvalues()[5] ? 1.0 / lambda : 1e12;
  }
  result.covariance = variance_factor * eigen.eigenvectors() * inverse_eigenvalues.asDiagonal() *
                      eigen.eigenvectors().transpose();
  // Observability is a property of the geometry, not of the noise: judge it on the unweighted
  // plane-to-plane information (Eq. (6) Jacobians, unit weights), whose eigenvalues compare like
  // with like for either method; whitened information mixes 1/m² and 1/rad² scales.
  Mat6 geometric_information = Mat6::Zero();
  Eigen::Matrix<double, 4, 6> jacobian;
  for (const PlanePair& pair : pairs_) {
    PlaneAlignmentResidual(cam_from_lidar_, pair.lidar_plane, pair.camera_plane, &jacobian);
    geometric_information += jacobian.transpose() * jacobian;
  }
  result.observability =
      AnalyseObservability(geometric_information, cam_from_lidar_, options_.weak_eigenvalue_ratio);
  if (redundancy <= 0) {
    result.observability.well_constrained = false;
    result.observability.weak_directions.push_back(
        "fewer than 2 redundant residuals: at least 2 pairs are needed, 3 for all six degrees of "
        "freedom");
  }
  return result;
}

}  // namespace calibench
