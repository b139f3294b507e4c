// The solver's board-edge residuals (SolverOptions::use_board_edges): each ring's crossing of
// the sheet's edge against the edge the camera's board pose places there, with the pair's
// nuisances (the dilation, the board pose's shared error) eliminated in closed form.
#include <Eigen/Cholesky>
#include <cmath>
#include <vector>

#include "core/lidar_camera/solver.h"

namespace calibench {

namespace {

// The inverse of a covariance that is symmetric positive definite and finite; false otherwise.
bool InvertCovariance(const Mat6& covariance, Mat6* information) {
  if (!covariance.allFinite()) return false;
  const Eigen::LLT<Mat6> llt(covariance);
  if (llt.info() != Eigen::Success) return false;
  *information = llt.solve(Mat6::Identity());
  return information->allFinite();
}

}  // namespace

std::vector<PlaneAlignmentSolver::EdgeRow> PlaneAlignmentSolver::EdgeRows(
    const Pose& cam_from_lidar, double range_offset_m, const PlanePair& pair) const {
  std::vector<EdgeRow> rows;
  rows.reserve(pair.lidar_edges.size());
  Eigen::Matrix<double, 1, 6> edge_jacobian;
  for (LidarEdgePoint edge : pair.lidar_edges) {
    // The crossing lies on the fitted plane, which a range offset b moved along the rays: the
    // board's own crossing is b closer along its ray.
    const Vec3 ray = edge.point.normalized();
    edge.point -= range_offset_m * ray;
    EdgeRow row;
    row.residual = BoardEdgeResidual(cam_from_lidar, pair.camera_from_board, pair.sheet_half_size_m,
                                     edge, options_.edge_floor_sigma_m, &edge_jacobian, &row.sigma,
                                     &row.board_pose_jacobian);
    row.sigma *= std::sqrt(edge_variance_scale_);
    row.jacobian.setZero();
    row.jacobian.head<6>() = edge_jacobian;
    // d e / d b: the point moves by −b·ray, and d e / d ρ is d e / d(point) in this frame.
    row.jacobian[kRangeOffset] = -edge_jacobian.head<3>().dot(ray);
    rows.push_back(row);
  }
  return rows;
}

std::vector<double> PlaneAlignmentSolver::EdgeWeights(const std::vector<EdgeRow>& rows,
                                                      bool with_dilation) const {
  // The pair's dilation δ (SolverOptions::estimate_edge_dilation): every crossing should lie δ
  // outside its edge. Its robust weighted mean at this pose sets the Huber weights.
  double dilation = 0.0;
  std::vector<double> weights(rows.size());
  for (int pass = 0; pass < (with_dilation ? 4 : 1); ++pass) {
    double weighted_sum = 0.0;
    double weight_sum = 0.0;
    for (size_t k = 0; k < rows.size(); ++k) {
      const double whitened = (rows[k].residual - dilation) / rows[k].sigma;
      weights[k] = RobustWeight(std::abs(whitened)) / (rows[k].sigma * rows[k].sigma);
      weighted_sum += weights[k] * rows[k].residual;
      weight_sum += weights[k];
    }
    if (with_dilation && pass < 3) dilation = weighted_sum / weight_sum;
  }
  return weights;
}

void PlaneAlignmentSolver::LinearizeEdges(const Pose& cam_from_lidar, double range_offset_m,
                                          const PlanePair& pair, Linearization* lin) const {
  const std::vector<EdgeRow> rows = EdgeRows(cam_from_lidar, range_offset_m, pair);
  if (rows.empty()) return;
  const bool with_dilation = options_.estimate_edge_dilation && rows.size() >= 3;
  const std::vector<double> weights = EdgeWeights(rows, with_dilation);
  // The pair's nuisances, eliminated in closed form (Schur complement; variable projection):
  // the dilation (flat prior; residual r − δ) and, with edge_board_pose_uncertainty, the error of
  // the camera's board pose (prior: its PnP covariance), which every edge point shares.
  Eigen::Matrix<double, 6, 6> pose_prior_information = Mat6::Zero();
  const bool with_board_pose =
      options_.edge_board_pose_uncertainty && !pair.camera_pose_covariance.isZero(0.0) &&
      InvertCovariance(pair.camera_pose_covariance, &pose_prior_information);
  const int first_pose = with_dilation ? 1 : 0;
  const int nuisances = first_pose + (with_board_pose ? 6 : 0);
  Eigen::MatrixXd nuisance_information = Eigen::MatrixXd::Zero(nuisances, nuisances);
  if (with_board_pose)
    nuisance_information.block<6, 6>(first_pose, first_pose) = pose_prior_information;
  Eigen::Matrix<double, kNumParameters, Eigen::Dynamic> cross =
      Eigen::Matrix<double, kNumParameters, Eigen::Dynamic>::Zero(kNumParameters, nuisances);
  Eigen::VectorXd nuisance_gradient = Eigen::VectorXd::Zero(nuisances);
  Mat7 information = Mat7::Zero();
  Vec7 gradient = Vec7::Zero();
  Eigen::RowVectorXd a(nuisances);
  for (size_t k = 0; k < rows.size(); ++k) {
    if (with_dilation) a[0] = -1.0;
    if (with_board_pose) a.segment<6>(first_pose) = rows[k].board_pose_jacobian;
    const double w = weights[k];
    const double e = rows[k].residual;
    information += w * rows[k].jacobian.transpose() * rows[k].jacobian;
    gradient += w * rows[k].jacobian.transpose() * e;
    cross += w * rows[k].jacobian.transpose() * a;
    nuisance_information += w * a.transpose() * a;
    nuisance_gradient += w * a.transpose() * e;
  }
  Eigen::VectorXd nuisance = Eigen::VectorXd::Zero(nuisances);
  if (nuisances > 0) {
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(nuisance_information);
    information -= cross * ldlt.solve(cross.transpose());
    gradient -= cross * ldlt.solve(nuisance_gradient);
    nuisance = -ldlt.solve(nuisance_gradient);  // the nuisances' estimate at this pose
  }
  if (with_dilation) {
    ++lin->num_edge_dilations;
    lin->pair_dilations_m.push_back(nuisance[0]);
  }
  lin->information += information;
  lin->edge_information += information;
  lin->gradient += gradient;
  for (size_t k = 0; k < rows.size(); ++k) {
    if (with_dilation) a[0] = -1.0;
    if (with_board_pose) a.segment<6>(first_pose) = rows[k].board_pose_jacobian;
    const double e = rows[k].residual + (nuisances > 0 ? a.dot(nuisance) : 0.0);
    lin->cost += RobustCost(std::abs(e / rows[k].sigma));
    lin->weighted_squared_error += weights[k] * e * e;
    lin->edge_weighted_squared_error += weights[k] * e * e;
    ++lin->num_residuals;
    ++lin->num_edge_residuals;
  }
  if (with_board_pose) {
    // The board pose's prior, as its own squared residual.
    const Vec6 pose_error = nuisance.segment<6>(first_pose);
    const double prior = pose_error.dot(pose_prior_information * pose_error);
    lin->cost += 0.5 * prior;
    lin->weighted_squared_error += prior;
    lin->edge_weighted_squared_error += prior;
  }
}

}  // namespace calibench
