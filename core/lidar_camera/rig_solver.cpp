#include "core/lidar_camera/rig_solver.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

namespace calibench {
namespace {

// A measurement's whitening: W with W Σ Wᵀ = I (Σ = L Lᵀ, W = L⁻¹); nullopt unless Σ > 0.
template <int N>
std::optional<Eigen::Matrix<double, N, N>> RigWhitening(
    const Eigen::Matrix<double, N, N>& covariance) {
  const Eigen::LLT<Eigen::Matrix<double, N, N>> llt(covariance);
  if (llt.info() != Eigen::Success || !covariance.allFinite()) return std::nullopt;
  return llt.matrixL().solve(Eigen::Matrix<double, N, N>::Identity());
}

struct RigViewTerm {
  int camera, capture;           // capture: index among the used captures
  Pose measured_board_from_cam;  // cam_from_board⁻¹
  Mat6 whitening;
};
struct RigPlaneTerm {
  int capture;
  Vec4 measured;                      // (n, d)
  Eigen::Matrix<double, 4, 3> basis;  // tangent coordinates of the measured plane
  Mat3 whitening;
  double sign = 1.0;  // the board's +z or -z faces the LiDAR
};

struct RigPriorTerm {
  int camera;
  Pose measured_inverse;  // prior⁻¹
  Mat6 whitening;
};

struct RigProblem {
  int cameras = 0;
  std::vector<Pose> cam_from_lidar;
  std::vector<Pose> lidar_from_board;
  std::vector<RigViewTerm> views;
  std::vector<RigPlaneTerm> planes;
  std::vector<RigPriorTerm> priors;
  int Measurements() const {
    return 6 * static_cast<int>(views.size() + priors.size()) + 3 * static_cast<int>(planes.size());
  }
  int Size() const { return 6 * (cameras + static_cast<int>(lidar_from_board.size())); }
  int CameraOffset(int c) const { return 6 * c; }
  int CaptureOffset(int k) const { return 6 * (cameras + k); }
};

double RigHuberWeight(double norm, double delta) { return norm <= delta ? 1.0 : delta / norm; }
double RigHuberCost(double norm, double delta) {
  return norm <= delta ? 0.5 * norm * norm : delta * norm - 0.5 * delta * delta;
}

// Log(M⁻¹ · cam_from_lidar · lidar_from_board), not yet whitened.
Vec6 RigViewError(const RigProblem& p, const RigViewTerm& v) {
  return LogSE3(v.measured_board_from_cam * p.cam_from_lidar[v.camera] *
                p.lidar_from_board[v.capture]);
}
Vec6 RigViewResidual(const RigProblem& p, const RigViewTerm& v) {
  return v.whitening * RigViewError(p, v);
}

// The inverse right Jacobian of SE(3) to first order, Log(Exp(r) Exp(δ)) ≈ r + (I + ad(r)/2) δ:
// exact enough that Gauss-Newton's fixed point is the cost's minimum to ~|r|³.
Mat6 RightJacobianInverse(const Vec6& r) {
  Mat6 ad = Mat6::Zero();
  ad.block<3, 3>(0, 0) = Skew(r.tail<3>());
  ad.block<3, 3>(0, 3) = Skew(r.head<3>());
  ad.block<3, 3>(3, 3) = Skew(r.tail<3>());
  return Mat6::Identity() + 0.5 * ad;
}

// The board's plane z = 0 under lidar_from_board, as (n, d) with the term's orientation.
Vec4 RigBoardPlane(const Pose& lidar_from_board, double sign) {
  const Vec3 n = sign * lidar_from_board.linear().col(2);
  return Vec4(n.x(), n.y(), n.z(), -n.dot(lidar_from_board.translation()));
}

Vec3 RigPlaneResidual(const RigProblem& p, const RigPlaneTerm& t) {
  return t.whitening * (t.basis.transpose() *
                        (RigBoardPlane(p.lidar_from_board[t.capture], t.sign) - t.measured));
}

Vec6 RigPriorError(const RigProblem& p, const RigPriorTerm& t) {
  return LogSE3(t.measured_inverse * p.cam_from_lidar[t.camera]);
}

double RigCost(const RigProblem& p, double delta) {
  double cost = 0.0;
  for (const RigPriorTerm& t : p.priors)
    cost += RigHuberCost((t.whitening * RigPriorError(p, t)).norm(), delta);
  for (const RigViewTerm& v : p.views) cost += RigHuberCost(RigViewResidual(p, v).norm(), delta);
  for (const RigPlaneTerm& t : p.planes) cost += RigHuberCost(RigPlaneResidual(p, t).norm(), delta);
  return cost;
}

// Gauss-Newton's normal equations at the current estimate (robust weights included).
void RigLinearize(const RigProblem& p, double delta, Eigen::MatrixXd* h, Eigen::VectorXd* g) {
  h->setZero(p.Size(), p.Size());
  g->setZero(p.Size());
  for (const RigPriorTerm& t : p.priors) {
    // r = Log(P⁻¹ x): x Exp(δ) gives r + Jr⁻¹(r) δ.
    const Vec6 error = RigPriorError(p, t);
    const Vec6 e = t.whitening * error;
    const double w = RigHuberWeight(e.norm(), delta);
    const Mat6 j = t.whitening * RightJacobianInverse(error);
    const int block = p.CameraOffset(t.camera);
    g->segment<6>(block) += w * j.transpose() * e;
    h->block<6, 6>(block, block) += w * j.transpose() * j;
  }
  for (const RigViewTerm& v : p.views) {
    const Vec6 error = RigViewError(p, v);
    const Vec6 e = v.whitening * error;
    const double w = RigHuberWeight(e.norm(), delta);
    // r = Log(M⁻¹ x T): x Exp(δx) T = x T Exp(Ad(T⁻¹) δx), and T Exp(δt).
    const Mat6 jr_inverse = v.whitening * RightJacobianInverse(error);
    Eigen::Matrix<double, 6, 12> j;
    j.leftCols<6>() = jr_inverse * AdjointSE3(p.lidar_from_board[v.capture].inverse());
    j.rightCols<6>() = jr_inverse;
    const int blocks[2] = {p.CameraOffset(v.camera), p.CaptureOffset(v.capture)};
    for (int a = 0; a < 2; ++a) {
      g->segment<6>(blocks[a]) += w * j.middleCols<6>(6 * a).transpose() * e;
      for (int b = 0; b < 2; ++b)
        h->block<6, 6>(blocks[a], blocks[b]) +=
            w * j.middleCols<6>(6 * a).transpose() * j.middleCols<6>(6 * b);
    }
  }
  for (const RigPlaneTerm& t : p.planes) {
    const Pose& board = p.lidar_from_board[t.capture];
    const Vec3 e3 = RigPlaneResidual(p, t);
    const double w = RigHuberWeight(e3.norm(), delta);
    // T Exp([ρ; φ]): R ← R Exp(φ), t ← t + R ρ. n = s R e_z, d = -n·t.
    const Mat3& r = board.linear();
    const Vec3 n = t.sign * r.col(2);
    const Mat3 dn_dphi = -t.sign * r * Skew(Vec3::UnitZ());
    Eigen::Matrix<double, 4, 6> dc = Eigen::Matrix<double, 4, 6>::Zero();
    dc.block<3, 3>(0, 3) = dn_dphi;
    dc.block<1, 3>(3, 0) = -n.transpose() * r;
    dc.block<1, 3>(3, 3) = -board.translation().transpose() * dn_dphi;
    const Eigen::Matrix<double, 3, 6> j = t.whitening * t.basis.transpose() * dc;
    const int block = p.CaptureOffset(t.capture);
    g->segment<6>(block) += w * j.transpose() * e3;
    h->block<6, 6>(block, block) += w * j.transpose() * j;
  }
}

void RigApplyStep(const Eigen::VectorXd& step, RigProblem* p) {
  for (int c = 0; c < p->cameras; ++c)
    p->cam_from_lidar[c] = p->cam_from_lidar[c] * ExpSE3(step.segment<6>(p->CameraOffset(c)));
  for (size_t k = 0; k < p->lidar_from_board.size(); ++k)
    p->lidar_from_board[k] =
        p->lidar_from_board[k] * ExpSE3(step.segment<6>(p->CaptureOffset(static_cast<int>(k))));
}

// The problem's terms from the captures; *why when they do not determine every camera.
std::optional<RigProblem> BuildRigProblem(const std::vector<RigCapture>& captures,
                                          const std::vector<Pose>& initial,
                                          const std::vector<std::optional<RigCameraPrior>>& priors,
                                          std::string* why) {
  RigProblem p;
  p.cameras = static_cast<int>(initial.size());
  p.cam_from_lidar = initial;
  if (!priors.empty() && priors.size() != initial.size())
    return *why = std::to_string(priors.size()) + " priors for " + std::to_string(initial.size()) +
                  " cameras",
           std::nullopt;
  for (size_t c = 0; c < priors.size(); ++c) {
    if (!priors[c]) continue;
    const auto whitening = RigWhitening<6>(priors[c]->covariance);
    if (!whitening)
      return *why = "camera " + std::to_string(c) + "'s prior covariance is not positive definite",
             std::nullopt;
    p.priors.push_back({static_cast<int>(c), priors[c]->cam_from_lidar.inverse(), *whitening});
  }
  std::vector<int> planes_per_camera(p.cameras, 0);
  for (const RigCapture& capture : captures) {
    if (capture.views.empty()) continue;
    const int k = static_cast<int>(p.lidar_from_board.size());
    const RigBoardView& first = capture.views.front();
    if (first.camera < 0 || first.camera >= p.cameras)
      return *why = capture.id + ": camera index " + std::to_string(first.camera) +
                    " outside the rig's " + std::to_string(p.cameras),
             std::nullopt;
    // The board where its first camera puts it under that camera's initial pose.
    p.lidar_from_board.push_back(initial[first.camera].inverse() * first.cam_from_board);
    for (const RigBoardView& view : capture.views) {
      if (view.camera < 0 || view.camera >= p.cameras)
        return *why = capture.id + ": camera index " + std::to_string(view.camera) +
                      " outside the rig's " + std::to_string(p.cameras),
               std::nullopt;
      const auto whitening = RigWhitening<6>(view.pose_covariance);
      if (!whitening)
        return *why = capture.id + ": camera " + std::to_string(view.camera) +
                      "'s board pose covariance is not positive definite",
               std::nullopt;
      p.views.push_back({view.camera, k, view.cam_from_board.inverse(), *whitening});
      if (capture.lidar_plane) ++planes_per_camera[view.camera];
    }
    if (!capture.lidar_plane) continue;
    RigPlaneTerm term;
    term.capture = k;
    term.measured = capture.lidar_plane->Coefficients();
    term.basis = TangentToPlaneCoefficients(capture.lidar_plane->normal);
    const auto whitening =
        RigWhitening<3>(term.basis.transpose() * capture.lidar_covariance * term.basis);
    if (!whitening)
      return *why = capture.id + ": the LiDAR plane's covariance is not positive definite",
             std::nullopt;
    term.whitening = *whitening;
    term.sign = RigBoardPlane(p.lidar_from_board[k], 1.0).dot(term.measured) >= 0.0 ? 1.0 : -1.0;
    p.planes.push_back(term);
  }
  for (int c = 0; c < p.cameras; ++c)
    if (planes_per_camera[c] < 3 && !(c < static_cast<int>(priors.size()) && priors[c]))
      return *why = "camera " + std::to_string(c) + " sees the board in " +
                    std::to_string(planes_per_camera[c]) +
                    " capture(s) with a LiDAR plane; at least 3 are needed",
             std::nullopt;
  return p;
}

}  // namespace

bool RigSolverOptions::Check(std::string* why) const {
  if (!(huber_delta > 0.0)) return *why = "huber_delta must be > 0 (standard deviations)", false;
  if (max_iterations < 1) return *why = "max_iterations must be >= 1", false;
  if (!(min_step > 0.0)) return *why = "min_step must be > 0", false;
  return true;
}

namespace {

// χ² medians: what a term's squared whitened norm is, half of the time, when its covariance is
// right.
constexpr double kChiSquare6Median = 5.35, kChiSquare3Median = 2.37;

double RigMedian(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

// Gauss-Newton from p's estimate, with backtracking: a step that raises the robust cost is halved
// (at most 8 times); converged when none lowers it, the step is negligible or the cost no longer
// moves. False, with *why, when the normal equations are singular.
bool RigGaussNewton(const RigSolverOptions& options, RigProblem* p, RigSolution* solution,
                    std::string* why) {
  double cost = RigCost(*p, options.huber_delta);
  Eigen::MatrixXd h;
  Eigen::VectorXd g;
  for (int it = 0; it < options.max_iterations; ++it) {
    RigLinearize(*p, options.huber_delta, &h, &g);
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(h);
    const Eigen::VectorXd step = ldlt.solve(-g);
    if (ldlt.info() != Eigen::Success || !step.allFinite())
      return *why = "the rig's normal equations are singular", false;
    ++solution->iterations;
    double scale = 1.0;
    bool lowered = false;
    const double cost_before = cost;
    for (int halving = 0; halving <= 8 && !lowered; ++halving, scale *= 0.5) {
      RigProblem trial = *p;
      RigApplyStep(scale * step, &trial);
      const double trial_cost = RigCost(trial, options.huber_delta);
      if (trial_cost <= cost) {
        *p = std::move(trial);
        cost = trial_cost;
        lowered = true;
      }
    }
    solution->converged =
        !lowered || step.norm() < options.min_step || cost_before - cost <= 1e-12 * cost_before;
    if (solution->converged) break;
  }
  solution->cost = cost;
  return true;
}

// The board views' variance factor: the median of their squared whitened norms against χ²₆'s,
// robust to the few boards whose PnP is off (those the Huber kernel down-weights).
double RigViewsFactor(const RigProblem& p) {
  std::vector<double> ratios;
  for (const RigViewTerm& v : p.views)
    ratios.push_back(RigViewResidual(p, v).squaredNorm() / kChiSquare6Median);
  return RigMedian(std::move(ratios));
}

// The whole problem's: the same median over every term.
double RigProblemFactor(const RigProblem& p) {
  std::vector<double> ratios;
  for (const RigViewTerm& v : p.views)
    ratios.push_back(RigViewResidual(p, v).squaredNorm() / kChiSquare6Median);
  for (const RigPlaneTerm& t : p.planes)
    ratios.push_back(RigPlaneResidual(p, t).squaredNorm() / kChiSquare3Median);
  for (const RigPriorTerm& t : p.priors)
    ratios.push_back((t.whitening * RigPriorError(p, t)).squaredNorm() / kChiSquare6Median);
  return RigMedian(std::move(ratios));
}

// The cameras' joint covariance: their block of H⁻¹ (the boards marginalised).
Eigen::MatrixXd RigCamerasCovariance(const RigProblem& p, double huber_delta) {
  Eigen::MatrixXd h;
  Eigen::VectorXd g;
  RigLinearize(p, huber_delta, &h, &g);
  const int camera_size = 6 * p.cameras;
  const Eigen::MatrixXd selector = Eigen::MatrixXd::Identity(p.Size(), camera_size);
  const Eigen::MatrixXd covariance =
      Eigen::LDLT<Eigen::MatrixXd>(h).solve(selector).topRows(camera_size);
  return 0.5 * (covariance + covariance.transpose());
}

}  // namespace

std::optional<RigSolution> SolveRig(const std::vector<RigCapture>& captures,
                                    const std::vector<Pose>& initial,
                                    const RigSolverOptions& options, std::string* why,
                                    const std::vector<std::optional<RigCameraPrior>>& priors) {
  if (!options.Check(why)) return std::nullopt;
  if (initial.empty()) return *why = "a rig needs at least one camera", std::nullopt;
  std::optional<RigProblem> problem = BuildRigProblem(captures, initial, priors, why);
  if (!problem) return std::nullopt;
  RigProblem& p = *problem;
  RigSolution solution;
  solution.used_captures = static_cast<int>(p.lidar_from_board.size());
  // With priors, the cameras' board poses are the terms whose covariances are least to be
  // believed (PnP's covariance from the corners' spread leaves out the lens model's and the
  // print's errors): their covariances are scaled by their own variance factor, re-estimated
  // after each solve, a few times over. Never narrower than PnP says. Redundancy: the boards'
  // poses take 6 of each capture's view dimensions, the relative poses 6 per camera after the
  // first.
  const int view_redundancy = 6 * static_cast<int>(p.views.size()) -
                              6 * static_cast<int>(p.lidar_from_board.size()) - 6 * (p.cameras - 1);
  for (int round = 0; round < 4; ++round) {
    if (!RigGaussNewton(options, &p, &solution, why)) return std::nullopt;
    if (view_redundancy <= 0 || p.priors.empty()) break;
    const double factor = RigViewsFactor(p);
    if ((factor < 1.2 && factor > 1.0 / 1.2) ||
        (factor <= 1.0 && solution.view_variance_factor <= 1.0))
      break;
    const double applied = std::max(factor, 1.0 / solution.view_variance_factor);
    solution.view_variance_factor *= applied;
    for (RigViewTerm& v : p.views) v.whitening /= std::sqrt(applied);
  }
  solution.covariance = RigCamerasCovariance(p, options.huber_delta);
  // Measurements that disagree more than their covariances say widen σ (medians, so that the few
  // boards the Huber kernel down-weights do not set it).
  if (p.Measurements() > p.Size()) {
    solution.variance_factor = RigProblemFactor(p);
    if (solution.variance_factor > 1.0) solution.covariance *= solution.variance_factor;
  }
  solution.cam_from_lidar = p.cam_from_lidar;
  return solution;
}

std::optional<RigSolution> SolveRigFromCameras(const std::vector<RigCapture>& captures,
                                               const std::vector<RigCameraPrior>& cameras,
                                               const RigSolverOptions& options, std::string* why,
                                               int* shared_captures) {
  std::vector<int> seen(cameras.size(), 0), shared(cameras.size(), 0);
  std::vector<RigCapture> ties;
  for (const RigCapture& capture : captures) {
    for (const RigBoardView& view : capture.views)
      if (view.camera >= 0 && view.camera < static_cast<int>(cameras.size())) ++seen[view.camera];
    if (capture.views.size() < 2) continue;  // one camera's board adds nothing to its prior
    for (const RigBoardView& view : capture.views)
      if (view.camera >= 0 && view.camera < static_cast<int>(cameras.size())) ++shared[view.camera];
    RigCapture tie = capture;
    tie.lidar_plane.reset();
    ties.push_back(std::move(tie));
  }
  if (shared_captures) *shared_captures = static_cast<int>(ties.size());
  std::vector<Pose> initial;
  std::vector<std::optional<RigCameraPrior>> priors;
  for (size_t c = 0; c < cameras.size(); ++c) {
    initial.push_back(cameras[c].cam_from_lidar);
    RigCameraPrior prior = cameras[c];
    if (seen[c] > 0) prior.covariance *= 1.0 + static_cast<double>(shared[c]) / seen[c];
    priors.push_back(prior);
  }
  return SolveRig(ties, initial, options, why, priors);
}

RelativePose CameraFromCamera(const RigSolution& solution, int to, int from) {
  const Pose& x_to = solution.cam_from_lidar[to];
  const Pose& x_from = solution.cam_from_lidar[from];
  RelativePose relative;
  relative.to_from_from = x_to * x_from.inverse();
  // x_to Exp(δt) (x_from Exp(δf))⁻¹ = y Exp(Ad(x_from) (δt - δf)) to first order.
  const Eigen::MatrixXd& s = solution.covariance;
  const Mat6 difference = s.block<6, 6>(6 * to, 6 * to) + s.block<6, 6>(6 * from, 6 * from) -
                          s.block<6, 6>(6 * to, 6 * from) - s.block<6, 6>(6 * from, 6 * to);
  const Mat6 adjoint = AdjointSE3(x_from);
  relative.covariance = adjoint * difference * adjoint.transpose();
  return relative;
}

}  // namespace calibench
