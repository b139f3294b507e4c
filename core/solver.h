// Extrinsic from plane correspondences: the closed-form initial guess and Ca²Lib's joint
// Gauss-Newton on SE(3) with a Huber kernel (Eq. (13)–(14)), as a steppable object so that a GUI
// can show every iteration.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/geometry.h"

namespace calibench {

// One accepted pair: the board plane seen by both sensors.
struct PlanePair {
  std::string id;
  Plane lidar_plane;   // LiDAR frame, normal towards the LiDAR (d > 0)
  Plane camera_plane;  // camera frame, normal towards the camera (d > 0)
  // Covariances of (n, d) (rank 3). Used by the weighted method; zero = unknown.
  Mat4 lidar_covariance = Mat4::Zero();
  Mat4 camera_covariance = Mat4::Zero();
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
  int max_iterations = 50;       // Gauss-Newton iterations
  double step_tolerance = 1e-9;  // stop when |delta| (m, rad) falls below this
  // A direction of the information matrix whose eigenvalue is below this fraction of the largest
  // is reported weak (about 2 degrees of spread of the board normals around it).
  double weak_eigenvalue_ratio = 1e-3;
  bool Check(std::string* why) const;
};

struct IterationReport {
  int iteration = 0;       // 0 = the initial estimate
  double cost = 0.0;       // sum of Huber costs, Eq. (14)
  double step_norm = 0.0;  // |delta|
  Pose cam_from_lidar = Pose::Identity();
};

struct ObservabilityReport {
  Vec6 eigenvalues = Vec6::Zero();           // of the information matrix JᵀWJ, ascending
  std::vector<std::string> weak_directions;  // in words, camera frame
  bool well_constrained = false;
};

struct SolverResult {
  Pose cam_from_lidar = Pose::Identity();
  Mat6 covariance = Mat6::Zero();  // right perturbation of cam_from_lidar, [rho; phi]
  bool converged = false;
  int iterations = 0;
  std::vector<double> cost_history;    // one entry per iteration, the initial cost first
  std::vector<Vec4> residuals;         // per pair, Eq. (6) at the solution
  std::vector<double> robust_weights;  // per pair, Huber IRLS weight at the solution (0 = gated)
  ObservabilityReport observability;
};

// Closed form from the planes alone: rotation aligning the normals (Kabsch/SVD), then the
// translation from n_c·t = d_l − d_c by least squares (minimum-norm along unobservable
// directions). nullopt with *why when fewer than two pairs or all normals parallel.
std::optional<Pose> InitialGuessFromPlanes(const std::vector<PlanePair>& pairs, std::string* why);

// Observability of the extrinsic from a set of planes at an estimate.
ObservabilityReport AnalyseObservability(const Mat6& information, const Pose& cam_from_lidar,
                                         double weak_eigenvalue_ratio);

// Σ Jᵢᵀ Sᵢ⁻¹ Jᵢ of the weighted residual (SolverMethod::kWeightedMl) at cam_from_lidar, with each
// pair's own covariances, no robust weights and no variance factor. With noise-free planes and the
// features' Cramér–Rao covariances this is the Fisher information of the extrinsic.
Mat6 WeightedPlaneInformation(const std::vector<PlanePair>& pairs, const Pose& cam_from_lidar);

// Eq. (14) solved by Gauss-Newton with iteratively reweighted Huber weights.
class PlaneAlignmentSolver {
 public:
  PlaneAlignmentSolver(std::vector<PlanePair> pairs, const SolverOptions& options,
                       const Pose& initial_cam_from_lidar);

  // One Gauss-Newton iteration; false once converged or out of iterations.
  bool Step();
  bool Done() const { return done_; }
  const Pose& Estimate() const { return cam_from_lidar_; }
  const std::vector<IterationReport>& History() const { return history_; }

  // Iterates to the end, calling on_iteration after each step (and once for the start).
  SolverResult Run(const std::function<void(const IterationReport&)>& on_iteration = {});
  // Covariance, residuals, weights and observability at the current estimate.
  SolverResult Summarize() const;

 private:
  struct Linearization {
    Mat6 information = Mat6::Zero();  // JᵀWJ
    Vec6 gradient = Vec6::Zero();     // JᵀWe
    double cost = 0.0;
    double weighted_squared_error = 0.0;
  };
  Linearization Linearize(const Pose& cam_from_lidar) const;
  double HuberDelta() const;  // huber_delta or whitened_huber_delta, by method
  double RobustWeight(double error_norm) const;
  double RobustCost(double error_norm) const;

  // One round of outlier gating (SolverOptions::outlier_gate); true when the gated set changed.
  bool GateOutliers();

  std::vector<PlanePair> pairs_;
  std::vector<char> gated_;  // per pair: dropped as an outlier
  int gating_rounds_ = 0;
  int iteration_budget_ = 0;  // history size at which Step stops
  SolverOptions options_;
  Pose cam_from_lidar_;
  std::vector<IterationReport> history_;
  bool done_ = false;
  bool converged_ = false;
};

}  // namespace calibench
