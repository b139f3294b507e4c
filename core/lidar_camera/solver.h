// Extrinsic from plane correspondences: the closed-form initial guess and Ca²Lib's joint
// Gauss-Newton on SE(3) with a Huber kernel (Eq. (13)–(14)), as a steppable object so that a GUI
// can show every iteration.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/estimation/uncertainty.h"
#include "core/geometry/geometry.h"
#include "core/target/board_edges.h"

namespace calibench {

// One accepted pair: the board plane seen by both sensors.
struct PlanePair {
  std::string id;
  Plane lidar_plane;   // LiDAR frame, normal towards the LiDAR (d > 0)
  Plane camera_plane;  // camera frame, normal towards the camera (d > 0)
  // Covariances of (n, d) (rank 3). Used by the weighted method; zero = unknown.
  Mat4 lidar_covariance = Mat4::Zero();
  Mat4 camera_covariance = Mat4::Zero();
  // d(n, d)/db of the LiDAR plane for a range offset b (LidarPlaneFit::range_offset_jacobian);
  // zero = unknown (the pair then says nothing about b).
  Vec4 lidar_range_offset_jacobian = Vec4::Zero();
  // Board-edge constraint (SolverOptions::use_board_edges): the rings' crossings of the sheet's
  // edge (LiDAR frame), the camera's board pose and the sheet's half size; zero size = none.
  std::vector<LidarEdgePoint> lidar_edges = {};
  Pose camera_from_board = Pose::Identity();
  Vec2 sheet_half_size_m = Vec2::Zero();
  // Covariance of camera_from_board (right perturbation, [rho; phi]; the PnP's); zero = unknown.
  // Every edge point of the pair shares that pose's in-plane error (SolverOptions::
  // edge_board_pose_uncertainty).
  Mat6 camera_pose_covariance = Mat6::Zero();
};

enum class SolverMethod {
  kCa2libGn,    // the paper: unweighted plane-to-plane error, Eq. (6), Huber on |e|
  kWeightedMl,  // residuals whitened by both planes' covariances, Huber on the Mahalanobis norm
  kKim,         // Kim et al. 2020, the paper's baseline: InitialGuessFromPlanes, no refinement
};
std::string SolverMethodName(SolverMethod method);  // "ca2lib-gn", "weighted-ml", "kim"
std::optional<SolverMethod> ParseSolverMethod(const std::string& name);

struct SolverOptions {
  SolverMethod method = SolverMethod::kWeightedMl;
  double huber_delta = 0.1;  // Huber threshold on |e_p| (Eq. (6) mixes unitless and metres)
  // kWeightedMl: Huber threshold on the whitened residual, in standard deviations.
  double whitened_huber_delta = 3.0;
  // kWeightedMl: once converged, the worst pair whose Mahalanobis residual exceeds outlier_gate
  // robust scales is given weight 0 and the solve continues (up to three rounds; a gated pair
  // whose residual falls back inside the gate returns). The robust scale is the median
  // Mahalanobis norm over its χ(3) expectation (1.54), at least 1: on real sensors, whose plane
  // residuals exceed the propagated noise, the gate widens with them. 0 = no gating.
  double outlier_gate = 4.0;
  // kWeightedMl: also estimate a LiDAR range offset b (metres; measured range = true range + b),
  // a constant error of the sensor's range calibration, from how each pair's plane moves with it.
  bool estimate_range_offset = false;
  // kWeightedMl: each ring's crossing of the sheet's edge must lie on the edge the camera sees
  // (pairs with a known sheet size), whitened by the crossing's uncertainty along the ring and
  // edge_floor_sigma_m (cut accuracy, beam width), with the Huber kernel of the planes.
  bool use_board_edges = true;
  double edge_floor_sigma_m = 0.003;
  // With board edges: the camera's board pose is uncertain too (PlanePair::
  // camera_pose_covariance), and its in-plane error (the sheet's position and turn within its
  // plane) moves every edge point of the pair alike. Treated as independent per point, a pair's
  // tens of edge points claimed that error tens of times over: on simulated OS0-128 data the
  // pairs' scatter came out 3x the model's σ. The pose error is a nuisance of the pair with the
  // PnP covariance as its prior, eliminated in closed form like the dilation.
  bool edge_board_pose_uncertainty = true;
  // With board edges: also estimate, per pair, how much larger than the sheet the LiDAR sees it
  // (metres per side). A beam whose footprint only partly covers the board still returns the
  // board's range, so a real sensor's ring ends reach past the edge by about half the footprint,
  // which grows with the range (7 mm on average for the VLP-16 in acfr-vlp16-chessboard);
  // unmodelled, it pushes every edge point outwards. Each pair's dilation is eliminated in closed
  // form (variable projection), so it costs one edge residual per pair.
  bool estimate_edge_dilation = true;
  // kWeightedMl: report the larger of the model's covariance and the pairs' cluster-robust
  // (sandwich) covariance along every direction (see SolverResult::covariance_inflation).
  bool sandwich_covariance = true;
  // kWeightedMl: where the leave-one-pair-out (jackknife) scatter of the estimate shows the model
  // violated, no narrower than the jackknife widened for the few pairs it comes from (see
  // solver_summary.cpp). Where the sandwich needs more pairs than parameters, the jackknife
  // already speaks from 4 pairs on.
  bool jackknife_covariance = true;
  // kWeightedMl: what is known of the LiDAR's range offset before the data (1σ, metres; 0 = no
  // prior). Estimated (estimate_range_offset), it is a pseudo-observation b = 0 ± σ; left out,
  // the pose's covariance carries the bias such an offset would cause (σ² g gᵀ, g the pose's
  // response to the offset): a spinning LiDAR's factory range calibration is good to about
  // 1-3 cm, and boards seen from one side cannot tell that from the translation.
  double range_offset_prior_sigma_m = 0.0;
  // Above this standard deviation (metres) the offset is reported as not determined by the data
  // (a weak direction).
  double range_offset_max_sigma_m = 0.01;
  // kWeightedMl without estimate_range_offset: a score test at the solution asks whether the data
  // shows a range offset all the same; one beyond this many standard deviations (and determined
  // within range_offset_max_sigma_m) is reported (SolverResult::unmodelled_range_offset).
  double range_offset_significance = 3.0;
  // Convergence, by Ceres's three tests: the solve (each round of it, see GateOutliers and
  // EstimateVarianceComponents) stops when the last step changed the cost by at most
  // function_tolerance of itself, when the largest gradient component is within
  // gradient_tolerance, or when the step is within parameter_tolerance · (|x| + parameter_
  // tolerance), x = [Log(cam_from_lidar); b]. At 1e-6 of a whitened cost the pose is within about
  // 1% of its σ of the minimum. SolverResult::termination says which test ended the solve.
  double function_tolerance = 1e-6;
  double gradient_tolerance = 1e-10;
  double parameter_tolerance = 1e-8;
  // Gauss-Newton iterations per round: a safety net (a well-posed solve converges in under ten);
  // reaching it means the solve did not converge, and the summary says so.
  int max_iterations = 100;
  // A pair whose robust weight at the solution is below this counts for nothing (the outlier
  // gate's pairs have 0, Huber's far tails come close): accepted, but in effect left out, and
  // reported so (the summary, the result's "down_weighted", the workbench's pair list).
  double negligible_weight = 0.05;
  // A direction of the information matrix whose eigenvalue is below this fraction of the largest
  // is reported weak (about 2 degrees of spread of the board normals around it).
  double weak_eigenvalue_ratio = 1e-3;
  bool Check(std::string* why) const;
};

// The estimated LiDAR range offset with what the data says about it: its standard deviation and
// its correlation with the camera-frame translation (b and the translation both move the planes'
// distances; boards at one distance and angle cannot tell them apart).
struct RangeOffsetEstimate {
  double value_m = 0.0;
  double sigma_m = 0.0;
  Vec3 correlation_with_translation = Vec3::Zero();  // camera x, y, z
  // sigma below SolverOptions::range_offset_max_sigma_m. A high correlation alone is no failure:
  // it shows in the translation's (marginal) standard deviation.
  bool well_determined = false;
  bool operator==(const RangeOffsetEstimate&) const = default;
};

// How much larger than the sheet the LiDAR sees it, per side (SolverOptions::
// estimate_edge_dilation): the mean over the pairs, its standard error and the pairs' spread.
struct EdgeDilationEstimate {
  double value_m = 0.0;
  double sigma_m = 0.0;
  double spread_m = 0.0;
  bool operator==(const EdgeDilationEstimate&) const = default;
};

struct SolverResult {
  SolverMethod method = SolverMethod::kWeightedMl;  // the method that produced it
  Pose cam_from_lidar = Pose::Identity();
  Mat6 covariance = Mat6::Zero();  // right perturbation of cam_from_lidar, [rho; phi]
  bool converged = false;          // termination.Converged()
  Termination termination;         // which test ended the solve
  int iterations = 0;
  std::vector<double> cost_history;  // one entry per iteration, the initial cost first
  // The first entry of cost_history comparable with the last: the iteration the weights last
  // changed at (IterationReport::reweighted), 0 when they never did.
  int cost_comparable_from = 0;
  std::vector<Vec4> residuals;         // per pair, Eq. (6) at the solution
  std::vector<double> robust_weights;  // per pair, Huber IRLS weight at the solution (0 = gated)
  double negligible_weight = SolverOptions{}.negligible_weight;  // the options' threshold
  // Whether the solved pair `index` (into robust_weights) was down-weighted to nothing.
  bool DownWeighted(size_t index) const {
    return index < robust_weights.size() && robust_weights[index] < negligible_weight;
  }
  ObservabilityReport observability;
  std::optional<RangeOffsetEstimate> range_offset;  // SolverOptions::estimate_range_offset
  // Not estimated, yet significant in the data (SolverOptions::range_offset_significance): the
  // offset one Gauss-Newton step from the solution would estimate, with its standard deviation.
  // The pose above does not include it; estimating it would move the pose.
  std::optional<RangeOffsetEstimate> unmodelled_range_offset;
  int num_edge_residuals = 0;  // board-edge points used (use_board_edges)
  // Per pair (as robust_weights), its board-edge points used; all 0 where the method uses none.
  std::vector<int> pair_edge_points;
  bool edges_in_model = false;  // the method and options use board edges (weighted-ml, edges on)
  std::optional<EdgeDilationEstimate> edge_dilation;  // estimate_edge_dilation, with edges
  // A-posteriori variance factors of the planes' and the edges' residuals (kWeightedMl; 1 = their
  // noise models held; for ca2lib-gn the planes' noise variance itself).
  double plane_variance_factor = 1.0;
  double edge_variance_factor = 1.0;
  // How much the pairs' spread widened the model's covariance (the largest variance ratio, ≥ 1;
  // SolverOptions::sandwich_covariance). Near 1: the noise models hold.
  double covariance_inflation = 1.0;
  // The pose's covariance under the noise models alone (the variance factor applied, before the
  // pairs' spread widened it): with `covariance`, how the widening is shaped, direction by
  // direction (guidance discounts a new pair's information by it).
  Mat6 model_covariance = Mat6::Zero();
  // The jackknife (SolverOptions::jackknife_covariance): the pairs it was computed over (0 = not
  // computed: too few pairs, or a pair whose absence leaves the pose undetermined) and the
  // standard deviations of the pairs' scatter it shows, free of the pairs' leverage (camera
  // axes; metres, degrees), so that a stop rule can ask whether the leave-one-out spread agrees
  // with the reported σ.
  int jackknife_pairs = 0;
  Vec3 jackknife_sigma_t_m = Vec3::Zero();
  Vec3 jackknife_sigma_r_deg = Vec3::Zero();
  // The pairs' scatter exceeded the model's (its per-pair errors are larger than its features'
  // noise says), so the reported covariance is the jackknife's, widened for the few pairs.
  bool jackknife_widened = false;
  std::string jackknife_skipped;  // why it did not run, in words ("" when it ran)
  // The part of `covariance` that the camera's intrinsics' covariance contributes (zero: none
  // known; AddIntrinsicsUncertainty): it does not shrink with more pairs.
  Mat6 intrinsics_covariance = Mat6::Zero();
};

// The LiDAR plane the board really has under a range offset b: the fitted one moved back by
// b · d(n, d)/db (first order; the offset is centimetres against metres of range).
Plane CorrectedLidarPlane(const PlanePair& pair, double range_offset_m);

// Closed form from the planes alone: rotation aligning the normals (Kabsch/SVD), then the
// translation from n_c·t = d_l − d_c by least squares (minimum-norm along unobservable
// directions). nullopt with *why when fewer than two pairs or all normals parallel.
std::optional<Pose> InitialGuessFromPlanes(const std::vector<PlanePair>& pairs, std::string* why);

// Σ Jᵢᵀ Sᵢ⁻¹ Jᵢ of the weighted residual (SolverMethod::kWeightedMl) at cam_from_lidar, with each
// pair's own covariances, no robust weights and no variance factor. With noise-free planes and the
// features' Cramér–Rao covariances this is the Fisher information of the extrinsic.
Mat6 WeightedPlaneInformation(const std::vector<PlanePair>& pairs, const Pose& cam_from_lidar);

// The information JᵀWJ over the pose (right perturbation, [rho; phi]) that `pairs` contribute at
// cam_from_lidar under the solver's own residual model (weighted planes, and board edges with
// options.use_board_edges), their noise scaled by the given variance factors (a finished solve's
// SolverResult::plane_variance_factor / edge_variance_factor). At noise-free features the robust
// weights are 1: the expected information of planned board poses (core/guidance).
Mat6 ExpectedPoseInformation(const std::vector<PlanePair>& pairs, const Pose& cam_from_lidar,
                             const SolverOptions& options, double plane_variance_factor = 1.0,
                             double edge_variance_factor = 1.0);

// Eq. (14) solved by Gauss-Newton with iteratively reweighted Huber weights.
class PlaneAlignmentSolver {
 public:
  // initial_range_offset_m: where the range offset starts (SolverOptions::estimate_range_offset),
  // or its fixed value otherwise.
  PlaneAlignmentSolver(std::vector<PlanePair> pairs, const SolverOptions& options,
                       const Pose& initial_cam_from_lidar, double initial_range_offset_m = 0.0);

