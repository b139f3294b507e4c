#include "core/guidance/next_pose.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/estimation/fisher_information.h"
#include "core/estimation/uncertainty.h"
#include "core/guidance/candidate_grid.h"
#include "core/lidar_camera/solver.h"

namespace calibench {

bool CaptureGoal::Check(std::string* why) const {
  if (!(translation_mm > 0) || !std::isfinite(translation_mm))
    return *why = "the translation goal must be > 0 mm", false;
  if (!(rotation_deg > 0) || !std::isfinite(rotation_deg))
    return *why = "the rotation goal must be > 0 degrees", false;
  return true;
}

bool SensorGeometry::Check(std::string* why) const {
  if (!camera.Check(why)) return false;
  if (!board.Check(why)) return false;
  if (!(min_distance_m > 0 && max_distance_m > min_distance_m))
    return *why = "the distance range must satisfy 0 < min < max", false;
  if (!(range_sigma_m > 0) || !(corner_sigma_px > 0) || !(angular_sigma_rad >= 0))
    return *why = "the sensors' noise must be > 0", false;
  return true;
}

bool GuidanceOptions::Check(std::string* why) const {
  if (!(image_margin_fraction >= 0 && image_margin_fraction < 0.25))
    return *why = "image_margin_fraction must be in [0, 0.25)", false;
  if (!(min_square_px >= 0)) return *why = "min_square_px must be >= 0", false;
  if (!lidar_returns.Check(why)) return false;
  if (!(max_incidence_deg > 0 && max_incidence_deg < 90))
    return *why = "max_incidence_deg must be in (0, 90)", false;
  if (distance_steps < 1 || image_columns < 1 || image_rows < 1)
    return *why = "the candidate grid needs at least one step in each dimension", false;
  if (yaw_deg.empty() || pitch_deg.empty() || roll_deg.empty())
    return *why = "the candidate tilts must not be empty", false;
  if (!(intrinsics_cover_weight >= 0)) return *why = "intrinsics_cover_weight must be >= 0", false;
  if (!(hand_tolerance_m >= 0 && hand_tolerance_m <= 1.0))
    return *why = "the hand's tolerance must be in [0, 1] m", false;
  if (!(hand_tolerance_deg >= 0 && hand_tolerance_deg <= 45.0))
    return *why = "the hand's tolerance must be in [0, 45] degrees", false;
  if (hand_samples < 1 || robust_candidates < 1)
    return *why = "hand_samples and robust_candidates must be >= 1", false;
  if (!(reach_square_margin >= 1.0) || !(reach_angle_margin_deg >= 0))
    return *why = "the margins inside the detector's reach must be >= 1 and >= 0 deg", false;
  if (!(usable_max_incidence_deg >= max_incidence_deg && usable_max_incidence_deg < 90) ||
      !(usable_min_square_px >= 0 && usable_min_square_px <= min_square_px) ||
      !(usable_image_margin_fraction >= 0 &&
        usable_image_margin_fraction <= image_margin_fraction) ||
      !usable_lidar_returns.Check(why))
    return *why = "the usable limits must be at least as wide as the suggestions' limits", false;
  if (!(tolerance_usable_share > 0 && tolerance_usable_share <= 1))
    return *why = "tolerance_usable_share must be in (0, 1]", false;
  return true;
}

namespace {

// The sheet's corners in BoardSpec's frame.
std::vector<Vec3> SheetCorners(const BoardSpec& board) {
  const double hw = 0.5 * board.SheetWidth(), hh = 0.5 * board.SheetHeight();
  return {{-hw, -hh, 0}, {hw, -hh, 0}, {hw, hh, 0}, {-hw, hh, 0}};
}

// The angle between a plane's normal and the ray from the sensor to a point on it.
double IncidenceDeg(const Vec3& normal, const Vec3& point) {
  return std::acos(std::min(1.0, std::abs(normal.dot(point.normalized())))) * kRadToDeg;
}

Vec3 SigmaT(const Mat6& covariance, const Pose& cam_from_lidar) {
  return TranslationStd(covariance, cam_from_lidar) * 1e3;
}

// The largest σ/goal over the six axes, and the sum of their squares.
std::pair<double, double> GoalScore(const Mat6& covariance, const Pose& cam_from_lidar,
                                    const CaptureGoal& goal) {
  const Vec3 t = SigmaT(covariance, cam_from_lidar) / goal.translation_mm;
  const Vec3 r = RotationStdDeg(covariance, cam_from_lidar) / goal.rotation_deg;
  return {std::max(t.maxCoeff(), r.maxCoeff()), t.squaredNorm() + r.squaredNorm()};
}

}  // namespace

BoardReturns PredictBoardReturns(const SensorGeometry& sensors, const Pose& lidar_from_board) {
  LidarRectangle sheet;
  sheet.lidar_from_rectangle = lidar_from_board;
  sheet.half_size_m = 0.5 * Vec2(sensors.board.SheetWidth(), sensors.board.SheetHeight());
  return CastBoardReturns(sensors.lidar, sheet);
}

Feasibility CheckFeasible(const SensorGeometry& sensors, const std::optional<Pose>& cam_from_lidar,
                          const Pose& cam_from_board, const GuidanceOptions& options,
                          BoardReturns* returns) {
  Feasibility f;
  char text[200];
  f.distance_m = cam_from_board.translation().norm();
  const Vec3 camera_normal = cam_from_board.linear().col(2);
  f.camera_incidence_deg = IncidenceDeg(camera_normal, cam_from_board.translation());
  if (options.keep_to_distance_range && (f.distance_m < sensors.min_distance_m - 1e-9 ||
                                         f.distance_m > sensors.max_distance_m + 1e-9)) {
    std::snprintf(text, sizeof(text), "%.1f m from the camera, outside the usable %.1f-%.1f m",
                  f.distance_m, sensors.min_distance_m, sensors.max_distance_m);
    f.why = text;
    return f;
  }
  // The sheet must face the camera (its back would show no pattern), within the detector's reach
  // measured on this rig where it is narrower than the options'.
  const double max_camera_incidence = std::min(
      options.max_incidence_deg, sensors.reach.max_incidence_deg - options.reach_angle_margin_deg);
  if (camera_normal.dot(cam_from_board.translation()) <= 0 ||
      f.camera_incidence_deg > max_camera_incidence) {
    f.why = TooOblique("camera", f.camera_incidence_deg, max_camera_incidence);
    return f;
  }
  const double margin = options.image_margin_fraction * sensors.camera.width;
  const std::vector<Vec3> corners = SheetCorners(sensors.board);
  for (int e = 0; e < 4; ++e) {
    for (int k = 0; k < 8; ++k) {
      const Vec3 p = corners[e] + (corners[(e + 1) % 4] - corners[e]) * (k / 8.0);
      const Vec3 in_cam = cam_from_board * p;
      const auto pixel = in_cam.z() > 0.05 ? sensors.camera.Project(in_cam) : std::nullopt;
      if (!pixel || !sensors.camera.InImage(*pixel, margin)) {
        f.why = "the board would leave the image (the whole sheet must be inside it with a margin)";
        return f;
      }
    }
  }
  const BoardAppearance look = AppearanceOf(sensors.camera, sensors.board, cam_from_board);
  const double min_square_px =
      std::max(options.min_square_px,
               options.reach_square_margin *
                   std::max(DetectableSquarePx(sensors.board), sensors.reach.min_square_px));
  if (look.square_px < min_square_px) {
    std::snprintf(text, sizeof(text), "the squares would be %.0f px wide in the image, under %.0f",
                  look.square_px, min_square_px);
    f.why = text;
    return f;
  }
  const double max_off_axis = sensors.reach.max_off_axis_deg - options.reach_angle_margin_deg;
  if (look.off_axis_deg > max_off_axis) {
    std::snprintf(text, sizeof(text),
                  "%.0f deg off the optical axis, beyond the %.0f deg this rig's detector reaches",
                  look.off_axis_deg, max_off_axis);
    f.why = text;
    return f;
  }
  if (cam_from_lidar) {
    const Pose lidar_from_board = cam_from_lidar->inverse() * cam_from_board;
    const Vec3 lidar_normal = lidar_from_board.linear().col(2);
    f.lidar_incidence_deg = IncidenceDeg(lidar_normal, lidar_from_board.translation());
    if (lidar_normal.dot(lidar_from_board.translation()) <= 0 ||
        f.lidar_incidence_deg > options.max_incidence_deg) {
      f.why = TooOblique("LiDAR", f.lidar_incidence_deg, options.max_incidence_deg);
      return f;
    }
    BoardReturns predicted = PredictBoardReturns(sensors, lidar_from_board);
    f.rings = options.lidar_returns.RingsCovered(predicted);
    f.points = static_cast<int>(predicted.points.size());
    std::string short_by;
    if (!options.lidar_returns.Met(predicted, &short_by)) {
      f.why = "too few LiDAR returns on the sheet (" + short_by + ")";
      return f;
    }
    if (returns) *returns = std::move(predicted);
  }
  f.feasible = true;
  return f;
}

PlanePair PlannedPair(const SensorGeometry& sensors, const Pose& cam_from_lidar,
                      const Pose& cam_from_board, const BoardReturns& returns) {
  PlanePair pair;
  pair.id = "planned";
  // Camera plane: normal towards the camera (BoardSpec's z points away from it).
  const Vec3 camera_normal = -cam_from_board.linear().col(2);
  pair.camera_plane = Plane{camera_normal, -camera_normal.dot(cam_from_board.translation())};
  const std::vector<Vec3> corners = BoardCornerPoints(sensors.board);
  pair.camera_covariance =
      CameraPlaneBoundCovariance(sensors.camera, corners, cam_from_board, sensors.corner_sigma_px);
  pair.camera_pose_covariance =
      CameraPoseBoundCovariance(sensors.camera, corners, cam_from_board, sensors.corner_sigma_px);
  const Pose lidar_from_board = cam_from_lidar.inverse() * cam_from_board;
  const Vec3 lidar_normal = -lidar_from_board.linear().col(2);
  pair.lidar_plane = Plane{lidar_normal, -lidar_normal.dot(lidar_from_board.translation())};
  pair.lidar_covariance = LidarPlaneBoundCovariance(
      returns.points, pair.lidar_plane, sensors.range_sigma_m, sensors.angular_sigma_rad);
  pair.lidar_edges = returns.edges;
  pair.camera_from_board = cam_from_board;
  pair.sheet_half_size_m =
      Vec2(0.5 * sensors.board.SheetWidth(), 0.5 * sensors.board.SheetHeight());
  return pair;
}

namespace {

// What a new pair's model information is expected to be worth, as the map D of I ↦ D I Dᵀ. In
// the coordinates where the model's covariance is the identity (T = H^½, H the model's
// information), the reported covariance reads W = T C T: how much wider than the model each
// direction came out. The new pair is discounted by W^-½ on both sides, D = T W^-½ T⁻¹, which
// maps the seen pairs' own information H onto C⁻¹ exactly. A scalar discount by the largest
// widening would also shrink the directions the model got right, and favour poses for the
// wrong axis where the widening is lopsided.
Mat6 InformationDiscount(const SolverResult& solution) {
  const Eigen::SelfAdjointEigenSolver<Mat6> model(solution.model_covariance);
  if (model.info() != Eigen::Success || !(model.eigenvalues().minCoeff() > 0))
    return Mat6::Identity() / std::sqrt(std::max(1.0, solution.covariance_inflation));
  const Mat6 root = model.operatorInverseSqrt();  // T = M^-½ = H^½
  const Mat6 root_inverse = model.operatorSqrt();
  const Eigen::SelfAdjointEigenSolver<Mat6> widening(root * solution.covariance * root);
  // Never credit a pair with more than its model information (W ≥ I).
  const Vec6 shrink = widening.eigenvalues().cwiseMax(1.0).cwiseInverse().cwiseSqrt();
  return root * widening.eigenvectors() * shrink.asDiagonal() *
         widening.eigenvectors().transpose() * root_inverse;
}

// The feasible candidate (with its tie-breaker) of the lowest score, after the intrinsics' wish
// for corners where none are yet: a candidate costs up to cover_weight more (times its score with
// a solution, added without) for the share of the most any candidate covers that it leaves.
std::optional<PoseSuggestion> LowestScore(std::vector<std::pair<PoseSuggestion, double>>* feasible,
                                          bool with_solution, double cover_weight) {
  int most_covered = 0;
  for (const auto& [s, tie] : *feasible)
    most_covered = std::max(most_covered, s.intrinsics_cells_covered);
  std::optional<PoseSuggestion> best;
  std::pair<double, double> best_score(std::numeric_limits<double>::infinity(), 0.0);
  for (auto& [suggestion, tie] : *feasible) {
    if (most_covered > 0) {
      const double left =
          1.0 - static_cast<double>(suggestion.intrinsics_cells_covered) / most_covered;
      suggestion.score = with_solution ? suggestion.score * (1.0 + cover_weight * left)
                                       : suggestion.score + cover_weight * left;
    }
    if (suggestion.score < best_score.first - 1e-12 ||
        (suggestion.score <= best_score.first + 1e-12 && tie < best_score.second)) {
      best_score = {suggestion.score, tie};
      best = suggestion;
    }
  }
  return best;
}

}  // namespace

namespace {

// A candidate's worth under the solver's model: the predicted covariance after adding it.
struct InformationModel {
  const SensorGeometry* sensors = nullptr;
  const SolverResult* solution = nullptr;
  const SolverOptions* solver_options = nullptr;
  const CaptureGoal* goal = nullptr;
  Mat6 current_information = Mat6::Zero();
  Mat6 discount = Mat6::Identity();
  double current_score = 0.0;  // Σ (σ/goal)² now

