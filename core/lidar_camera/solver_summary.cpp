// PlaneAlignmentSolver::Summarize: what the solution says about itself — residuals and weights,
// covariance (model and sandwich), the range offset, observability.
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "core/estimation/uncertainty.h"
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

// `base` widened to `other` along every direction where `other` is larger by more than
// `noise_ratio` (a variance ratio; 1 = any excess): other v = λ base v with vᵀ base v = 1, so in
// the basis V, base = V⁻ᵀV⁻¹ and other = V⁻ᵀΛV⁻¹, and V⁻ᵀ max(Λ / noise_ratio, 1) V⁻¹ is the
// larger of the two along every direction. `base` when the pencil cannot be solved.
Eigen::MatrixXd LargerAlongEveryDirection(const Eigen::MatrixXd& base, const Eigen::MatrixXd& other,
                                          double noise_ratio) {
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> generalized(other, base);
  if (generalized.info() != Eigen::Success) return base;
  const Eigen::MatrixXd to_basis = generalized.eigenvectors().inverse();
  const Eigen::VectorXd widening = (generalized.eigenvalues() / noise_ratio).cwiseMax(1.0);
  return to_basis.transpose() * widening.asDiagonal() * to_basis;
}

// The quantile of F(a, b) at the normal's z, by Paulson's normal approximation of the cube root
// (within a few per cent for a >= 3): solves (A y − B)² = z² (C y² + D) for y = F^(1/3).
double FQuantile(int a, int b, double z) {
  const double c = 2.0 / (9.0 * b), d = 2.0 / (9.0 * a);
  const double big_a = 1.0 - c, big_b = 1.0 - d;
  const double quadratic = big_a * big_a - z * z * c;
  const double discriminant =
      big_a * big_a * big_b * big_b - quadratic * (big_b * big_b - z * z * d);
  if (!(quadratic > 0) || !(discriminant >= 0)) return 1e9;  // too few residuals to tell
  const double y = (big_a * big_b + std::sqrt(discriminant)) / quadratic;
  return y * y * y;
}

// The standard normal's quantile (Acklam's rational approximation, relative error < 1.2e-9 in
// the upper tail used here).
double NormalQuantile(double p) {
  // Upper region only (p > 0.97575), which is all this file asks for.
  const double q = std::sqrt(-2.0 * std::log(1.0 - p));
  static constexpr double c[] = {-7.784894002430293e-03, -3.223964580411365e-01,
                                 -2.400758277161838e+00, -2.549732539343734e+00,
                                 4.374664141464968e+00,  2.938163982698783e+00};
  static constexpr double d[] = {7.784695709041462e-03, 3.224671290700398e-01,
                                 2.445134137142996e+00, 3.754408661907416e+00};
  return -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
         ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
}

// The Student t quantile at the normal's 3σ (one-sided 0.99865) for `dof` degrees of freedom,
// interpolated in 1/dof between tabulated values (computed by numerical integration of the t
// density); 3 in the limit.
double StudentQuantileAt3Sigma(int dof) {
  static constexpr std::pair<double, double> kTable[] = {
      {1, 235.8},  {2, 19.21},  {3, 9.219},  {4, 6.620},  {5, 5.507},
      {6, 4.904},  {7, 4.530},  {8, 4.277},  {9, 4.094},  {10, 3.957},
      {12, 3.764}, {15, 3.586}, {20, 3.422}, {30, 3.270}, {60, 3.130}};
  if (dof <= 1) return kTable[0].second;
  for (size_t i = 1; i < std::size(kTable); ++i) {
    if (dof > kTable[i].first) continue;
    const auto [v0, q0] = kTable[i - 1];
    const auto [v1, q1] = kTable[i];
    const double f = (1.0 / v0 - 1.0 / dof) / (1.0 / v0 - 1.0 / v1);
    return q0 + f * (q1 - q0);
  }
  const auto [v_last, q_last] = kTable[std::size(kTable) - 1];
  return 3.0 + (q_last - 3.0) * v_last / dof;
}