  // One Gauss-Newton iteration; false once converged or out of iterations.
  bool Step();
  bool Done() const { return done_; }
  const Pose& Estimate() const { return cam_from_lidar_; }
  double RangeOffset() const { return range_offset_m_; }
  const std::vector<IterationReport>& History() const { return history_; }

  // Iterates to the end, calling on_iteration after each step (and once for the start).
  SolverResult Run(const std::function<void(const IterationReport&)>& on_iteration = {});
  // Covariance, residuals, weights and observability at the current estimate.
  SolverResult Summarize() const;
  // Starts from known variance factors of the planes and the edges (a finished solve's
  // SolverResult::plane_variance_factor / edge_variance_factor), so that Summarize at its
  // estimate weighs the residuals as that solve did.
  void SetVarianceFactors(double plane_variance_factor, double edge_variance_factor);
  // JᵀWJ over the pose at the current estimate (robust weights and variance factors applied).
  Mat6 PoseInformation() const { return LinearizeHere().information.topLeftCorner<6, 6>(); }

 private:
  // Parameters [rho; phi; b]: the pose's right perturbation and the range offset. The offset's
  // row and column are always filled (kWeightedMl), so that an offset left out can be tested;
  // it moves only when estimated.
  static constexpr int kNumParameters = 7;
  static constexpr int kRangeOffset = 6;
  using Mat7 = Eigen::Matrix<double, kNumParameters, kNumParameters>;
  using Vec7 = Eigen::Matrix<double, kNumParameters, 1>;
  struct Linearization {
    Mat7 information = Mat7::Zero();  // JᵀWJ
    Vec7 gradient = Vec7::Zero();     // JᵀWe
    double cost = 0.0;
    double weighted_squared_error = 0.0;
    int num_residuals = 0;  // scalar residuals (3 per weighted pair, 4 per paper pair, 1 per edge)
    int num_edge_residuals = 0;
    int num_edge_dilations = 0;  // pairs whose edge dilation was eliminated (one residual each)
    std::vector<double> pair_dilations_m;  // those pairs' dilations
    Mat7 edge_information = Mat7::Zero();  // the edges' part of `information`
    std::vector<Vec7> pair_gradients;      // kWeightedMl: each used pair's share of `gradient`
    std::vector<Mat7> pair_informations;   // kWeightedMl: each used pair's share of `information`
    std::vector<double> pair_weights;      // per pair, its planes' robust weight (0 = gated)
    std::vector<int> pair_edge_points;     // per pair, its edge residuals
    double edge_weighted_squared_error = 0.0;
  };
  Linearization Linearize(const Pose& cam_from_lidar, double range_offset_m) const;
  Linearization LinearizeHere() const { return Linearize(cam_from_lidar_, range_offset_m_); }
  // Indices of the estimated parameters: the pose's six, then b when estimated.
  std::vector<int> ActiveParameters() const;
  // One board-edge point at a pose: its residual (signed distance outside the sheet's edge,
  // metres), σ and Jacobians over the parameters and over the camera's board pose.
  struct EdgeRow {
    double residual = 0.0;
    double sigma = 0.0;
    Eigen::Matrix<double, 1, kNumParameters> jacobian;
    Eigen::Matrix<double, 1, 6> board_pose_jacobian;
  };
  std::vector<EdgeRow> EdgeRows(const Pose& cam_from_lidar, double range_offset_m,
                                const PlanePair& pair) const;
  // Each row's weight (Huber over 1/σ²) about the pair's robust dilation, when it is estimated.
  std::vector<double> EdgeWeights(const std::vector<EdgeRow>& rows, bool with_dilation) const;
  // Adds one pair's board-edge residuals to `lin`.
  void LinearizeEdges(const Pose& cam_from_lidar, double range_offset_m, const PlanePair& pair,
                      Linearization* lin) const;
  double HuberDelta() const;  // huber_delta or whitened_huber_delta, by method
  double RobustWeight(double error_norm) const;
  double RobustCost(double error_norm) const;

