// RefineIntrinsicsJointly: Levenberg–Marquardt over [intrinsics; cam_from_lidar; per pair its
// board pose and edge dilation], the Jacobian by central differences block by block (a pair's
// residuals depend on the intrinsics, the extrinsic and its own board only), the normal equations
// dense (a few hundred unknowns for 40 pairs). The pipeline steps around it are in
// intrinsics_steps.cpp.
#include "core/lidar_camera/joint_intrinsics.h"

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/base/statistics.h"
#include "core/target/board_edges.h"

namespace calibench {
namespace {

// One pair as the joint problem sees it: its corners, its LiDAR plane (range offset applied) with
// the whitening of its tangent residual, its edge crossings.
struct JointPair {
  std::string id;
  BoardDetection corners;
  Plane lidar_plane;
  Eigen::Matrix<double, 3, 2> basis;  // the LiDAR normal's tangent plane
  Mat3 plane_whitening;               // L⁻¹ of the residual's covariance C = L Lᵀ
  std::vector<LidarEdgePoint> edges;
  Vec2 sheet_half_size_m = Vec2::Zero();
  bool dilation = false;  // the pair's edge dilation is a parameter
  int first = 0;          // its first parameter (the board pose, then the dilation)
};

enum Group { kCorners = 0, kPlanes = 1, kEdges = 2, kGroups = 3 };

struct State {
  std::vector<double> intrinsics;  // the camera's IntrinsicParameters
  Pose cam_from_lidar = Pose::Identity();
  std::vector<Pose> cam_from_board;
  std::vector<double> dilation_m;
};

// Whitened residuals of one pair with the group of each (corners in pairs of rows).
struct PairResiduals {
  Eigen::VectorXd values;
  std::vector<Group> groups;
  bool valid = true;  // every corner projected
};

class JointProblem {
 public:
  JointProblem(std::vector<JointPair> pairs, const CameraModel& camera, std::vector<int> active,
               double edge_floor_sigma_m, const JointIntrinsicsOptions& options)
      : pairs_(std::move(pairs)),
        camera_(camera),
        start_intrinsics_(IntrinsicParameters(camera)),
        active_(std::move(active)),
        edge_floor_sigma_m_(edge_floor_sigma_m),
        options_(options) {
    int next = Global();
    for (JointPair& p : pairs_) {
      p.first = next;
      next += 6 + (p.dilation ? 1 : 0);
    }
    size_ = next;
  }

  int Global() const { return static_cast<int>(active_.size()) + 6; }
  int Size() const { return size_; }
  const std::vector<JointPair>& Pairs() const { return pairs_; }

  void SetPrior(const Eigen::MatrixXd& information, const Eigen::VectorXd& mean) {
    prior_information_ = information;
    prior_mean_ = mean;
  }
  void SetScales(double corner_sigma_px, double plane_factor, double edge_factor) {
    corner_sigma_px_ = corner_sigma_px;
    plane_factor_ = plane_factor;
    edge_factor_ = edge_factor;
  }
  double CornerSigma() const { return corner_sigma_px_; }
  double PlaneFactor() const { return plane_factor_; }
  double EdgeFactor() const { return edge_factor_; }