  // The model's information of a pair held at cam_from_board, discounted by how much wider than
  // the model the reported covariance is (the pairs' scatter on real sensors): a new pair is
  // expected to help as much as the ones seen so far did.
  Mat6 PredictedCovariance(const Pose& cam_from_board, const BoardReturns& returns) const {
    const Pose& cam_from_lidar = solution->cam_from_lidar;
    const Mat6 model_added = ExpectedPoseInformation(
        {PlannedPair(*sensors, cam_from_lidar, cam_from_board, returns)}, cam_from_lidar,
        *solver_options, solution->plane_variance_factor, solution->edge_variance_factor);
    return (current_information + discount * model_added * discount.transpose()).inverse();
  }
};

// The options that judge a held placement: the pipeline's reach instead of the suggestions'.
GuidanceOptions UsableLimits(const GuidanceOptions& options) {
  GuidanceOptions usable = options;
  usable.max_incidence_deg = options.usable_max_incidence_deg;
  usable.min_square_px = options.usable_min_square_px;
  usable.image_margin_fraction = options.usable_image_margin_fraction;
  usable.lidar_returns = options.usable_lidar_returns;
  usable.reach_square_margin = 1.0;
  usable.keep_to_distance_range = false;  // where boards were held, not what the sensors reach
  usable.reach_angle_margin_deg = 0.0;
  return usable;
}

// The expected Σ (σ/goal)² after a board is held where a hand puts it for `target` (a placement
// the sensors cannot use adds nothing), and the share of usable placements. Without a model
// (no solution), the share only.
std::pair<double, double> UnderTheHand(const InformationModel& model,
                                       const std::optional<Pose>& cam_from_lidar,
                                       const std::vector<Pose>& placements,
                                       const GuidanceOptions& suggestion_options, bool with_score) {
  const GuidanceOptions options = UsableLimits(suggestion_options);
  double expected = 0.0;
  int usable = 0;
  for (const Pose& held : placements) {
    BoardReturns returns;
    const Feasibility f = CheckFeasible(*model.sensors, cam_from_lidar, held, options, &returns);
    usable += f.feasible;
    if (!with_score || !model.solution) continue;
    expected += f.feasible ? GoalScore(model.PredictedCovariance(held, returns), *cam_from_lidar,
                                       *model.goal)
                                 .second
                           : model.current_score;
  }
  const double n = static_cast<double>(placements.size());
  return {expected / n, usable / n};
}

// The widest of the hand's tolerance, halved in turn or place, halved in both, quartered, within
// which options.tolerance_usable_share of placements are usable; in words a person can follow.
HoldTolerance ToleranceOf(const InformationModel& model, const std::optional<Pose>& cam_from_lidar,
                          const Pose& target, double usable_share, const GuidanceOptions& options) {
  const double t = options.hand_tolerance_m, r = options.hand_tolerance_deg;
  const std::vector<std::pair<double, double>> steps{
      {t, r}, {t, 0.5 * r}, {0.5 * t, r}, {0.5 * t, 0.5 * r}, {0.25 * t, 0.25 * r}};
  HoldTolerance tolerance;
  char text[240];
  for (size_t k = 0; k < steps.size(); ++k) {
    const auto [metres, degrees] = steps[k];
    const double share =
        k == 0 ? usable_share
               : UnderTheHand(model, cam_from_lidar,
                              HandPlacements(target, metres, degrees, options.hand_samples),
                              options, /*with_score=*/false)
                     .second;
    if (share < options.tolerance_usable_share) continue;
    tolerance = {metres, degrees, share, ""};
    if (k == 0)
      std::snprintf(text, sizeof(text),
                    "anywhere within a hand's width of it is fine (±%.0f cm, ±%.0f°)", metres * 100,
                    degrees);
    else if (metres == t)
      std::snprintf(text, sizeof(text), "keep the tilt within %.0f° of it", degrees);
    else if (degrees == r)
      std::snprintf(text, sizeof(text), "keep it within %.0f cm of the spot", metres * 100);
    else
      std::snprintf(text, sizeof(text), "hold it within %.0f cm and %.0f° of it", metres * 100,
                    degrees);
    tolerance.words = text;
    return tolerance;
  }
  tolerance = {steps.back().first, steps.back().second, usable_share, ""};
  std::snprintf(text, sizeof(text),
                "hold it as exactly as you can: only %.0f %% of placements within a hand's width "
                "are usable",
                100 * usable_share);
  tolerance.words = text;
  return tolerance;
}

// Each feasible candidate scored again where a hand would hold it. With a solution: the
// robust_candidates best by their nominal score, by their expected score under the hand (the rest
// leave: their nominal scores do not compare), and among those whose expected gain is within 2 %
// of the best, the one usable most often. Without: only the candidates usable about as often as
// the most robust one stay.
void RobustToTheHand(const InformationModel& model, const std::optional<Pose>& cam_from_lidar,
                     const GuidanceOptions& options,
                     std::vector<std::pair<PoseSuggestion, double>>* feasible) {
  auto& list = *feasible;
  if (cam_from_lidar) {
    // By the nominal score as LowestScore will weigh it (the intrinsics' wish for corners where
    // none are yet), so the truncation keeps the poses that cover them.
    int most_covered = 0;
    for (const auto& [s, tie] : list)
      most_covered = std::max(most_covered, s.intrinsics_cells_covered);
    auto weighed = [&](const PoseSuggestion& s) {
      if (most_covered == 0) return s.score;
      return s.score *
             (1.0 + options.intrinsics_cover_weight *
                        (1.0 - static_cast<double>(s.intrinsics_cells_covered) / most_covered));
    };
    std::sort(list.begin(), list.end(),
              [&](const auto& a, const auto& b) { return weighed(a.first) < weighed(b.first); });
    if (static_cast<int>(list.size()) > options.robust_candidates)
      list.resize(options.robust_candidates);
  }
  double best_share = 0.0, best_expected = std::numeric_limits<double>::infinity();
  for (auto& [suggestion, tie] : list) {
    const auto [expected, share] =
        UnderTheHand(model, cam_from_lidar,
                     HandPlacements(suggestion.cam_from_board, options.hand_tolerance_m,
                                    options.hand_tolerance_deg, options.hand_samples),
                     options, /*with_score=*/true);
    suggestion.usable_share = share;
    best_share = std::max(best_share, share);
    if (cam_from_lidar) {
      suggestion.score = expected;
      best_expected = std::min(best_expected, expected);
    }
  }
  if (!cam_from_lidar) {
    std::erase_if(list, [&](const auto& s) { return s.first.usable_share < best_share - 0.05; });
    return;
  }
  const double best_gain = model.current_score - best_expected;
  for (auto& [suggestion, tie] : list) {
    if (model.current_score - suggestion.score < 0.98 * best_gain) continue;
    suggestion.score = best_expected;
    tie = -suggestion.usable_share;
  }
}

}  // namespace

std::optional<PoseSuggestion> NextBestPose(const SensorGeometry& sensors,
                                           const std::optional<SolverResult>& solution,
                                           const std::vector<Pose>& seen, const CaptureGoal& goal,
                                           const GuidanceOptions& options,
                                           const SolverOptions& solver_options, std::string* why) {
  if (!sensors.Check(why) || !goal.Check(why) || !options.Check(why)) return std::nullopt;
  const std::optional<Pose> cam_from_lidar =
      solution ? std::optional<Pose>(solution->cam_from_lidar) : std::nullopt;
  InformationModel model;
  model.sensors = &sensors;
  model.solver_options = &solver_options;
  model.goal = &goal;
  if (solution) {
    model.solution = &*solution;
    Eigen::LDLT<Mat6> ldlt(solution->covariance);
    if (ldlt.info() == Eigen::Success && ldlt.isPositive())
      model.current_information = ldlt.solve(Mat6::Identity());
    model.discount = InformationDiscount(*solution);
    model.current_score = GoalScore(solution->covariance, *cam_from_lidar, goal).second;
  }
  const std::vector<Candidate> grid = CandidateGrid(sensors, options);
  std::vector<std::pair<PoseSuggestion, double>> feasible;  // with its tie-breaker
  std::string last_reason;
  for (const Candidate& c : grid) {
    if (NearAHeldBoard(c.cam_from_board, seen, options)) continue;
    // No solution yet: the LiDAR cannot be checked, so stay where a spinning LiDAR beside the
    // camera sees most (the image's middle band, moderate turns).
    if (!cam_from_lidar && !(c.middle_row && c.moderate)) continue;
    BoardReturns returns;
    const Feasibility f =
        CheckFeasible(sensors, cam_from_lidar, c.cam_from_board, options, &returns);
    if (!f.feasible) {
      last_reason = f.why;
      continue;
    }
    PoseSuggestion suggestion;
    suggestion.cam_from_board = c.cam_from_board;
    suggestion.feasibility = f;
    std::pair<double, double> score;
    if (cam_from_lidar) {
      // The sum of squared σ/goal over the six axes (A-optimal in units of the goal: the weakest
      // axis dominates it), the largest ratio breaking ties. Chasing the largest ratio alone
      // alternates between axes and took more poses in the guided sweep (OS0-128 + fisheye: 16
      // against 11.5 poses, median of 4 seeds).
      const Mat6 predicted = model.PredictedCovariance(c.cam_from_board, returns);
      const auto [largest, sum_of_squares] = GoalScore(predicted, *cam_from_lidar, goal);
      score = {sum_of_squares, largest};
      suggestion.lidar_from_board =
          cam_from_lidar->inverse() * c.cam_from_board * ShownFromBoardSpec();
      suggestion.predicted_sigma_t_mm = SigmaT(predicted, *cam_from_lidar);
      suggestion.predicted_sigma_r_deg = RotationStdDeg(predicted, *cam_from_lidar);
    } else {
      score = StarterScore(c, seen);
    }
    if (!options.intrinsics_cells_to_cover.empty())
      suggestion.intrinsics_cells_covered =
          CellsCovered(sensors, c.cam_from_board, options.intrinsics_cells_to_cover);
    suggestion.score = score.first;
    feasible.push_back({std::move(suggestion), score.second});
  }
  if (feasible.empty()) {
    *why = "none of the " + std::to_string(grid.size()) +
           " candidate board poses is feasible or new" +
           (last_reason.empty() ? std::string() : " (the last refused: " + last_reason + ")");
    return std::nullopt;
  }
  RobustToTheHand(model, cam_from_lidar, options, &feasible);
  std::optional<PoseSuggestion> best =
      LowestScore(&feasible, cam_from_lidar.has_value(), options.intrinsics_cover_weight);
  best->tolerance =
      ToleranceOf(model, cam_from_lidar, best->cam_from_board, best->usable_share, options);
  best->words =
      DescribeBoardPose(sensors.camera, best->cam_from_board) + "; " + best->tolerance.words;
  if (best->intrinsics_cells_covered > 0)
    best->words += "; it puts corners in " + std::to_string(best->intrinsics_cells_covered) +
                   " of the " + std::to_string(options.intrinsics_cells_to_cover.size()) +
                   " image cells the intrinsics still lack";
  return best;
}

}  // namespace calibench