  // Summarize's parts (solver_summary.cpp). The pose's covariance (and the offset's, when
  // estimated) from the information scaled by the variance factor, widened to the pairs' spread
  // (sandwich) where that is larger; *inflation gets the widening (1 = none).
  Mat7 Covariance(const Linearization& lin, const std::vector<int>& active, double variance_factor,
                  SolverResult* result) const;
  // The offset's correlation with the camera-frame translation R ρ (right perturbation).
  Vec3 OffsetCorrelation(const Mat7& joint_covariance) const;
  // The estimated range offset, or (not estimated) the score test's significant one.
  void ReportRangeOffset(const Linearization& lin, const Mat7& covariance, double variance_factor,
                         SolverResult* result) const;
  // Eigenvalues and weak directions of the geometry, plus what the offset and the redundancy say.
  ObservabilityReport Observability(const SolverResult& result, int redundancy) const;

  // One round of outlier gating (SolverOptions::outlier_gate); true when the gated set changed.
  bool GateOutliers();
  // One round of variance component estimation for planes and edges; true when the weights
  // changed enough to solve again.
  bool EstimateVarianceComponents();

  std::vector<PlanePair> pairs_;
  std::vector<char> gated_;  // per pair: dropped as an outlier
  int gating_rounds_ = 0;
  int iteration_budget_ = 0;  // history size at which Step stops
  SolverOptions options_;
  Pose cam_from_lidar_;
  double range_offset_m_ = 0.0;
  // Variance components (EstimateVarianceComponents): the planes' covariances and the edges'
  // variances are multiplied by these.
  double plane_variance_scale_ = 1.0;
  double edge_variance_scale_ = 1.0;
  int variance_component_rounds_ = 0;
  std::vector<IterationReport> history_;
  // The cost after `step` from the current estimate (right perturbation; the offset's entry).
  double CostAt(const Vec7& step) const;
  // Step's way on where no part of the Gauss-Newton step lowers the cost (its linearization at
  // `lin`, damped information `damped`, gᵀδ of the full step); the return as Step's.
  bool StepOutOfStall(const Linearization& lin, const Mat7& damped, double gradient_dot_step);
  // Ends the current round with `termination`, unless gating or variance components start
  // another (then the solve goes on).
  void FinishRound(const Termination& termination);

  bool done_ = false;
  Termination termination_;
};

}  // namespace calibench