  // The pair's residuals at `state` with its local parameters moved by `local`
  // ([active intrinsics; extrinsic; board pose; dilation]).
  PairResiduals Evaluate(const State& state, size_t i, const Eigen::VectorXd& local) const {
    const JointPair& p = pairs_[i];
    const int m = static_cast<int>(active_.size());
    CameraModel camera = camera_;
    std::vector<double> k = state.intrinsics;
    for (int a = 0; a < m; ++a) k[active_[a]] += local[a];
    SetIntrinsicParameters(k, &camera);
    const Pose x = state.cam_from_lidar * ExpSE3(local.segment<6>(m));
    const Pose board = state.cam_from_board[i] * ExpSE3(local.segment<6>(m + 6));
    const double dilation = p.dilation ? state.dilation_m[i] + local[m + 12] : 0.0;

    PairResiduals out;
    const size_t corners = p.corners.pixels.size();
    out.values.resize(static_cast<Eigen::Index>(2 * corners + 3 + p.edges.size()));
    Eigen::Index row = 0;
    for (size_t c = 0; c < corners; ++c) {
      const std::optional<Vec2> pixel = camera.Project(board * p.corners.board_points[c]);
      if (!pixel) {
        out.valid = false;
        return out;
      }
      out.values.segment<2>(row) = (*pixel - p.corners.pixels[c]) / corner_sigma_px_;
      out.groups.insert(out.groups.end(), 2, kCorners);
      row += 2;
    }
    // The board's plane in the camera frame, then in the LiDAR frame, against the LiDAR's.
    const Vec3 normal = board.linear().col(2);
    const Plane camera_plane = OrientTowardsOrigin(Plane{normal, -normal.dot(board.translation())});
    const Plane predicted = OrientTowardsOrigin(TransformPlane(x.inverse(), camera_plane));
    Vec3 plane;
    plane.head<2>() = p.basis.transpose() * (predicted.normal - p.lidar_plane.normal);
    plane[2] = predicted.distance - p.lidar_plane.distance;
    out.values.segment<3>(row) = p.plane_whitening * plane / std::sqrt(plane_factor_);
    out.groups.insert(out.groups.end(), 3, kPlanes);
    row += 3;
    for (const LidarEdgePoint& edge : p.edges) {
      double sigma = 0.0;
      const double e = BoardEdgeResidual(x, board, p.sheet_half_size_m, edge, edge_floor_sigma_m_,
                                         nullptr, &sigma);
      out.values[row++] = (e - dilation) / (sigma * std::sqrt(edge_factor_));
      out.groups.push_back(kEdges);
    }
    return out;
  }

  // Robust weights of a pair's residuals (corners per corner, the plane as one, edges each).
  std::vector<double> Weights(const PairResiduals& r, double* cost) const {
    std::vector<double> w(r.groups.size(), 1.0);
    const double delta = options_.huber_delta;
    auto huber = [&](double norm, size_t from, size_t count) {
      const double weight = norm <= delta ? 1.0 : delta / norm;
      *cost += norm <= delta ? 0.5 * norm * norm : delta * (norm - 0.5 * delta);
      for (size_t j = from; j < from + count; ++j) w[j] = weight;
    };
    size_t j = 0;
    while (j < r.groups.size()) {
      const size_t count = r.groups[j] == kCorners ? 2 : r.groups[j] == kPlanes ? 3 : 1;
      huber(r.values.segment(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(count)).norm(),
            j, count);
      j += count;
    }
    return w;
  }

  double Cost(const State& state) const {
    double cost = PriorCost(state);
    for (size_t i = 0; i < pairs_.size(); ++i) {
      const PairResiduals r = Evaluate(state, i, Eigen::VectorXd::Zero(LocalSize(i)));
      if (!r.valid) return std::numeric_limits<double>::infinity();
      Weights(r, &cost);
    }
    return cost;
  }

  struct Linearization {
    Eigen::MatrixXd information;  // JᵀWJ
    Eigen::VectorXd gradient;     // JᵀWr
    double cost = 0.0;
    bool valid = true;
    Eigen::MatrixXd group_information[kGroups];  // each group's share of `information`
    double group_squares[kGroups] = {0, 0, 0};   // Σ w r² per group
    int group_count[kGroups] = {0, 0, 0};        // residuals per group
  };

