#include "core/lidar_camera/time_offset.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "core/geometry/geometry.h"

namespace calibench {
namespace {

std::string Words(const char* format, double a, double b = 0, double c = 0, double d = 0) {
  char text[320];
  std::snprintf(text, sizeof(text), format, a, b, c, d);
  return text;
}

// The profile's solver: the planes whitened by both covariances, no robust weights, no gate and no
// variance components (the edges' share would be re-estimated at each offset), so that the costs
// at different offsets compare.
SolverOptions ProfileSolverOptions(const SolverOptions& solver) {
  SolverOptions lean = solver;
  lean.method = SolverMethod::kWeightedMl;
  lean.use_board_edges = false;
  lean.outlier_gate = 0.0;
  lean.whitened_huber_delta = 1e9;
  lean.jackknife_covariance = false;
  lean.sandwich_covariance = false;
  return lean;
}

struct ProfilePoint {
  double offset_s = 0.0;
  double cost = 0.0;
  Pose cam_from_lidar = Pose::Identity();
  int residuals = 0;
};

class Profile {
 public:
  Profile(std::vector<const PairFeatures*> pairs, const PipelineOptions& options)
      : pairs_(std::move(pairs)),
        options_(options.time_offset),
        solver_(ProfileSolverOptions(options.solver)) {}

  // The solve at one offset, from `start`; nullopt where a pair's frames do not hold its instant.
  std::optional<ProfilePoint> At(double offset_s, const Pose& start) const {
    std::vector<PlanePair> planes;
    for (const PairFeatures* p : pairs_) {
      std::optional<CameraBoardObservation> board = *p->camera;
      if (BoardMoved(*p, options_))
        board = BoardAtTime(p->camera_track, LidarInstantS(*p) + offset_s, options_.track);
      if (!board) return std::nullopt;
      planes.push_back(MakePlanePair(p->id, *p->lidar, *board));
    }
    PlaneAlignmentSolver solver(planes, solver_, start);
    const SolverResult result = solver.Run();
    if (result.cost_history.empty()) return std::nullopt;
    return ProfilePoint{offset_s, result.cost_history.back(), result.cam_from_lidar,
                        3 * static_cast<int>(planes.size())};
  }

