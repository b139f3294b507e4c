// Extrinsic cam_from_lrf from 2D scan points that must lie on camera-frame planes.
//
// Both LRF methods reduce to point-on-plane constraints: a scan corner on a camera line is on
// the two planes that make the line (paper Eq. (7)–(9)), a scan point of a face is on the face's
// plane, a scan point on a checkerboard is on the board's plane (Zhang & Pless 2004).
//  - paper-linear: Eq. (9)–(11), the 9 unknowns H = [r1 r2 t] by linear least squares from the
//    corner rows, r3 = r1 × r2, then the nearest rotation. The baseline.
//  - refined: Gauss-Newton on SE(3) (right perturbation, [rho; phi]) over every scan point of every
//    face (point-to-plane), Huber kernel, seeded by paper-linear; covariance and observability as
//    for the 3D method. Directions the data does not constrain are held at the seed (the step is
//    solved in the observable subspace) and reported weak.
//  - adaptive: Algorithm 1: add observations until the Eq. (12) point-to-line error of the newest
//    observation under the current estimate falls below a threshold.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/estimation/uncertainty.h"
#include "core/lrf_data/types.h"

namespace calibench {

// One scan point (LRF frame, z = 0) that must lie on a camera-frame plane.
struct PointOnPlane {
  Vec2 point = Vec2::Zero();
  Plane plane;
  int observation = 0;  // index into the observation list (for per-observation residuals)
};

enum class LrfMethod { kPaperLinear, kRefined };
std::string LrfMethodName(LrfMethod method);  // "paper-linear", "refined"
std::optional<LrfMethod> ParseLrfMethod(const std::string& name);

struct LrfSolverOptions {
  LrfMethod method = LrfMethod::kRefined;
  double huber_delta_m = 0.03;  // Huber threshold on the point-to-plane distance (metres)
  int max_iterations = 50;
  double step_tolerance = 1e-10;  // stop when |delta| (m, rad) falls below this
  // Eigenvalues of JᵀWJ below this fraction of the largest are weak (held at the seed, reported).
  double weak_eigenvalue_ratio = 1e-4;
  bool Check(std::string* why) const;
};

struct LrfSolution {
  bool ok = false;
  std::string reason;  // why not ok, in words
  LrfMethod method = LrfMethod::kRefined;
  Pose cam_from_lrf = Pose::Identity();
  Mat6 covariance = Mat6::Zero();  // right perturbation of cam_from_lrf, [rho; phi]
  ObservabilityReport observability;
  bool converged = false;
  int iterations = 0;
  std::vector<double> cost_history;      // refined: per iteration, the seed's cost first
  std::vector<IterationReport> history;  // refined: estimate per iteration (cam_from_lidar field)
  // Per observation: Eq. (12) mean corner-to-line distance (metres) and, for refined, the RMS
  // point-to-plane distance of its scan points and the mean Huber weight.
  std::vector<double> point_to_line_m;
  std::vector<double> point_to_plane_rms_m;
  std::vector<double> robust_weights;
  double mean_point_to_line_m = 0.0;  // Eq. (12) over all observations
};

// F on planes 0 and 1, G on 1 and 2, H on 2 and 0: six rows per observation (Eq. (9)).
std::vector<PointOnPlane> CornerConstraints(const std::vector<LrfObservation>& observations);
// Every scan point of face k on camera plane k.
std::vector<PointOnPlane> FaceConstraints(const std::vector<LrfObservation>& observations);
// Every board scan point on the camera board plane.
std::vector<PointOnPlane> BoardConstraints(const std::vector<LrfBoardObservation>& observations);

// Eq. (10)–(11): linear least squares for [r11 r12 t1 r21 r22 t2 r31 r32 t3], r3 = r1 × r2, then
// the nearest rotation (the scale of r1, r2 is re-estimated so that t keeps its units). nullopt
// with *why when the system is rank-deficient (fewer than two usable observations, parallel
// faces).
std::optional<Pose> SolveLinearPointOnPlane(const std::vector<PointOnPlane>& constraints,
                                            std::string* why);

// Eq. (12) for one observation: mean distance (metres) of the corners F, G, H, moved into the
// camera frame, to the lines AB, AC, AD.
double PointToLineError(const LrfObservation& observation, const Pose& cam_from_lrf);

// Point-to-plane Gauss-Newton, steppable (the GUI shows every iteration).
class PointPlaneSolver {
 public:
  PointPlaneSolver(std::vector<PointOnPlane> constraints, const LrfSolverOptions& options,
                   const Pose& initial_cam_from_lrf);
  bool Step();  // one iteration; false once converged or out of iterations
  bool Done() const { return done_; }
  const Pose& Estimate() const { return cam_from_lrf_; }
  const std::vector<IterationReport>& History() const { return history_; }
  // Iterates to the end; fills covariance, observability, history, per-observation RMS/weights
  // (sized by the largest observation index + 1).
  LrfSolution Run();
  LrfSolution Summarize() const;

 private:
  std::vector<PointOnPlane> constraints_;
  LrfSolverOptions options_;
  Pose cam_from_lrf_;
  std::vector<IterationReport> history_;
  bool done_ = false;
  bool converged_ = false;
};

// The three-face method: paper-linear, or refined seeded by paper-linear (or by `initial` when
// given and the linear system is rank-deficient). Observations whose features are not ok are
// skipped; fewer than two usable ones fail with a reason. Per-observation figures are indexed like
// `observations`.
LrfSolution SolveLrf(const std::vector<LrfObservation>& observations,
                     const LrfSolverOptions& options, const std::optional<Pose>& initial = {});

struct AdaptiveLrfResult {
  LrfSolution solution;
  int observations_used = 0;
  bool reached_threshold = false;
  // Eq. (12) error of observation k (k ≥ 2) under the estimate from observations 0..k-1.
  std::vector<double> newest_error_m;
};
// Algorithm 1 over `sequence` in order, with `options.method` for every solve.
AdaptiveLrfResult SolveLrfAdaptive(const std::vector<LrfObservation>& sequence,
                                   double error_threshold_m, const LrfSolverOptions& options);

// Zhang & Pless: linear seed from the board rows (or `initial`), then the same refinement.
LrfSolution SolveLrfBoard(const std::vector<LrfBoardObservation>& observations,
                          const LrfSolverOptions& options, const std::optional<Pose>& initial = {});

}  // namespace calibench
