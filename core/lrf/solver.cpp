#include "core/lrf/solver.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/base/names.h"

namespace calibench {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

constexpr EnumName<LrfMethod> kLrfMethodNames[] = {{LrfMethod::kPaperLinear, "paper-linear"},
                                                   {LrfMethod::kRefined, "refined"}};

// Eq. (10)–(11) is declared rank-deficient when its condition number exceeds 1e7: exact
// degeneracies (parallel faces, a single pose, board normals without a component along one axis)
// give ratios near 1e-16; the test scenes of two to ten three-face poses give 5e-3 to 3e-2.
constexpr double kMinSingularValueRatio = 1e-7;

bool Usable(const LrfObservation& observation) {
  return observation.scan.ok && observation.depth.ok;
}

// The point-to-plane residual r = n·(R [x y 0]ᵀ + t) + d (metres) and, when jacobian is given,
// dr/d(delta) for the right perturbation cam_from_lrf·Exp([rho; phi]):
//   dr/drho = nᵀR,  dr/dphi = −nᵀR[p]x  (Exp(delta)·p ≈ p + rho + phi × p).
double PointOnPlaneResidual(const Pose& cam_from_lrf, const PointOnPlane& constraint,
                            Eigen::Matrix<double, 1, 6>* jacobian) {
  const Vec3 point(constraint.point.x(), constraint.point.y(), 0.0);
  if (jacobian) {
    const Eigen::RowVector3d normal_in_lrf =
        constraint.plane.normal.transpose() * cam_from_lrf.linear();
    jacobian->head<3>() = normal_in_lrf;
    jacobian->tail<3>() = -normal_in_lrf * Skew(point);
  }
  return constraint.plane.SignedDistance(cam_from_lrf * point);
}

struct Linearization {
  Mat6 information = Mat6::Zero();            // JᵀWJ
  Mat6 geometric_information = Mat6::Zero();  // JᵀJ (observability, unit weights)
  Vec6 gradient = Vec6::Zero();               // JᵀWr
  double cost = 0.0;                          // sum of Huber costs
  double weighted_squared_error = 0.0;        // sum of w r²
};

double HuberWeight(double residual, double delta) {
  const double magnitude = std::abs(residual);
  return magnitude <= delta ? 1.0 : delta / magnitude;
}

double HuberCost(double residual, double delta) {
  const double magnitude = std::abs(residual);
  return magnitude <= delta ? 0.5 * magnitude * magnitude : delta * (magnitude - 0.5 * delta);
}

Linearization Linearize(const std::vector<PointOnPlane>& constraints, const Pose& cam_from_lrf,
                        double huber_delta_m) {
  Linearization lin;
  Eigen::Matrix<double, 1, 6> jacobian;
  for (const PointOnPlane& constraint : constraints) {
    const double r = PointOnPlaneResidual(cam_from_lrf, constraint, &jacobian);
    const double w = HuberWeight(r, huber_delta_m);  // Huber by iteratively reweighted LSQ
    lin.information += w * jacobian.transpose() * jacobian;
    lin.geometric_information += jacobian.transpose() * jacobian;
    lin.gradient += w * jacobian.transpose() * r;
    lin.cost += HuberCost(r, huber_delta_m);
    lin.weighted_squared_error += w * r * r;
  }
  return lin;
}

// Gauss-Newton step restricted to the observable subspace of JᵀWJ: eigen-directions whose
// eigenvalue is below weak_ratio × the largest get no step, so they stay at the seed instead of
// following noise (they are reported weak by the observability analysis).
Vec6 ObservableStep(const Linearization& lin, double weak_ratio) {
  Eigen::SelfAdjointEigenSolver<Mat6> eigen(lin.information);
  const double largest = eigen.eigenvalues()[5];
  Vec6 delta = Vec6::Zero();
  if (!(largest > 0)) return delta;
  for (int i = 0; i < 6; ++i) {
    const double lambda = eigen.eigenvalues()[i];
    if (lambda < weak_ratio * largest) continue;
    const Vec6 v = eigen.eigenvectors().col(i);
    delta -= v * (v.dot(lin.gradient) / lambda);
  }
  return delta;
}

int NumObservations(const std::vector<PointOnPlane>& constraints) {
  int count = 0;
  for (const PointOnPlane& c : constraints) count = std::max(count, c.observation + 1);
  return count;
}

// Per observation (sized by the largest index + 1, NaN where an index has no constraint): RMS
// point-to-plane distance and mean Huber weight of its scan points.
void FillPointToPlane(const std::vector<PointOnPlane>& constraints, const Pose& cam_from_lrf,
                      double huber_delta_m, LrfSolution* solution) {
  const int num_observations = NumObservations(constraints);
  std::vector<double> squared(num_observations, 0.0), weights(num_observations, 0.0);
  std::vector<int> counts(num_observations, 0);
  for (const PointOnPlane& constraint : constraints) {
    const double r = PointOnPlaneResidual(cam_from_lrf, constraint, nullptr);
    squared[constraint.observation] += r * r;
    weights[constraint.observation] += HuberWeight(r, huber_delta_m);
    ++counts[constraint.observation];
  }
  solution->point_to_plane_rms_m.assign(num_observations, kNaN);
  solution->robust_weights.assign(num_observations, kNaN);
  for (int i = 0; i < num_observations; ++i) {
    if (counts[i] == 0) continue;
    solution->point_to_plane_rms_m[i] = std::sqrt(squared[i] / counts[i]);
    solution->robust_weights[i] = weights[i] / counts[i];
  }
}

// σ̂² (JᵀWJ)⁻¹ with the a-posteriori variance factor σ̂² = Σ w r² / (m − 6): the residuals carry no
// noise model. As in the 3D solver, directions without information get a huge variance
// (1e12 σ̂²) rather than a pseudo-inverse's zero, so that they cannot look certain.
Mat6 Covariance(const Linearization& lin, int redundancy) {
  const double variance_factor = redundancy > 0 ? lin.weighted_squared_error / redundancy : 0.0;
  Eigen::SelfAdjointEigenSolver<Mat6> eigen(lin.information);
  Vec6 inverse_eigenvalues;
  for (int i = 0; i < 6; ++i) {
    const double lambda = eigen.eigenvalues()[i];
    inverse_eigenvalues[i] = lambda > 1e-12 * eigen.eigenvalues()[5] ? 1.0 / lambda : 1e12;
  }
  return variance_factor * eigen.eigenvectors() * inverse_eigenvalues.asDiagonal() *
         eigen.eigenvectors().transpose();
}

void AddPointOnPlanes(const Vec2& point, const Plane& a, const Plane& b, int observation,
                      std::vector<PointOnPlane>* out) {
  out->push_back({point, a, observation});
  out->push_back({point, b, observation});
}

// Per-observation figures resized to `size` entries, NaN where nothing was computed.
void ResizePerObservation(size_t size, LrfSolution* solution) {
  solution->point_to_plane_rms_m.resize(size, kNaN);
  solution->robust_weights.resize(size, kNaN);
}

// Eq. (12) per usable observation (NaN for the others) and its mean over the usable ones.
void FillPointToLine(const std::vector<LrfObservation>& observations, LrfSolution* solution) {
  solution->point_to_line_m.assign(observations.size(), kNaN);
  double sum = 0.0;
  int count = 0;
  for (size_t i = 0; i < observations.size(); ++i) {
    if (!Usable(observations[i])) continue;
    solution->point_to_line_m[i] = PointToLineError(observations[i], solution->cam_from_lrf);
    sum += solution->point_to_line_m[i];
    ++count;
  }
  solution->mean_point_to_line_m = count > 0 ? sum / count : 0.0;
}

LrfSolution Failure(LrfMethod method, const std::string& reason) {
  LrfSolution solution;
  solution.ok = false;
  solution.method = method;
  solution.reason = reason;
  return solution;
}

// The paper-linear answer with σ: covariance and observability from the point-to-plane
// information of the same corner rows at the linear estimate; per-observation RMS and weights
// from every scan point (face constraints), so that they compare with the refined method's.
LrfSolution LinearSolution(const std::vector<PointOnPlane>& corner_constraints,
                           const std::vector<PointOnPlane>& point_constraints,
                           const LrfSolverOptions& options, const Pose& cam_from_lrf,
                           size_t num_observations) {
  LrfSolution solution = PointPlaneSolver(corner_constraints, options, cam_from_lrf).Summarize();
  const LrfSolution per_point =
      PointPlaneSolver(point_constraints, options, cam_from_lrf).Summarize();
  solution.point_to_plane_rms_m = per_point.point_to_plane_rms_m;
  solution.robust_weights = per_point.robust_weights;
  ResizePerObservation(num_observations, &solution);
  solution.method = LrfMethod::kPaperLinear;
  solution.converged = true;  // closed form
  solution.iterations = 0;
  solution.cost_history.clear();
  solution.history.clear();
  return solution;
}

// The paper-linear answer (Eq. (10)–(11) over `linear_constraints`), or the refinement over
// `refine_constraints` seeded by it, or by `initial` when the linear system is rank-deficient.
LrfSolution SolveLinearThenRefine(const std::vector<PointOnPlane>& linear_constraints,
                                  const std::vector<PointOnPlane>& refine_constraints,
                                  const LrfSolverOptions& options,
                                  const std::optional<Pose>& initial, size_t num_observations) {
  std::string why;
  const std::optional<Pose> linear = SolveLinearPointOnPlane(linear_constraints, &why);
  if (options.method == LrfMethod::kPaperLinear) {
    if (!linear) return Failure(options.method, why);
    return LinearSolution(linear_constraints, refine_constraints, options, *linear,
                          num_observations);
  }
  if (!linear && !initial)
    return Failure(options.method, why + "; no initial estimate was given to refine from");
  LrfSolution solution =
      PointPlaneSolver(refine_constraints, options, linear ? *linear : *initial).Run();
  ResizePerObservation(num_observations, &solution);
  return solution;
}

}  // namespace