  Linearization Linearize(const State& state) const {
    Linearization lin;
    lin.information = Eigen::MatrixXd::Zero(size_, size_);
    lin.gradient = Eigen::VectorXd::Zero(size_);
    for (auto& g : lin.group_information) g = Eigen::MatrixXd::Zero(size_, size_);
    lin.cost = PriorCost(state);
    if (prior_information_.size() > 0) {
      const int m = static_cast<int>(active_.size());
      lin.information.topLeftCorner(m, m) += prior_information_;
      lin.gradient.head(m) += prior_information_ * (ActiveIntrinsics(state) - prior_mean_);
    }
    for (size_t i = 0; i < pairs_.size(); ++i) {
      const int n = LocalSize(i);
      const PairResiduals r0 = Evaluate(state, i, Eigen::VectorXd::Zero(n));
      if (!r0.valid) {
        lin.valid = false;
        return lin;
      }
      const std::vector<double> w = Weights(r0, &lin.cost);
      Eigen::MatrixXd jacobian(r0.values.size(), n);
      for (int c = 0; c < n; ++c) {
        const double h = Step(c);
        Eigen::VectorXd plus = Eigen::VectorXd::Zero(n), minus = Eigen::VectorXd::Zero(n);
        plus[c] = h, minus[c] = -h;
        const PairResiduals a = Evaluate(state, i, plus), b = Evaluate(state, i, minus);
        if (!a.valid || !b.valid) {
          lin.valid = false;
          return lin;
        }
        jacobian.col(c) = (a.values - b.values) / (2 * h);
      }
      const std::vector<int> index = LocalIndex(i);
      for (Eigen::Index row = 0; row < r0.values.size(); ++row) {
        const double weight = w[static_cast<size_t>(row)];
        const Group group = r0.groups[static_cast<size_t>(row)];
        const double e = r0.values[row];
        lin.group_squares[group] += weight * e * e;
        ++lin.group_count[group];
        for (int a = 0; a < n; ++a) {
          const double ja = weight * jacobian(row, a);
          if (ja == 0.0) continue;
          lin.gradient[index[a]] += ja * e;
          for (int b = 0; b < n; ++b) {
            lin.information(index[a], index[b]) += ja * jacobian(row, b);
            lin.group_information[group](index[a], index[b]) += ja * jacobian(row, b);
          }
        }
      }
    }
    return lin;
  }

  State Apply(const State& state, const Eigen::VectorXd& step) const {
    State next = state;
    const int m = static_cast<int>(active_.size());
    for (int a = 0; a < m; ++a) next.intrinsics[active_[a]] += step[a];
    next.cam_from_lidar = state.cam_from_lidar * ExpSE3(step.segment<6>(m));
    for (size_t i = 0; i < pairs_.size(); ++i) {
      const int first = pairs_[i].first;
      next.cam_from_board[i] = state.cam_from_board[i] * ExpSE3(step.segment<6>(first));
      if (pairs_[i].dilation) next.dilation_m[i] += step[first + 6];
    }
    return next;
  }

  Eigen::VectorXd ActiveIntrinsics(const State& state) const {
    Eigen::VectorXd k(static_cast<Eigen::Index>(active_.size()));
    for (size_t a = 0; a < active_.size(); ++a) k[a] = state.intrinsics[active_[a]];
    return k;
  }

 private:
  int LocalSize(size_t i) const {
    return static_cast<int>(active_.size()) + 12 + (pairs_[i].dilation ? 1 : 0);
  }
  // Each local parameter's place in the whole vector.
  std::vector<int> LocalIndex(size_t i) const {
    std::vector<int> index;
    for (int a = 0; a < Global(); ++a) index.push_back(a);
    for (int a = 0; a < 6 + (pairs_[i].dilation ? 1 : 0); ++a) index.push_back(pairs_[i].first + a);
    return index;
  }
  // Central-difference steps: relative for the intrinsics, 1e-6 for poses (rad, m) and dilations.
  double Step(int local) const {
    const int m = static_cast<int>(active_.size());
    if (local >= m) return 1e-6;
    const double value = std::abs(start_intrinsics_[active_[local]]);
    return 1e-6 * std::max(value, active_[local] < 4 ? 1.0 : 0.01);
  }
  double PriorCost(const State& state) const {
    if (prior_information_.size() == 0) return 0.0;
    const Eigen::VectorXd d = ActiveIntrinsics(state) - prior_mean_;
    return 0.5 * d.dot(prior_information_ * d);
  }

