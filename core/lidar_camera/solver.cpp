#include "core/lidar_camera/solver.h"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "core/base/names.h"

namespace calibench {

namespace {

constexpr EnumName<SolverMethod> kSolverMethodNames[] = {{SolverMethod::kCa2libGn, "ca2lib-gn"},
                                                         {SolverMethod::kWeightedMl, "weighted-ml"},
                                                         {SolverMethod::kKim, "kim"}};
}  // namespace

std::string SolverMethodName(SolverMethod method) { return NameIn(kSolverMethodNames, method); }

std::optional<SolverMethod> ParseSolverMethod(const std::string& name) {
  return ValueIn(kSolverMethodNames, name);
}

bool SolverOptions::Check(std::string* why) const {
  auto fail = [&](const std::string& message) {
    if (why) *why = message;
    return false;
  };
  if (!(huber_delta > 0)) return fail("huber_delta must be > 0");
  if (!(whitened_huber_delta > 0)) return fail("whitened_huber_delta must be > 0 (sigmas)");
  if (max_iterations < 1) return fail("max_iterations must be >= 1");
  if (!(negligible_weight >= 0 && negligible_weight < 1))
    return fail("negligible_weight must be in [0, 1)");
  if (!(function_tolerance > 0 && gradient_tolerance > 0 && parameter_tolerance > 0))
    return fail("function_tolerance, gradient_tolerance and parameter_tolerance must be > 0");
  if (!(outlier_gate == 0 || outlier_gate >= 2))
    return fail("outlier_gate must be 0 (off) or at least 2 robust scales");
  if (!(weak_eigenvalue_ratio > 0 && weak_eigenvalue_ratio < 1))
    return fail("weak_eigenvalue_ratio must be in (0, 1)");
  if (!(range_offset_max_sigma_m > 0)) return fail("range_offset_max_sigma_m must be > 0 (metres)");
  if (!(range_offset_significance > 0))
    return fail("range_offset_significance must be > 0 (standard deviations)");
  if (!(edge_floor_sigma_m > 0)) return fail("edge_floor_sigma_m must be > 0 (metres)");
  if (!(range_offset_prior_sigma_m >= 0))
    return fail("range_offset_prior_sigma_m must be >= 0 (metres; 0 = no prior)");
  if (estimate_range_offset && method != SolverMethod::kWeightedMl)
    return fail("a range offset is estimated by the weighted-ml method only, not by " +
                SolverMethodName(method));
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
  Vec3 offset_jacobian;  // d r / d(range offset)
  Mat3 covariance;
};

WeightedResidual ComputeWeightedResidual(const Pose& cam_from_lidar, const PlanePair& pair,
                                         double range_offset_m = 0.0) {
  const Mat3& r = cam_from_lidar.linear();
  const Vec3& t = cam_from_lidar.translation();
  const Plane lidar_plane = CorrectedLidarPlane(pair, range_offset_m);
  const Plane moved = TransformPlane(cam_from_lidar, lidar_plane);
  const Vec3& n_c = pair.camera_plane.normal;
  const Eigen::Matrix<double, 3, 2> basis = PlaneTangentBasis(n_c);
  WeightedResidual out;
  out.residual.head<2>() = basis.transpose() * (moved.normal - n_c);
  out.residual[2] = moved.distance - pair.camera_plane.distance;
  // d/d(delta), as in PlaneAlignmentResidual: dn'/dphi = −R[n]x, dd'/drho = −nᵀ, dd'/dphi =
  // tᵀR[n]x.
  const Mat3 r_skew_n = r * Skew(lidar_plane.normal);
  out.jacobian.setZero();
  out.jacobian.block<2, 3>(0, 3) = -basis.transpose() * r_skew_n;
  out.jacobian.block<1, 3>(2, 0) = -lidar_plane.normal.transpose();
  out.jacobian.block<1, 3>(2, 3) = t.transpose() * r_skew_n;
  // d r / d(n_l, d_l) and d r / d(n_c, d_c).
  Eigen::Matrix<double, 3, 4> d_lidar = Eigen::Matrix<double, 3, 4>::Zero();
  d_lidar.block<2, 3>(0, 0) = basis.transpose() * r;
  d_lidar.block<1, 3>(2, 0) = -t.transpose() * r;
  d_lidar(2, 3) = 1.0;
  out.offset_jacobian = -d_lidar * pair.lidar_range_offset_jacobian;
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

Plane CorrectedLidarPlane(const PlanePair& pair, double range_offset_m) {
  if (range_offset_m == 0.0) return pair.lidar_plane;
  const Vec4 c =
      pair.lidar_plane.Coefficients() - range_offset_m * pair.lidar_range_offset_jacobian;
  return Plane{c.head<3>().normalized(), c[3] / c.head<3>().norm()};
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

PlaneAlignmentSolver::PlaneAlignmentSolver(std::vector<PlanePair> pairs,
                                           const SolverOptions& options,
                                           const Pose& initial_cam_from_lidar,
                                           double initial_range_offset_m)
    : pairs_(std::move(pairs)),
      options_(options),
      cam_from_lidar_(initial_cam_from_lidar),
      range_offset_m_(initial_range_offset_m) {
  std::string why;
  CALIBENCH_CHECK(options_.Check(&why));
  CALIBENCH_CHECK(!pairs_.empty());
  gated_.assign(pairs_.size(), 0);
  iteration_budget_ = options_.max_iterations;
  history_.push_back({0, LinearizeHere().cost, 0.0, cam_from_lidar_, range_offset_m_});
  // Kim et al.'s estimate is the closed form itself: nothing to iterate.
  if (options_.method == SolverMethod::kKim) {
    done_ = true;
    termination_.test = TerminationTest::kClosedForm;
  }
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

std::vector<int> PlaneAlignmentSolver::ActiveParameters() const {
  std::vector<int> active = {0, 1, 2, 3, 4, 5};
  if (options_.estimate_range_offset) active.push_back(kRangeOffset);
  return active;
}

PlaneAlignmentSolver::Linearization PlaneAlignmentSolver::Linearize(const Pose& cam_from_lidar,
                                                                    double range_offset_m) const {
  Linearization lin;
  lin.pair_weights.assign(pairs_.size(), 0.0);
  lin.pair_edge_points.assign(pairs_.size(), 0);
  if (options_.method == SolverMethod::kWeightedMl) {
    Eigen::Matrix<double, 3, kNumParameters> jacobian =
        Eigen::Matrix<double, 3, kNumParameters>::Zero();
    for (size_t i = 0; i < pairs_.size(); ++i) {
      if (gated_[i]) continue;
      const Vec7 gradient_before = lin.gradient;
      const Mat7 information_before = lin.information;
      const WeightedResidual w = ComputeWeightedResidual(cam_from_lidar, pairs_[i], range_offset_m);
      jacobian.leftCols<6>() = w.jacobian;
      jacobian.col(kRangeOffset) = w.offset_jacobian;
      const Mat3 information = w.covariance.inverse() / plane_variance_scale_;
      const double mahalanobis = std::sqrt(w.residual.dot(information * w.residual));
      const double weight = RobustWeight(mahalanobis);
      lin.pair_weights[i] = weight;
      lin.information += weight * jacobian.transpose() * information * jacobian;
      lin.gradient += weight * jacobian.transpose() * information * w.residual;
      lin.cost += RobustCost(mahalanobis);
      lin.weighted_squared_error += weight * mahalanobis * mahalanobis;
      lin.num_residuals += 3;
      const int edges_before = lin.num_edge_residuals;
      if (options_.use_board_edges && pairs_[i].sheet_half_size_m.minCoeff() > 0)
        LinearizeEdges(cam_from_lidar, range_offset_m, pairs_[i], &lin);
      lin.pair_edge_points[i] = lin.num_edge_residuals - edges_before;
      lin.pair_gradients.push_back(lin.gradient - gradient_before);
      lin.pair_informations.push_back(lin.information - information_before);
    }
    // The offset's prior, a pseudo-observation b = 0 ± σ (only where b is estimated).
    const double prior = options_.range_offset_prior_sigma_m;
    if (options_.estimate_range_offset && prior > 0) {
      lin.information(kRangeOffset, kRangeOffset) += 1.0 / (prior * prior);
      lin.gradient[kRangeOffset] += range_offset_m / (prior * prior);
      lin.cost += 0.5 * range_offset_m * range_offset_m / (prior * prior);
    }
    return lin;
  }
  Eigen::Matrix<double, 4, 6> jacobian;
  for (size_t i = 0; i < pairs_.size(); ++i) {
    const PlanePair& pair = pairs_[i];
    const Vec4 e =
        PlaneAlignmentResidual(cam_from_lidar, pair.lidar_plane, pair.camera_plane, &jacobian);
    const double norm = e.norm();
    const double w = RobustWeight(norm);  // Eq. (14) by iteratively reweighted least squares
    lin.pair_weights[i] = w;
    lin.information.topLeftCorner<6, 6>() += w * jacobian.transpose() * jacobian;
    lin.gradient.head<6>() += w * jacobian.transpose() * e;
    lin.cost += RobustCost(norm);
    lin.weighted_squared_error += w * e.squaredNorm();
    lin.num_residuals += 4;
  }
  return lin;
}

bool PlaneAlignmentSolver::Step() {
  if (done_) return false;
  const Linearization lin = LinearizeHere();
  // Normal equations of Eq. (13)–(14); an LDLT with a tiny damping keeps rank-deficient
  // (degenerate) problems finite: unobservable directions then simply do not move. The offset
  // stays put unless it is estimated (and when the data says nothing about it).
  Mat7 damped = lin.information;
  Vec7 gradient = lin.gradient;
  if (!options_.estimate_range_offset) {
    damped.row(kRangeOffset).setZero();
    damped.col(kRangeOffset).setZero();
    gradient[kRangeOffset] = 0.0;
  }
  const double gradient_max = gradient.cwiseAbs().maxCoeff();
  if (gradient_max <= options_.gradient_tolerance) {
    FinishRound({TerminationTest::kGradientTolerance, gradient_max, options_.gradient_tolerance});
    return !done_;
  }
  if (damped(kRangeOffset, kRangeOffset) == 0) damped(kRangeOffset, kRangeOffset) = 1.0;
  damped.diagonal().array() += 1e-12 * std::max(1.0, damped.diagonal().maxCoeff());
  const Vec7 full_step = -damped.ldlt().solve(gradient);
  Vec7 delta = full_step;
  double cost = CostAt(delta);
  // Backtracking keeps Gauss-Newton monotone far from the solution (robust weights change).
  for (int halvings = 0; cost > lin.cost && halvings < 10; ++halvings) {
    delta *= 0.5;
    cost = CostAt(delta);
  }
  if (cost > lin.cost) return StepOutOfStall(lin, damped, gradient.dot(full_step));
  const double scale = std::max(lin.cost, std::numeric_limits<double>::min());
  Vec7 x;
  x << LogSE3(cam_from_lidar_), range_offset_m_;
  cam_from_lidar_ = cam_from_lidar_ * ExpSE3(delta.head<6>());
  range_offset_m_ += delta[kRangeOffset];
  history_.push_back(
      {static_cast<int>(history_.size()), cost, delta.norm(), cam_from_lidar_, range_offset_m_});
  const double relative_change = (lin.cost - cost) / scale;
  const double tolerance = options_.parameter_tolerance;
  if (delta.norm() <= tolerance * (x.norm() + tolerance))
    FinishRound(
        {TerminationTest::kParameterTolerance, delta.norm() / (x.norm() + tolerance), tolerance});
  else if (relative_change <= options_.function_tolerance)
    FinishRound(
        {TerminationTest::kFunctionTolerance, relative_change, options_.function_tolerance});
  else if (static_cast<int>(history_.size()) > iteration_budget_)
    FinishRound({TerminationTest::kIterationCap, relative_change, options_.function_tolerance,
                 options_.max_iterations});
  return !done_;
}

double PlaneAlignmentSolver::CostAt(const Vec7& step) const {
  return Linearize(cam_from_lidar_ * ExpSE3(step.head<6>()), range_offset_m_ + step[kRangeOffset])
      .cost;
}

bool PlaneAlignmentSolver::StepOutOfStall(const Linearization& lin, const Mat7& damped,
                                          double gradient_dot_step) {
  const double scale = std::max(lin.cost, std::numeric_limits<double>::min());
  // Stalled: along the Gauss-Newton direction the cost only rises. Where the step's own
  // prediction of the decrease (½ gᵀH⁻¹g) is within the function tolerance, the cost is at its
  // numerical floor. Otherwise the robust weights or an edge point's nearest edge switch close
  // by, and the linearization points where the cost does not fall: moves of 0.01σ and 0.1σ
  // along each parameter are tried, the best taken if it lowers the cost; if none does, this is
  // a minimum at the scale of the pose's uncertainty.
  const double predicted = -0.5 * gradient_dot_step / scale;
  if (predicted <= options_.function_tolerance) {
    history_.push_back(
        {static_cast<int>(history_.size()), lin.cost, 0.0, cam_from_lidar_, range_offset_m_});
    FinishRound({TerminationTest::kFunctionTolerance, predicted, options_.function_tolerance});
    return !done_;
  }
  const int redundancy =
      lin.num_residuals - lin.num_edge_dilations - static_cast<int>(ActiveParameters().size());
  const double variance_factor = std::max(2.0 * lin.cost / std::max(1, redundancy), 1e-300);
  const Mat7 covariance = variance_factor * damped.ldlt().solve(Mat7::Identity());
  Vec7 best_move = Vec7::Zero();
  double best_cost = lin.cost;
  for (int k : ActiveParameters())
    for (double fraction : {0.01, 0.1, -0.01, -0.1}) {
      Vec7 move = Vec7::Zero();
      move[k] = fraction * std::sqrt(std::max(covariance(k, k), 0.0));
      const double moved = CostAt(move);
      if (moved < best_cost) {
        best_cost = moved;
        best_move = move;
      }
    }
  if (best_cost < lin.cost) {
    cam_from_lidar_ = cam_from_lidar_ * ExpSE3(best_move.head<6>());
    range_offset_m_ += best_move[kRangeOffset];
  }
  history_.push_back({static_cast<int>(history_.size()), best_cost, best_move.norm(),
                      cam_from_lidar_, range_offset_m_});
  if (best_cost >= lin.cost)
    FinishRound({TerminationTest::kLocalMinimum, predicted, options_.function_tolerance});
  else if (static_cast<int>(history_.size()) > iteration_budget_)
    FinishRound({TerminationTest::kIterationCap, (lin.cost - best_cost) / scale,
                 options_.function_tolerance, options_.max_iterations});
  return !done_;
}

void PlaneAlignmentSolver::FinishRound(const Termination& termination) {
  termination_ = termination;
  done_ = true;
  if (GateOutliers() || EstimateVarianceComponents()) {
    // Continue from here without the gated pairs, with a fresh iteration budget; costs before
    // and after are not comparable.
    history_.back().cost = LinearizeHere().cost;
    history_.back().reweighted = true;
    done_ = false;
    termination_ = {};
    iteration_budget_ = static_cast<int>(history_.size()) + options_.max_iterations;
  }
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
    const WeightedResidual w = ComputeWeightedResidual(cam_from_lidar_, pair, range_offset_m_);
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

bool PlaneAlignmentSolver::EstimateVarianceComponents() {
  // Förstner's variance component estimation for the two kinds of residual: each kind's
  // variance factor is its weighted squared residuals over its share of the redundancy,
  // r_g = n_g − tr(N⁻¹ N_g). Real sensors break the noise models differently (the planes by range
  // biases and board flatness, the edges by beam width and mixed returns): one common factor
  // would let the kind whose model is too optimistic dominate.
  if (variance_component_rounds_ >= 6 || options_.method != SolverMethod::kWeightedMl ||
      !options_.use_board_edges)
    return false;
  const Linearization lin = LinearizeHere();
  const int edges = lin.num_edge_residuals;
  const int planes = lin.num_residuals - edges;
  const std::vector<int> active = ActiveParameters();
  const int num_parameters = static_cast<int>(active.size());
  if (edges < num_parameters || planes < num_parameters) return false;
  ++variance_component_rounds_;
  const Eigen::MatrixXd information = lin.information(active, active);
  const Eigen::MatrixXd edge_information = lin.edge_information(active, active);
  const Eigen::MatrixXd covariance =
      information.ldlt().solve(Eigen::MatrixXd::Identity(num_parameters, num_parameters));
  const double edge_trace = (covariance * edge_information).trace();
  // Each eliminated dilation takes one of its pair's edge residuals.
  const double edge_redundancy = edges - lin.num_edge_dilations - edge_trace;
  const double plane_redundancy = planes - (num_parameters - edge_trace);
  if (!(edge_redundancy > 1) || !(plane_redundancy > 1)) return false;
  const double edge_factor = lin.edge_weighted_squared_error / edge_redundancy;
  const double plane_factor =
      (lin.weighted_squared_error - lin.edge_weighted_squared_error) / plane_redundancy;
  edge_variance_scale_ *= edge_factor;
  plane_variance_scale_ *= plane_factor;
  // Continue (a fresh solve with the new weights) while either factor moved by more than 5%.
  return std::abs(edge_factor - 1) > 0.05 || std::abs(plane_factor - 1) > 0.05;
}

void PlaneAlignmentSolver::SetVarianceFactors(double plane_variance_factor,
                                              double edge_variance_factor) {
  CALIBENCH_CHECK(plane_variance_factor > 0 && edge_variance_factor > 0);
  plane_variance_scale_ = plane_variance_factor;
  edge_variance_scale_ = edge_variance_factor;
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

Mat6 ExpectedPoseInformation(const std::vector<PlanePair>& pairs, const Pose& cam_from_lidar,
                             const SolverOptions& options, double plane_variance_factor,
                             double edge_variance_factor) {
  if (pairs.empty()) return Mat6::Zero();
  SolverOptions model = options;
  model.method = SolverMethod::kWeightedMl;
  model.estimate_range_offset = false;
  PlaneAlignmentSolver solver(pairs, model, cam_from_lidar);
  solver.SetVarianceFactors(plane_variance_factor, edge_variance_factor);
  return solver.PoseInformation();
}

}  // namespace calibench