 private:
  std::vector<const PairFeatures*> pairs_;
  const TimeOffsetOptions& options_;
  SolverOptions solver_;
};

// c0 + c1 x + c2 x² through the points (least squares), x about `centre`.
Vec3 FitParabola(const std::vector<ProfilePoint>& points, double centre) {
  Eigen::MatrixXd a(points.size(), 3);
  Eigen::VectorXd b(points.size());
  for (size_t k = 0; k < points.size(); ++k) {
    const double x = points[k].offset_s - centre;
    a.row(static_cast<Eigen::Index>(k)) << 1.0, x, x * x;
    b(static_cast<Eigen::Index>(k)) = points[k].cost;
  }
  return a.colPivHouseholderQr().solve(b);
}

// `points` into the estimate's profile, kept in the offset's order (one point per offset).
void KeepInProfile(const std::vector<ProfilePoint>& points, TimeOffsetEstimate* e) {
  std::map<double, double> profile;
  for (size_t k = 0; k < e->profile_offsets_s.size(); ++k)
    profile[e->profile_offsets_s[k]] = e->profile_costs[k];
  for (const ProfilePoint& p : points) profile.emplace(p.offset_s, p.cost);
  e->profile_offsets_s.clear();
  e->profile_costs.clear();
  for (const auto& [offset_s, cost] : profile) {
    if (!e->profile_offsets_s.empty() && offset_s - e->profile_offsets_s.back() < 1e-9) continue;
    e->profile_offsets_s.push_back(offset_s);
    e->profile_costs.push_back(cost);
  }
}

// The grid over the window: a moving pair takes part where its frames hold its instant at
// every offset of it (the same pairs at every offset, or the costs would not compare); still
// pairs always. Counts the moving ones into e->profiled_pairs.
std::vector<const PairFeatures*> CoveredPairs(const std::vector<const PairFeatures*>& accepted,
                                              const TimeOffsetOptions& o, int steps,
                                              TimeOffsetEstimate* e) {
  std::vector<const PairFeatures*> profiled;
  for (const PairFeatures* p : accepted) {
    const bool moved = BoardMoved(*p, o);
    bool covered = true;
    for (int k = -steps; k <= steps && covered && moved; ++k)
      covered = BoardAtTime(p->camera_track, LidarInstantS(*p) + k * o.step_s, o.track).has_value();
    if (!covered) continue;
    profiled.push_back(p);
    e->profiled_pairs += moved;
  }
  return profiled;
}

// About the grid's best: a fifth of its step (kept in the profile), a parabola through it, the
// offset and its σ, and how the pose follows the offset there; e->why says why not where it fails.
void Refine(const Profile& profile, const ProfilePoint& best, const TimeOffsetOptions& o,
            TimeOffsetEstimate* out) {
  TimeOffsetEstimate& e = *out;
  // A fifth of the step about the best, and a parabola through it.
  std::vector<ProfilePoint> fine;
  for (int k = -5; k <= 5; ++k)
    if (auto point = profile.At(best.offset_s + k * o.step_s / 5, best.cam_from_lidar))
      fine.push_back(*point);
  KeepInProfile(fine, &e);
  const Vec3 c = FitParabola(fine, best.offset_s);
  if (fine.size() < 5 || !(c(2) > 0)) {
    e.why = "the planes' agreement does not curve about its best offset: the motion cannot tell it";
    return;
  }
  const double offset = best.offset_s - c(1) / (2 * c(2));
  const std::optional<ProfilePoint> at = profile.At(offset, best.cam_from_lidar);
  if (!at) {
    e.why = "the frames do not hold the best offset's instants";
    return;
  }
  // cost = ½χ²: the profile's curvature is the inverse of the offset's variance, scaled by the
  // fit's variance factor where the planes scatter more than their covariances say.
  const int dof = std::max(1, at->residuals - 7);
  const double variance_factor = std::max(1.0, 2.0 * at->cost / dof);
  e.camera_minus_lidar_s = offset;
  e.std_s = std::sqrt(variance_factor / (2.0 * c(2)));
  const double h = o.step_s / 5;
  const auto ahead = profile.At(offset + h, at->cam_from_lidar);
  const auto behind = profile.At(offset - h, at->cam_from_lidar);
  if (ahead && behind)
    e.pose_rate = (LogSE3(at->cam_from_lidar.inverse() * ahead->cam_from_lidar) -
                   LogSE3(at->cam_from_lidar.inverse() * behind->cam_from_lidar)) /
                  (2 * h);
  e.why = Words(
      "searched over +-%.0f ms: the planes of %.0f moving pairs agree best there "
      "(variance factor %.2f)",
      o.search_s * 1e3, e.profiled_pairs, variance_factor);
}

// The grid over +-steps: the window coarse_steps apart, then every step about the coarse best
// (the profile's basin is wider than the coarse step, so the best of the whole grid is among
// them: about 45 solves where every step would take 2 * steps + 1), each point kept in the
// profile. Its best, or nullopt with e->why where it lies on the window's edge.
std::optional<ProfilePoint> SearchGrid(const Profile& profile, const TimeOffsetOptions& o,
                                       int steps, const Pose& initial, TimeOffsetEstimate* e) {
  const int stride = std::clamp(o.coarse_steps, 1, steps);
  std::map<int, ProfilePoint> grid;  // by step index
  auto solve_at = [&](int k, const Pose& from) {
    if (grid.count(k)) return;
    if (std::optional<ProfilePoint> point = profile.At(k * o.step_s, from)) grid.emplace(k, *point);
  };
  auto lowest = [&] {
    return std::min_element(grid.begin(), grid.end(), [](const auto& a, const auto& b) {
      return a.second.cost < b.second.cost;
    });
  };
  Pose start = initial;
  for (int k = -steps; k <= steps; k = k < steps ? std::min(k + stride, steps) : k + 1) {
    solve_at(k, start);
    if (const auto at = grid.find(k); at != grid.end())
      start = at->second.cam_from_lidar;  // the next offset's solve starts near
  }
  if (grid.empty()) {
    e->why = "no solve converged over the search window";
    return std::nullopt;
  }
  const auto coarse_best = lowest();
  const int centre = coarse_best->first;
  const Pose from = coarse_best->second.cam_from_lidar;
  for (int k = std::max(-steps, centre - stride + 1); k <= std::min(steps, centre + stride - 1);
       ++k)
    solve_at(k, from);
  std::vector<ProfilePoint> solved;
  for (const auto& [k, point] : grid) solved.push_back(point);
  KeepInProfile(solved, e);
  const auto best = lowest();
  if (best == grid.begin() || std::next(best) == grid.end()) {
    e->why = Words(
        "the planes agree best at the search window's edge (%+.0f ms): widen "
        "--time-offset-search",
        best->second.offset_s * 1e3);
    return std::nullopt;
  }
  return best->second;
}

}  // namespace

bool TimeOffsetOptions::Check(std::string* why) const {
  auto fail = [&](const char* text) {
    if (why) *why = text;
    return false;
  };
  if (!(search_s > 0 && search_s <= 5.0))
    return fail("the time offset's search must be in (0, 5] s");
  if (fixed_s && !(std::abs(*fixed_s) <= 60.0)) return fail("a time offset must be within 60 s");
  if (!(step_s > 0 && step_s <= search_s))
    return fail("the time offset's step must be in (0, search]");
  if (coarse_steps < 1) return fail("the time offset's coarse_steps must be >= 1");
  if (!(min_speed_mps >= 0)) return fail("min_speed_mps must be >= 0");
  if (min_moving_pairs < 3) return fail("min_moving_pairs must be >= 3");
  return track.Check(why);
}

double LidarInstantS(const PairFeatures& pair) {
  if (!pair.lidar || pair.lidar->inlier_times_s.empty()) return 0.0;
  std::vector<float> times = pair.lidar->inlier_times_s;
  std::nth_element(times.begin(), times.begin() + times.size() / 2, times.end());
  return times[times.size() / 2];
}

bool BoardMoved(const PairFeatures& pair, const TimeOffsetOptions& options) {
  return pair.camera_track.size() >= 2 &&
         MotionOf(pair.camera_track).speed_mps >= options.min_speed_mps;
}

bool PlaceCameraBoardAt(PairFeatures* pair, double camera_minus_lidar_s,
                        const TimeOffsetOptions& options) {
  if (pair->camera_track.empty()) return true;
  std::optional<CameraBoardObservation> board =
      BoardAtTime(pair->camera_track, LidarInstantS(*pair) + camera_minus_lidar_s, options.track);
  if (!board) return false;
  pair->camera = std::move(board);
  return true;
}

TimeOffsetEstimate EstimateTimeOffset(const std::vector<PairFeatures>& pairs,
                                      const PipelineOptions& options, const Pose& initial) {
  const TimeOffsetOptions& o = options.time_offset;
  TimeOffsetEstimate e;
  std::vector<const PairFeatures*> accepted;
  for (const PairFeatures& p : pairs)
    if (p.status == PairStatus::kAccepted && p.lidar && p.camera) {
      accepted.push_back(&p);
      e.moving_pairs += BoardMoved(p, o);
    }
  if (o.fixed_s) {
    e.camera_minus_lidar_s = *o.fixed_s;
    e.fixed = true;
    e.why = "given (--time-offset)";
    return e;
  }
  if (e.moving_pairs < o.min_moving_pairs) {
    e.why = e.moving_pairs == 0
                ? "every pair is a still hold (one image, or a board its frames saw still): "
                  "the motion cannot tell the two clocks apart"
                : Words(
                      "only %.0f pairs of a moving board (at least %.0f needed): the motion "
                      "cannot tell the two clocks apart",
                      e.moving_pairs, o.min_moving_pairs);
    return e;
  }
  const int steps = std::max(1, static_cast<int>(std::lround(o.search_s / o.step_s)));
  const std::vector<const PairFeatures*> profiled = CoveredPairs(accepted, o, steps, &e);
  if (e.profiled_pairs < o.min_moving_pairs) {
    e.why = Words(
        "the frames around only %.0f of %.0f moving pairs cover the whole search "
        "window (+-%.0f ms): the offset is not searched",
        e.profiled_pairs, e.moving_pairs, o.search_s * 1e3);
    return e;
  }
  const Profile profile(profiled, options);
  const std::optional<ProfilePoint> best = SearchGrid(profile, o, steps, initial, &e);
  if (best) Refine(profile, *best, o, &e);
  return e;
}

void PlaceBoardsInTime(const PipelineOptions& options, CalibrationOutcome* outcome) {
  const bool moving = std::any_of(outcome->pairs.begin(), outcome->pairs.end(),
                                  [](const PairFeatures& p) { return !p.camera_track.empty(); });
  std::optional<Pose> start = options.initial_cam_from_lidar;
  if (moving && !start && !options.time_offset.fixed_s) {
    std::vector<PlanePair> planes;
    for (const PairFeatures& p : outcome->pairs)
      if (p.status == PairStatus::kAccepted)
        planes.push_back(MakePlanePair(p.id, *p.lidar, *p.camera));
    std::string why;
    start = InitialGuessFromPlanes(planes, &why);
  }
  outcome->time_offset =
      EstimateTimeOffset(outcome->pairs, options, start.value_or(Pose::Identity()));
  if (!outcome->time_offset.camera_minus_lidar_s) return;
  const double offset = *outcome->time_offset.camera_minus_lidar_s;
  for (PairFeatures& p : outcome->pairs)
    if (p.status == PairStatus::kAccepted && !PlaceCameraBoardAt(&p, offset, options.time_offset)) {
      p.status = PairStatus::kFailed;
      p.reason =
          "camera: its frames do not show the board at the LiDAR's instant under the time "
          "offset";
    }
}

std::string DescribeTimeOffset(const TimeOffsetEstimate& e) {
  if (!e.camera_minus_lidar_s) return "time offset: not estimated (" + e.why + ")";
  const double ms = *e.camera_minus_lidar_s * 1e3;
  if (e.fixed) return Words("time offset: camera - LiDAR %+.1f ms, given", ms);
  return Words("time offset: camera - LiDAR %+.1f ms +- %.1f ms", ms, e.std_s * 1e3) +
         (ms >= 0 ? " (the camera's stamps late)" : " (the camera's stamps early)") +
         Words(", from %.0f moving pairs", e.profiled_pairs);
}

}  // namespace calibench