// The cluster-robust covariance H⁻¹ (Σᵢ gᵢgᵢᵀ) H⁻¹ · n/(n − p), the pairs as clusters.
Eigen::MatrixXd Sandwich(const std::vector<Eigen::VectorXd>& gradients,
                         const Eigen::MatrixXd& inverse_information) {
  const int n = static_cast<int>(gradients.size());
  const int p = static_cast<int>(inverse_information.rows());
  Eigen::MatrixXd meat = Eigen::MatrixXd::Zero(p, p);
  for (const Eigen::VectorXd& g : gradients) meat += g * g.transpose();
  return static_cast<double>(n) / (n - p) * inverse_information * meat * inverse_information;
}

// The leave-one-pair-out estimate: `raw` the jackknife of the moves, `scatter` what it says of
// the covariance once the pairs' leverage is taken out; `skipped` says why there is none.
struct Jackknife {
  int pairs = 0;
  Eigen::MatrixXd raw;
  Eigen::MatrixXd scatter;
  std::string skipped;
};

// How far the estimate moves when each pair is left out, one Gauss-Newton step from the solution
// without that pair's share: Δᵢ = Aᵢ gᵢ with Aᵢ = (H − Hᵢ)⁻¹ (gᵢ the pair's gradient, Hᵢ its
// information). Unlike the sandwich it sees a pair's leverage (a pair the others hardly constrain
// moves the estimate by more than H⁻¹ gᵢ), and it needs only 4 pairs. But a pair of high leverage
// moves the estimate more than the model's covariance suggests even when the model holds (with k
// pairs and p parameters the average pair carries p/k of the information): gᵢ has covariance
// s² Hᵢ then, so the jackknife is judged against E = s² Σ Aᵢ Hᵢ Aᵢᵀ, its excess X = L_E⁻¹ J L_E⁻ᵀ
// (the identity when the model holds) carried over to the model's covariance, L_M X L_Mᵀ.
Jackknife LeaveOnePairOut(const Eigen::MatrixXd& information,
                          const std::vector<Eigen::MatrixXd>& pair_informations,
                          const std::vector<Eigen::VectorXd>& pair_gradients,
                          const std::vector<std::string>& pair_ids, double variance_factor,
                          const Eigen::MatrixXd& model_covariance) {
  const int k = static_cast<int>(pair_gradients.size());
  const int p = static_cast<int>(information.rows());
  Jackknife out;
  out.pairs = k;
  std::vector<Eigen::VectorXd> moves;
  Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(p, p);
  for (int i = 0; i < k; ++i) {
    const Eigen::MatrixXd without = information - pair_informations[i];
    const Eigen::VectorXd lambdas =
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(without).eigenvalues();
    if (!(lambdas[0] > 1e-9 * lambdas[p - 1])) {
      out.skipped = "leaving pair " + pair_ids[i] + " out leaves the pose undetermined";
      return out;
    }
    const Eigen::MatrixXd inverse = without.ldlt().solve(Eigen::MatrixXd::Identity(p, p));
    moves.push_back(inverse * pair_gradients[i]);
    expected += variance_factor * inverse * pair_informations[i] * inverse.transpose();
  }
  const Eigen::LLT<Eigen::MatrixXd> expected_llt(expected * ((k - 1.0) / k));
  const Eigen::LLT<Eigen::MatrixXd> model_llt(model_covariance);
  if (expected_llt.info() != Eigen::Success || model_llt.info() != Eigen::Success) {
    out.skipped = "the leave-one-out moves could not be compared with the model";
    return out;
  }
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(p);
  for (const Eigen::VectorXd& move : moves) mean += move / k;
  out.raw = Eigen::MatrixXd::Zero(p, p);
  for (const Eigen::VectorXd& move : moves) out.raw += (move - mean) * (move - mean).transpose();
  out.raw *= (k - 1.0) / k;
  const Eigen::MatrixXd l_expected = expected_llt.matrixL();
  const Eigen::MatrixXd l_model = model_llt.matrixL();
  const Eigen::MatrixXd excess = l_expected.triangularView<Eigen::Lower>().solve(
      l_expected.triangularView<Eigen::Lower>().solve(out.raw).transpose());
  out.scatter = l_model * excess * l_model.transpose();
  return out;
}

