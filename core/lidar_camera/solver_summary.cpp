// PlaneAlignmentSolver::Summarize: what the solution says about itself — residuals and weights,
// covariance (model and sandwich), the range offset, observability.
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/lidar_camera/solver.h"

namespace calibench {
namespace {

// The mean of the pairs' dilations, its standard error and their spread.
std::optional<EdgeDilationEstimate> DilationOverPairs(const std::vector<double>& dilations_m) {
  if (dilations_m.empty()) return std::nullopt;
  const int n = static_cast<int>(dilations_m.size());
  EdgeDilationEstimate dilation;
  for (double d : dilations_m) dilation.value_m += d / n;
  for (double d : dilations_m) dilation.spread_m += (d - dilation.value_m) * (d - dilation.value_m);
  dilation.spread_m = n > 1 ? std::sqrt(dilation.spread_m / (n - 1)) : 0.0;
  dilation.sigma_m = dilation.spread_m / std::sqrt(n);
  return dilation;
}

}  // namespace

SolverResult PlaneAlignmentSolver::Summarize() const {
  SolverResult result;
  result.method = options_.method;
  result.cam_from_lidar = cam_from_lidar_;
  result.converged = converged_;
  result.iterations = static_cast<int>(history_.size()) - 1;
  for (const IterationReport& it : history_) result.cost_history.push_back(it.cost);
  for (const PlanePair& pair : pairs_)
    result.residuals.push_back(PlaneAlignmentResidual(
        cam_from_lidar_, CorrectedLidarPlane(pair, range_offset_m_), pair.camera_plane, nullptr));
  const Linearization lin = LinearizeHere();
  // As the solver weighed them: with the planes' variance component, 0 for gated pairs.
  result.robust_weights = lin.pair_weights;
  // The inverse information scaled by the a-posteriori variance factor: for the paper's residual,
  // which has no noise model, that is the noise estimate itself (4 residuals per pair); for the
  // weighted residual (3 per pair) it absorbs what the feature covariances miss on real sensors.
  const std::vector<int> active = ActiveParameters();
  const int redundancy =
      lin.num_residuals - lin.num_edge_dilations - static_cast<int>(active.size());
  result.num_edge_residuals = lin.num_edge_residuals;
  result.edge_dilation = DilationOverPairs(lin.pair_dilations_m);
  const double variance_factor = redundancy > 0 ? lin.weighted_squared_error / redundancy : 0.0;
  // The a-posteriori variance factor of each kind of residual against its noise model: the
  // component estimated for it times the common factor that remains.
  result.plane_variance_factor = plane_variance_scale_ * variance_factor;
  result.edge_variance_factor = edge_variance_scale_ * variance_factor;
  const Mat7 covariance = Covariance(lin, active, variance_factor, &result.covariance_inflation);
  result.covariance = covariance.topLeftCorner<6, 6>();
  ReportRangeOffset(lin, covariance, variance_factor, &result);
  result.observability = Observability(result, redundancy);
  return result;
}

PlaneAlignmentSolver::Mat7 PlaneAlignmentSolver::Covariance(const Linearization& lin,
                                                            const std::vector<int>& active,
                                                            double variance_factor,
                                                            double* inflation) const {
  // With the offset estimated, the pose covariance is the marginal of the joint one: the offset's
  // uncertainty spreads into the translation it is correlated with.
  const int num_parameters = static_cast<int>(active.size());
  const Eigen::MatrixXd information = lin.information(active, active);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(information);
  Eigen::VectorXd inverse_eigenvalues(num_parameters);
  const double largest = eigen.eigenvalues()[num_parameters - 1];
  for (int i = 0; i < num_parameters; ++i) {
    const double lambda = eigen.eigenvalues()[i];
    inverse_eigenvalues[i] = lambda > 1e-12 * largest ? 1.0 / lambda : 1e12;
  }
  Mat7 covariance = Mat7::Zero();
  const Eigen::MatrixXd model_covariance = variance_factor * eigen.eigenvectors() *
                                           inverse_eigenvalues.asDiagonal() *
                                           eigen.eigenvectors().transpose();
  covariance(active, active) = model_covariance;
  // The model's covariance trusts every residual to be independent. On real sensors they are
  // not (a pair's edge points share its range-dependent beam footprint, its board's flatness,
  // its rings' angle errors), which the model cannot see and the spread over pairs shows. The
  // cluster-robust (sandwich) covariance with the pairs as clusters, H⁻¹ (Σᵢ gᵢgᵢᵀ) H⁻¹ scaled by
  // n/(n − p), measures that spread from the data; the reported covariance is the larger of the
  // two in every direction (beyond the sandwich's own sampling noise).
  const int clusters = static_cast<int>(lin.pair_gradients.size());
  if (options_.method != SolverMethod::kWeightedMl || !options_.sandwich_covariance ||
      clusters <= num_parameters + 2 || !(variance_factor > 0) ||
      !(eigen.eigenvalues()[0] > 1e-12 * largest))
    return covariance;
  Eigen::MatrixXd meat = Eigen::MatrixXd::Zero(num_parameters, num_parameters);
  for (const Vec7& g : lin.pair_gradients) {
    const Eigen::VectorXd active_g = g(active);
    meat += active_g * active_g.transpose();
  }
  const Eigen::MatrixXd inverse_information = model_covariance / variance_factor;
  const Eigen::MatrixXd sandwich = static_cast<double>(clusters) / (clusters - num_parameters) *
                                   inverse_information * meat * inverse_information;
  // sandwich v = λ model v with vᵀ model v = 1: in the basis V, model = V⁻ᵀV⁻¹ and
  // sandwich = V⁻ᵀΛV⁻¹, so V⁻ᵀ max(Λ, 1) V⁻¹ is the larger of the two along every direction.
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> generalized(sandwich, model_covariance);
  if (generalized.info() != Eigen::Success) return covariance;
  // A variance ratio estimated from n clusters scatters by about √(2 / (n − p)) even when the
  // model holds: only the excess beyond that one-σ noise inflates, so that a correct model
  // keeps its covariance (and its χ² calibration) while a violated one widens.
  const double noise = 1.0 + std::sqrt(2.0 / (clusters - num_parameters));
  const Eigen::MatrixXd to_basis = generalized.eigenvectors().inverse();
  const Eigen::VectorXd widening = (generalized.eigenvalues() / noise).cwiseMax(1.0);
  covariance(active, active) = to_basis.transpose() * widening.asDiagonal() * to_basis;
  *inflation = widening.maxCoeff();
  return covariance;
}

Vec3 PlaneAlignmentSolver::OffsetCorrelation(const Mat7& joint_covariance) const {
  const Mat3& rotation = cam_from_lidar_.linear();
  const Mat3 translation_covariance =
      rotation * joint_covariance.topLeftCorner<3, 3>() * rotation.transpose();
  const Vec3 cross = rotation * joint_covariance.block<3, 1>(0, kRangeOffset);
  const double offset_sigma =
      std::sqrt(std::max(0.0, joint_covariance(kRangeOffset, kRangeOffset)));
  Vec3 correlation = Vec3::Zero();
  for (int k = 0; k < 3; ++k) {
    const double denominator = std::sqrt(translation_covariance(k, k)) * offset_sigma;
    correlation[k] = denominator > 0 ? cross[k] / denominator : 0.0;
  }
  return correlation;
}

void PlaneAlignmentSolver::ReportRangeOffset(const Linearization& lin, const Mat7& covariance,
                                             double variance_factor, SolverResult* result) const {
  if (options_.estimate_range_offset) {
    RangeOffsetEstimate offset;
    offset.value_m = range_offset_m_;
    offset.sigma_m = std::sqrt(std::max(0.0, covariance(kRangeOffset, kRangeOffset)));
    offset.correlation_with_translation = OffsetCorrelation(covariance);
    offset.well_determined = offset.sigma_m < options_.range_offset_max_sigma_m;
    result->range_offset = offset;
    return;
  }
  if (options_.method != SolverMethod::kWeightedMl || !(variance_factor > 0) ||
      !(lin.information(kRangeOffset, kRangeOffset) > 0))
    return;
  // Score test for the offset left out: one Gauss-Newton step in the joint parameters from
  // the solution. The pose's gradient is zero there, so the step is the offset's own, less what
  // the pose would absorb; its variance is the joint one's, like the pose's no smaller than the
  // pairs' spread says (sandwich).
  const int clusters = static_cast<int>(lin.pair_gradients.size());
  const Eigen::LDLT<Mat7> joint(lin.information);
  const Mat7 joint_inverse = joint.solve(Mat7::Identity());
  const Vec7 step = -joint_inverse * lin.gradient;
  double variance = variance_factor * joint_inverse(kRangeOffset, kRangeOffset);
  if (options_.sandwich_covariance && clusters > kNumParameters + 2) {
    double meat = 0.0;
    for (const Vec7& g : lin.pair_gradients)
      meat += std::pow(joint_inverse.row(kRangeOffset).dot(g), 2);
    variance =
        std::max(variance, static_cast<double>(clusters) / (clusters - kNumParameters) * meat);
  }
  const double sigma = std::sqrt(variance);
  if (joint.info() != Eigen::Success || !std::isfinite(step[kRangeOffset]) || !(sigma > 0) ||
      sigma >= options_.range_offset_max_sigma_m ||
      std::abs(step[kRangeOffset]) <= options_.range_offset_significance * sigma)
    return;
  RangeOffsetEstimate offset;
  offset.value_m = range_offset_m_ + step[kRangeOffset];
  offset.sigma_m = sigma;
  offset.correlation_with_translation = OffsetCorrelation(variance_factor * joint_inverse);
  offset.well_determined = true;
  result->unmodelled_range_offset = offset;
}

ObservabilityReport PlaneAlignmentSolver::Observability(const SolverResult& result,
                                                        int redundancy) const {
  // Observability is a property of the geometry, not of the noise: judge it on the unweighted
  // plane-to-plane information (Eq. (6) Jacobians, unit weights), whose eigenvalues compare like
  // with like for either method; whitened information mixes 1/m² and 1/rad² scales.
  Mat6 geometric_information = Mat6::Zero();
  Eigen::Matrix<double, 4, 6> jacobian;
  for (const PlanePair& pair : pairs_) {
    PlaneAlignmentResidual(cam_from_lidar_, pair.lidar_plane, pair.camera_plane, &jacobian);
    geometric_information += jacobian.transpose() * jacobian;
  }
  ObservabilityReport report =
      AnalyseObservability(geometric_information, cam_from_lidar_, options_.weak_eigenvalue_ratio);
  if (result.range_offset && !result.range_offset->well_determined) {
    const RangeOffsetEstimate& offset = *result.range_offset;
    int axis = 0;
    offset.correlation_with_translation.cwiseAbs().maxCoeff(&axis);
    static const char* kAxisNames[3] = {"x", "y", "z"};
    char text[200];
    std::snprintf(text, sizeof(text),
                  "LiDAR range offset: %+.1f ± %.1f mm, correlation %.2f with the translation "
                  "along camera %s (boards over a wider range of distances, angles and "
                  "directions from the LiDAR separate them)",
                  offset.value_m * 1e3, offset.sigma_m * 1e3,
                  offset.correlation_with_translation[axis], kAxisNames[axis]);
    report.weak_directions.push_back(text);
    report.well_constrained = false;
  }
  if (redundancy <= 0) {
    report.well_constrained = false;
    report.weak_directions.push_back(
        "fewer than 2 redundant residuals: at least 2 pairs are needed, 3 for all six degrees of "
        "freedom");
  }
  return report;
}

}  // namespace calibench