std::string LrfMethodName(LrfMethod method) { return NameIn(kLrfMethodNames, method); }

std::optional<LrfMethod> ParseLrfMethod(const std::string& name) {
  return ValueIn(kLrfMethodNames, name);
}

bool LrfSolverOptions::Check(std::string* why) const {
  if (!(huber_delta_m > 0)) return FailCheck(why, "huber_delta_m must be > 0 (metres)");
  if (max_iterations < 1) return FailCheck(why, "max_iterations must be >= 1");
  if (!(step_tolerance > 0)) return FailCheck(why, "step_tolerance must be > 0");
  if (!(weak_eigenvalue_ratio > 0 && weak_eigenvalue_ratio < 1))
    return FailCheck(why, "weak_eigenvalue_ratio must be in (0, 1)");
  return true;
}

std::vector<PointOnPlane> CornerConstraints(const std::vector<LrfObservation>& observations) {
  std::vector<PointOnPlane> constraints;
  for (size_t i = 0; i < observations.size(); ++i) {
    if (!Usable(observations[i])) continue;
    const auto& corners = observations[i].scan.corners;
    const auto& planes = observations[i].depth.planes;
    const int index = static_cast<int>(i);
    // Eq. (9): F on AB = planes 0 ∩ 1, G on AC = 1 ∩ 2, H on AD = 2 ∩ 0.
    AddPointOnPlanes(corners[0], planes[0], planes[1], index, &constraints);
    AddPointOnPlanes(corners[1], planes[1], planes[2], index, &constraints);
    AddPointOnPlanes(corners[2], planes[2], planes[0], index, &constraints);
  }
  return constraints;
}