// Where the model holds, the jackknife's scatter along a direction lies around the model's
// variance like an F(k − 1, r) ratio (the model's own scale is estimated from the r redundant
// residuals), and the model, which knows every residual's noise, is the better estimate. Only a
// scatter beyond that ratio's 99 % quantile for the largest of the p directions (Bonferroni:
// 1 − 0.01/p, z = 2.93 for six) says the model is violated (real sensors' per-pair errors). Then
// the jackknife itself is reported where it is larger, widened by the Student t quantile over the
// normal's at 3σ for its k − 1 degrees of freedom (a 3σ test then keeps its 99.7 %): with few
// pairs its leverage makes it conservative, the side to err on once the model is known not to
// hold. True when *reported was widened.
bool WidenWhereTheModelFails(const Jackknife& jackknife, const Eigen::MatrixXd& model_covariance,
                             int redundancy, Eigen::MatrixXd* reported) {
  const int pairs = jackknife.pairs;
  const int parameters = static_cast<int>(model_covariance.rows());
  const double threshold =
      FQuantile(pairs - 1, std::max(1, redundancy), NormalQuantile(1.0 - 0.01 / parameters));
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> test(jackknife.scatter,
                                                                 model_covariance);
  if (test.info() != Eigen::Success || !(test.eigenvalues().maxCoeff() > threshold)) return false;
  const double widen = StudentQuantileAt3Sigma(pairs - 1) / 3.0;
  *reported = LargerAlongEveryDirection(*reported, widen * widen * jackknife.raw, 1.0);
  return true;
}

// An offset left out that the data cannot see still biases the pose by g·b (g = −H_pp⁻¹ H_pb,
// the pose's response to an offset): its prior σ_b, narrowed by what the data itself says of b
// (the information left for it once the pose is free, at the solve's variance factor),
// σ_post² = 1 / (1/σ_b² + I_b|pose), spreads into the pose's covariance as σ_post² g gᵀ.
template <typename Information>
Mat6 RangeOffsetPriorCovariance(const Information& information, int offset, double prior_sigma_m,
                                double variance_factor) {
  if (!(variance_factor > 0)) return Mat6::Zero();
  const Mat6 pose_information = information.template topLeftCorner<6, 6>();
  const Vec6 cross = information.template block<6, 1>(0, offset);
  const Vec6 response = -pose_information.ldlt().solve(cross);
  const double offset_information =
      std::max(0.0, (information(offset, offset) + cross.dot(response)) / variance_factor);
  const double posterior = 1.0 / (1.0 / (prior_sigma_m * prior_sigma_m) + offset_information);
  if (!response.allFinite() || !std::isfinite(posterior)) return Mat6::Zero();
  return posterior * response * response.transpose();
}

}  // namespace

SolverResult PlaneAlignmentSolver::Summarize() const {
  SolverResult result;
  result.method = options_.method;
  result.cam_from_lidar = cam_from_lidar_;
  result.termination = termination_;
  result.converged = termination_.Converged();
  result.iterations = static_cast<int>(history_.size()) - 1;
  for (const IterationReport& it : history_) {
    if (it.reweighted) result.cost_comparable_from = static_cast<int>(result.cost_history.size());
    result.cost_history.push_back(it.cost);
  }
  for (const PlanePair& pair : pairs_)
    result.residuals.push_back(PlaneAlignmentResidual(
        cam_from_lidar_, CorrectedLidarPlane(pair, range_offset_m_), pair.camera_plane, nullptr));
  const Linearization lin = LinearizeHere();
  // As the solver weighed them: with the planes' variance component, 0 for gated pairs.
  result.robust_weights = lin.pair_weights;
  result.negligible_weight = options_.negligible_weight;
  // The inverse information scaled by the a-posteriori variance factor: for the paper's residual,
  // which has no noise model, that is the noise estimate itself (4 residuals per pair); for the
  // weighted residual (3 per pair) it absorbs what the feature covariances miss on real sensors.
  const std::vector<int> active = ActiveParameters();
  const int redundancy =
      lin.num_residuals - lin.num_edge_dilations - static_cast<int>(active.size());
  result.num_edge_residuals = lin.num_edge_residuals;
  result.pair_edge_points = lin.pair_edge_points;
  result.edges_in_model = options_.method == SolverMethod::kWeightedMl && options_.use_board_edges;
  result.edge_dilation = DilationOverPairs(lin.pair_dilations_m);
  const double variance_factor = redundancy > 0 ? lin.weighted_squared_error / redundancy : 0.0;
  // The a-posteriori variance factor of each kind of residual against its noise model: the
  // component estimated for it times the common factor that remains.
  result.plane_variance_factor = plane_variance_scale_ * variance_factor;
  result.edge_variance_factor = edge_variance_scale_ * variance_factor;
  const Mat7 covariance = Covariance(lin, active, variance_factor, &result);
  result.covariance = covariance.topLeftCorner<6, 6>();
  ReportRangeOffset(lin, covariance, variance_factor, &result);
  result.observability = Observability(result, redundancy);
  return result;
}