  std::vector<JointPair> pairs_;
  CameraModel camera_;
  std::vector<double> start_intrinsics_;  // IntrinsicParameters(camera_): the steps' scale
  std::vector<int> active_;
  double edge_floor_sigma_m_;
  JointIntrinsicsOptions options_;
  int size_ = 0;
  double corner_sigma_px_ = 0.3, plane_factor_ = 1.0, edge_factor_ = 1.0;
  Eigen::MatrixXd prior_information_;
  Eigen::VectorXd prior_mean_;
};

// Levenberg–Marquardt to convergence (or the iteration limit); true when converged.
bool Minimize(const JointProblem& problem, const JointIntrinsicsOptions& options, State* state,
              int* iterations) {
  double lambda = 1e-4;
  for (int it = 0; it < options.max_iterations; ++it) {
    const JointProblem::Linearization lin = problem.Linearize(*state);
    if (!lin.valid) throw std::invalid_argument("a board's corners left the image model");
    ++*iterations;
    bool moved = false;
    for (int attempt = 0; attempt < 12 && !moved; ++attempt) {
      Eigen::MatrixXd damped = lin.information;
      damped.diagonal() += lambda * lin.information.diagonal().cwiseMax(1e-12);
      const Eigen::VectorXd step = damped.ldlt().solve(-lin.gradient);
      if (!step.allFinite()) {
        lambda *= 10;
        continue;
      }
      const State next = problem.Apply(*state, step);
      const double cost = problem.Cost(next);
      if (cost < lin.cost) {
        *state = next;
        lambda = std::max(lambda / 10, 1e-12);
        moved = true;
        if (lin.cost - cost <= options.function_tolerance * lin.cost) return true;
      } else {
        lambda *= 10;
      }
    }
    if (!moved) return true;  // no step lowers the cost: at the minimum to the precision
  }
  return false;
}

// Which IntrinsicParameters entries the joint problem estimates.
std::vector<int> ActiveParameters(const CameraModel& camera, IntrinsicsToRefine which) {
  if (which == IntrinsicsToRefine::kFocal) return {0, 1};
  std::vector<int> active = {0, 1, 2, 3};
  if (which == IntrinsicsToRefine::kPinhole) return active;
  const size_t d = camera.distortion.size();
  if (camera.type == CameraModelType::kKannalaBrandt) {
    for (int i = 0; i < 4; ++i) active.push_back(4 + i);
  } else {
    for (size_t i = 0; i < std::min<size_t>(d, 4); ++i) active.push_back(4 + static_cast<int>(i));
    if (d >= 5 && camera.distortion[4] != 0.0) active.push_back(8);  // k3, where it was used
  }
  return active;
}

// The pairs of a solve that the joint problem uses: accepted, weighted, with corners.
std::vector<JointPair> JointPairs(const std::vector<PairFeatures>& pairs,
                                  const SolverResult& solution, std::vector<Pose>* boards) {
  const double offset = solution.range_offset ? solution.range_offset->value_m : 0.0;
  std::vector<JointPair> out;
  size_t solved = 0;  // index into the solution's per-pair vectors (the accepted pairs)
  for (const PairFeatures& f : pairs) {
    if (f.status != PairStatus::kAccepted || !f.lidar || !f.camera) continue;
    const size_t index = solved++;
    if (solution.DownWeighted(index) || f.camera->corners.pixels.empty()) continue;
    const PlanePair plane_pair = MakePlanePair(f.id, *f.lidar, *f.camera);
    JointPair p;
    p.id = f.id;
    p.corners = f.camera->corners;
    p.lidar_plane = CorrectedLidarPlane(plane_pair, offset);
    p.basis = PlaneTangentBasis(p.lidar_plane.normal);
    Eigen::Matrix<double, 3, 4> d = Eigen::Matrix<double, 3, 4>::Zero();
    d.block<2, 3>(0, 0) = p.basis.transpose();
    d(2, 3) = 1.0;
    Mat3 covariance = d * plane_pair.lidar_covariance * d.transpose();
    covariance.diagonal() += Vec3(1e-10, 1e-10, 1e-8);  // as the solver's floor
    const Eigen::LLT<Mat3> llt(covariance);
    if (llt.info() != Eigen::Success) continue;
    p.plane_whitening = llt.matrixL().solve(Mat3::Identity());
    for (LidarEdgePoint edge : plane_pair.lidar_edges) {
      edge.point -= offset * edge.point.normalized();  // the range offset, as the solver's
      p.edges.push_back(edge);
    }
    p.sheet_half_size_m = plane_pair.sheet_half_size_m;
    if (p.sheet_half_size_m.minCoeff() <= 0) p.edges.clear();
    p.dilation = p.edges.size() >= 3;
    boards->push_back(f.camera->cam_from_board);
    out.push_back(std::move(p));
  }
  return out;
}

// Förstner's variance components: each group's Σ w r² over its redundancy n_g − tr(H⁻¹ H_g).
void VarianceFactors(const JointProblem::Linearization& lin, double factors[kGroups]) {
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(lin.information);
  for (int g = 0; g < kGroups; ++g) {
    factors[g] = 1.0;
    if (lin.group_count[g] == 0) continue;
    const double used = ldlt.solve(lin.group_information[g]).trace();
    const double redundancy = std::max(1.0, lin.group_count[g] - used);
    factors[g] = lin.group_squares[g] / redundancy;
  }
}

// The camera file's own estimate, where it has a covariance, as a prior on the active parameters.
void SetCameraPrior(const CameraModel& camera, const std::vector<int>& active, const State& state,
                    JointProblem* problem) {
  if (camera.covariance.empty()) return;
  const int m = static_cast<int>(active.size());
  const Eigen::Index n = static_cast<Eigen::Index>(state.intrinsics.size());
  const Eigen::Map<const Eigen::MatrixXd> full(camera.covariance.data(), n, n);
  Eigen::MatrixXd sub(m, m);
  for (int a = 0; a < m; ++a)
    for (int b = 0; b < m; ++b) sub(a, b) = full(active[a], active[b]);
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(sub);
  if (ldlt.info() == Eigen::Success && ldlt.isPositive() && sub.diagonal().minCoeff() > 0)
    problem->SetPrior(ldlt.solve(Eigen::MatrixXd::Identity(m, m)),
                      problem->ActiveIntrinsics(state));
}

// Minimize, then rounds of variance components (each group's noise scaled to its residuals) while
// a factor moves by more than 5 %; true when the last minimisation converged.
bool MinimizeWithVarianceComponents(const JointIntrinsicsOptions& options, JointProblem* problem,
                                    State* state, int* iterations) {
  bool converged = Minimize(*problem, options, state, iterations);
  for (int round = 0; round < options.variance_rounds; ++round) {
    double factors[kGroups];
    VarianceFactors(problem->Linearize(*state), factors);
    bool changed = false;
    for (const double f : factors) changed |= std::abs(f - 1.0) > 0.05;
    if (!changed) break;
    problem->SetScales(problem->CornerSigma() * std::sqrt(factors[kCorners]),
                       problem->PlaneFactor() * factors[kPlanes],
                       problem->EdgeFactor() * factors[kEdges]);
    converged = Minimize(*problem, options, state, iterations);
  }
  return converged;
}

// The solution into *result: the refined camera with the marginal covariance of its active
// parameters (the weights hold the noise), the extrinsic with its marginal, the corner RMS.
void FillResult(const JointProblem& problem, const State& state, const CameraModel& camera,
                const std::vector<int>& active, JointIntrinsicsResult* result) {
  const int m = static_cast<int>(active.size());
  const JointProblem::Linearization lin = problem.Linearize(state);
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(lin.information);
  const Eigen::MatrixXd covariance =
      ldlt.solve(Eigen::MatrixXd::Identity(problem.Size(), problem.Size()).leftCols(m + 6))
          .topRows(m + 6);
  result->camera = camera;
  SetIntrinsicParameters(state.intrinsics, &result->camera);
  const size_t n = state.intrinsics.size();
  result->camera.covariance.assign(n * n, 0.0);
  result->refined.assign(n, false);
  for (int a = 0; a < m; ++a) {
    result->refined[active[a]] = true;
    for (int b = 0; b < m; ++b)
      result->camera.covariance[active[a] * n + active[b]] =
          0.5 * (covariance(a, b) + covariance(b, a));
  }
  result->cam_from_lidar = state.cam_from_lidar;
  result->cam_from_lidar_covariance = covariance.block(m, m, 6, 6);
  result->corner_sigma_px = problem.CornerSigma();
  result->plane_variance_factor = problem.PlaneFactor();
  result->edge_variance_factor = problem.EdgeFactor();
  double squared = 0.0;
  for (size_t i = 0; i < problem.Pairs().size(); ++i) {
    const JointPair& p = problem.Pairs()[i];
    for (size_t c = 0; c < p.corners.pixels.size(); ++c) {
      const auto pixel =
          result->camera.Project(state.cam_from_board[i] * p.corners.board_points[c]);
      if (pixel) squared += (*pixel - p.corners.pixels[c]).squaredNorm();
    }
  }
  result->corner_rms_px = std::sqrt(squared / std::max(1, result->corners));
}

}  // namespace

JointIntrinsicsResult RefineIntrinsicsJointly(const std::vector<PairFeatures>& pairs,
                                              const SolverResult& solution,
                                              const CameraModel& camera,
                                              const SolverOptions& solver,
                                              const JointIntrinsicsOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw std::invalid_argument(why);
  State state;
  std::vector<JointPair> joint = JointPairs(pairs, solution, &state.cam_from_board);
  if (joint.size() < 3)
    throw std::invalid_argument(
        "the joint refinement needs 3 pairs with corners and a LiDAR "
        "plane, " +
        std::to_string(joint.size()) + " have them");
  const std::vector<int> active = ActiveParameters(camera, options.refine);
  JointIntrinsicsResult result;
  for (const JointPair& p : joint) {
    result.pair_ids.push_back(p.id);
    result.corners += static_cast<int>(p.corners.pixels.size());
    result.edge_points += static_cast<int>(p.edges.size());
  }
  result.planes = static_cast<int>(joint.size());
  state.intrinsics = IntrinsicParameters(camera);
  state.cam_from_lidar = solution.cam_from_lidar;
  state.dilation_m.assign(joint.size(),
                          solution.edge_dilation ? solution.edge_dilation->value_m : 0.0);
  JointProblem problem(std::move(joint), camera, active, solver.edge_floor_sigma_m, options);
  SetCameraPrior(camera, active, state, &problem);
  std::vector<double> corner_sigmas;
  for (const PairFeatures& f : pairs)
    if (f.camera && f.camera->corner_sigma_px > 0)
      corner_sigmas.push_back(f.camera->corner_sigma_px);
  problem.SetScales(corner_sigmas.empty() ? 0.3 : Median(corner_sigmas), 1.0,
                    solution.edge_variance_factor > 0 ? solution.edge_variance_factor : 1.0);

  result.converged = MinimizeWithVarianceComponents(options, &problem, &state, &result.iterations);
  FillResult(problem, state, camera, active, &result);
  return result;
}

}  // namespace calibench