std::vector<PointOnPlane> FaceConstraints(const std::vector<LrfObservation>& observations) {
  std::vector<PointOnPlane> constraints;
  for (size_t i = 0; i < observations.size(); ++i) {
    if (!Usable(observations[i])) continue;
    for (int face = 0; face < 3; ++face) {
      for (const Vec2& point : observations[i].scan.face_points[face])
        constraints.push_back({point, observations[i].depth.planes[face], static_cast<int>(i)});
    }
  }
  return constraints;
}

std::vector<PointOnPlane> BoardConstraints(const std::vector<LrfBoardObservation>& observations) {
  std::vector<PointOnPlane> constraints;
  for (size_t i = 0; i < observations.size(); ++i) {
    for (const Vec2& point : observations[i].board_points)
      constraints.push_back({point, observations[i].camera_plane, static_cast<int>(i)});
  }
  return constraints;
}

std::optional<Pose> SolveLinearPointOnPlane(const std::vector<PointOnPlane>& constraints,
                                            std::string* why) {
  auto fail = [&](const std::string& message) -> std::optional<Pose> {
    if (why) *why = message;
    return std::nullopt;
  };
  if (constraints.size() < 9)
    return fail("only " + std::to_string(constraints.size()) +
                " point-on-plane rows for the 9 unknowns of Eq. (11): fewer than two usable "
                "observations");
  // Eq. (10): n1 (r11 x + r12 y + t1) + n2 (...) + n3 (...) = −d, one row per constraint.
  Eigen::MatrixXd a(constraints.size(), 9);
  Eigen::VectorXd b(constraints.size());
  for (size_t i = 0; i < constraints.size(); ++i) {
    const Vec3 p(constraints[i].point.x(), constraints[i].point.y(), 1.0);
    for (int k = 0; k < 3; ++k) a.block<1, 3>(i, 3 * k) = constraints[i].plane.normal[k] * p;
    b[i] = -constraints[i].plane.distance;
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const double ratio = svd.singularValues()[8] / std::max(svd.singularValues()[0], 1e-300);
  if (!(ratio >= kMinSingularValueRatio)) {
    std::ostringstream message;
    message << "the linear system of Eq. (11) is rank-deficient (smallest/largest singular value "
            << ratio << "): the observations need at least two distinct target poses whose "
            << "planes are not parallel and whose normals span all three camera axes";
    return fail(message.str());
  }
  const Eigen::VectorXd x = svd.solve(b);  // [r11 r12 t1 r21 r22 t2 r31 r32 t3]
  // Under noise r1, r2 are neither unit nor orthogonal: normalise them, complete with
  // r3 = r1 × r2 and take the nearest rotation, as the paper does. t is kept from the least
  // squares as it stands (the paper's baseline), not re-solved for the orthonormalised rotation.
  const Vec3 r1 = Vec3(x[0], x[3], x[6]).normalized();
  const Vec3 r2 = Vec3(x[1], x[4], x[7]).normalized();
  Mat3 rotation;
  rotation << r1, r2, r1.cross(r2);
  Pose cam_from_lrf = Pose::Identity();
  cam_from_lrf.linear() = NearestRotation(rotation);
  cam_from_lrf.translation() = Vec3(x[2], x[5], x[8]);
  return cam_from_lrf;
}

double PointToLineError(const LrfObservation& observation, const Pose& cam_from_lrf) {
  // Eq. (12): F on AB, G on AC, H on AD.
  double sum = 0.0;
  for (int j = 0; j < 3; ++j) {
    const Vec2& corner = observation.scan.corners[j];
    const Vec3 corner_in_cam = cam_from_lrf * Vec3(corner.x(), corner.y(), 0.0);
    sum += observation.depth.lines[j].Distance(corner_in_cam);
  }
  return sum / 3.0;
}

PointPlaneSolver::PointPlaneSolver(std::vector<PointOnPlane> constraints,
                                   const LrfSolverOptions& options,
                                   const Pose& initial_cam_from_lrf)
    : constraints_(std::move(constraints)), options_(options), cam_from_lrf_(initial_cam_from_lrf) {
  std::string why;
  CALIBENCH_CHECK(options_.Check(&why));
  CALIBENCH_CHECK(!constraints_.empty());
  const double cost = Linearize(constraints_, cam_from_lrf_, options_.huber_delta_m).cost;
  history_.push_back({0, cost, 0.0, cam_from_lrf_});
}

bool PointPlaneSolver::Step() {
  if (done_) return false;
  const double delta_m = options_.huber_delta_m;
  const Linearization lin = Linearize(constraints_, cam_from_lrf_, delta_m);
  Vec6 delta = ObservableStep(lin, options_.weak_eigenvalue_ratio);
  Pose candidate = cam_from_lrf_ * ExpSE3(delta);
  double cost = Linearize(constraints_, candidate, delta_m).cost;
  // Backtracking keeps Gauss-Newton monotone while the Huber weights change.
  for (int halvings = 0; cost > lin.cost && halvings < 10; ++halvings) {
    delta *= 0.5;
    candidate = cam_from_lrf_ * ExpSE3(delta);
    cost = Linearize(constraints_, candidate, delta_m).cost;
  }
  const bool accepted = cost <= lin.cost;
  if (accepted) cam_from_lrf_ = candidate;
  const double step_norm = accepted ? delta.norm() : 0.0;
  history_.push_back(
      {static_cast<int>(history_.size()), std::min(cost, lin.cost), step_norm, cam_from_lrf_});
  converged_ = step_norm < options_.step_tolerance ||
               (accepted && lin.cost - cost <= 1e-15 * std::max(1.0, lin.cost));
  done_ = converged_ || static_cast<int>(history_.size()) > options_.max_iterations;
  return !done_;
}

LrfSolution PointPlaneSolver::Run() {
  while (Step()) {
  }
  return Summarize();
}

LrfSolution PointPlaneSolver::Summarize() const {
  LrfSolution solution;
  solution.ok = true;
  solution.method = LrfMethod::kRefined;
  solution.cam_from_lrf = cam_from_lrf_;
  solution.converged = converged_;
  solution.iterations = static_cast<int>(history_.size()) - 1;
  solution.history = history_;
  for (const IterationReport& it : history_) solution.cost_history.push_back(it.cost);

  FillPointToPlane(constraints_, cam_from_lrf_, options_.huber_delta_m, &solution);

  const Linearization lin = Linearize(constraints_, cam_from_lrf_, options_.huber_delta_m);
  const int redundancy = static_cast<int>(constraints_.size()) - 6;
  solution.covariance = Covariance(lin, redundancy);
  // Observability is geometry, not noise: judged on the unweighted information JᵀJ.
  solution.observability = AnalyseObservability(lin.geometric_information, cam_from_lrf_,
                                                options_.weak_eigenvalue_ratio, "LRF");
  if (redundancy <= 0) {
    solution.observability.well_constrained = false;
    solution.observability.weak_directions.push_back(
        "no redundant point-on-plane constraints: more than 6 are needed");
  }
  return solution;
}

LrfSolution SolveLrf(const std::vector<LrfObservation>& observations,
                     const LrfSolverOptions& options, const std::optional<Pose>& initial) {
  std::string why;
  if (!options.Check(&why)) return Failure(options.method, why);
  const int usable = static_cast<int>(std::count_if(observations.begin(), observations.end(),
                                                    [](const auto& o) { return Usable(o); }));
  if (usable < 2)
    return Failure(options.method, "fewer than two usable observations (" + std::to_string(usable) +
                                       " of " + std::to_string(observations.size()) +
                                       " had features)");
  const std::vector<PointOnPlane> corners = CornerConstraints(observations);
  const std::vector<PointOnPlane> points = FaceConstraints(observations);
  if (points.size() < 7)
    return Failure(options.method, "the usable observations have only " +
                                       std::to_string(points.size()) + " face scan points");
  // Eq. (11) from the corners; the refinement runs over every scan point of every face.
  LrfSolution solution =
      SolveLinearThenRefine(corners, points, options, initial, observations.size());
  if (!solution.ok) return solution;
  FillPointToLine(observations, &solution);
  return solution;
}

AdaptiveLrfResult SolveLrfAdaptive(const std::vector<LrfObservation>& sequence,
                                   double error_threshold_m, const LrfSolverOptions& options) {
  // Algorithm 1: the first two usable observations are added and solved (lines 32–36); from then
  // on each new observation is first tested under the current estimate (line 18). Below the
  // threshold the loop ends and the estimate stands (lines 19–23, the tested observation is not
  // added); otherwise it is added and the system re-solved (lines 25–29).
  AdaptiveLrfResult result;
  std::vector<LrfObservation> added;
  std::optional<LrfSolution> current;
  size_t current_size = 0;  // observations (a prefix of `sequence`) behind `current`
  for (size_t k = 0; k < sequence.size(); ++k) {
    result.observations_used = static_cast<int>(k) + 1;
    const bool usable = Usable(sequence[k]);
    if (k >= 2) {
      const bool can_test = usable && current && current->ok;
      result.newest_error_m.push_back(
          can_test ? PointToLineError(sequence[k], current->cam_from_lrf) : kNaN);
      if (can_test && result.newest_error_m.back() < error_threshold_m) {
        result.reached_threshold = true;
        break;
      }
    }
    // The observation enters the system; an unusable one is kept so that the solution's
    // per-observation figures stay indexed like `sequence` (SolveLrf skips it).
    added.push_back(sequence[k]);
    if (usable && std::count_if(added.begin(), added.end(), Usable) >= 2) {
      current = SolveLrf(added, options);
      current_size = added.size();
    }
  }
  // Per-observation figures cover the observations the estimate was solved from.
  result.solution = current && (result.reached_threshold || current_size == added.size())
                        ? *current
                        : SolveLrf(added, options);
  return result;
}

LrfSolution SolveLrfBoard(const std::vector<LrfBoardObservation>& observations,
                          const LrfSolverOptions& options, const std::optional<Pose>& initial) {
  std::string why;
  if (!options.Check(&why)) return Failure(options.method, why);
  const int usable =
      static_cast<int>(std::count_if(observations.begin(), observations.end(),
                                     [](const auto& o) { return o.board_points.size() >= 2; }));
  if (usable < 2)
    return Failure(options.method, "fewer than two usable observations (" + std::to_string(usable) +
                                       " of " + std::to_string(observations.size()) +
                                       " had at least two board points)");
  // Zhang & Pless's linear step is Eq. (10) with one row per board scan point.
  const std::vector<PointOnPlane> constraints = BoardConstraints(observations);
  return SolveLinearThenRefine(constraints, constraints, options, initial, observations.size());
}

}  // namespace calibench