PlaneAlignmentSolver::Mat7 PlaneAlignmentSolver::Covariance(const Linearization& lin,
                                                            const std::vector<int>& active,
                                                            double variance_factor,
                                                            SolverResult* result) const {
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
  result->model_covariance = covariance.topLeftCorner<6, 6>();
  const int clusters = static_cast<int>(lin.pair_gradients.size());
  if (options_.method != SolverMethod::kWeightedMl || !(variance_factor > 0) ||
      !(eigen.eigenvalues()[0] > 1e-12 * largest))
    return covariance;
  // Each used pair's share of the gradient and the information, over the active parameters.
  std::vector<Eigen::VectorXd> gradients;
  std::vector<Eigen::MatrixXd> informations;
  for (int i = 0; i < clusters; ++i) {
    gradients.push_back(lin.pair_gradients[i](active));
    informations.push_back(lin.pair_informations[i](active, active));
  }
  Eigen::MatrixXd reported = model_covariance;
  // The model's covariance trusts every residual to be independent. On real sensors they are
  // not (a pair's edge points share its range-dependent beam footprint, its board's flatness,
  // its rings' angle errors), which the model cannot see and the spread over pairs shows. The
  // cluster-robust (sandwich) covariance with the pairs as clusters measures that spread from the
  // data; the reported covariance is the larger of the two in every direction (beyond the
  // sandwich's own sampling noise: a variance ratio estimated from n clusters scatters by about
  // √(2 / (n − p)) even when the model holds, so a correct model keeps its χ² calibration).
  if (options_.sandwich_covariance && clusters > num_parameters + 2)
    reported =
        LargerAlongEveryDirection(reported, Sandwich(gradients, model_covariance / variance_factor),
                                  1.0 + std::sqrt(2.0 / (clusters - num_parameters)));
  if (!options_.jackknife_covariance) {
    result->jackknife_skipped = "the jackknife is off";
  } else if (clusters < 4) {
    result->jackknife_skipped = "fewer than 4 pairs in the solve";
  } else {
    std::vector<std::string> ids;  // the pairs behind pair_gradients: those not gated
    for (size_t j = 0; j < pairs_.size(); ++j)
      if (!gated_[j]) ids.push_back(pairs_[j].id);
    const Jackknife jackknife = LeaveOnePairOut(information, informations, gradients, ids,
                                                variance_factor, model_covariance);
    result->jackknife_skipped = jackknife.skipped;
    if (jackknife.skipped.empty()) {
      Mat7 scatter_pose = Mat7::Zero();
      scatter_pose(active, active) = jackknife.scatter;
      result->jackknife_pairs = clusters;
      result->jackknife_sigma_t_m =
          TranslationStd(scatter_pose.topLeftCorner<6, 6>(), cam_from_lidar_);
      result->jackknife_sigma_r_deg =
          RotationStdDeg(scatter_pose.topLeftCorner<6, 6>(), cam_from_lidar_);
      const int redundancy = lin.num_residuals - lin.num_edge_dilations - num_parameters;
      result->jackknife_widened =
          WidenWhereTheModelFails(jackknife, model_covariance, redundancy, &reported);
    }
  }
  covariance(active, active) = reported;
  if (!options_.estimate_range_offset && options_.range_offset_prior_sigma_m > 0)
    covariance.topLeftCorner<6, 6>() += RangeOffsetPriorCovariance(
        lin.information, kRangeOffset, options_.range_offset_prior_sigma_m, variance_factor);
  // How much wider than the model the reported covariance is, along its widest direction.
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ratio(covariance(active, active),
                                                                  model_covariance);
  if (ratio.info() == Eigen::Success)
    result->covariance_inflation = std::max(1.0, ratio.eigenvalues().maxCoeff());
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
