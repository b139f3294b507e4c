#include "core/guidance/next_pose.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/estimation/fisher_information.h"
#include "core/estimation/uncertainty.h"
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
  if (!(range_sigma_m > 0) || !(corner_sigma_px > 0))
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

// Facing the camera along `bearing` (z away from the camera, x near camera x), turned by yaw
// about the board's vertical axis, pitch about its horizontal axis and roll in its plane.
Mat3 BoardRotation(const Vec3& bearing, double yaw_deg, double pitch_deg, double roll_deg) {
  const Vec3 z = bearing.normalized();
  const Vec3 x = (Vec3::UnitX() - Vec3::UnitX().dot(z) * z).normalized();
  Mat3 facing;
  facing << x, z.cross(x), z;
  return facing * Eigen::AngleAxisd(yaw_deg * kDegToRad, Vec3::UnitY()).toRotationMatrix() *
         Eigen::AngleAxisd(pitch_deg * kDegToRad, Vec3::UnitX()).toRotationMatrix() *
         Eigen::AngleAxisd(roll_deg * kDegToRad, Vec3::UnitZ()).toRotationMatrix();
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
  if (f.distance_m < sensors.min_distance_m - 1e-9 ||
      f.distance_m > sensors.max_distance_m + 1e-9) {
    std::snprintf(text, sizeof(text), "%.1f m from the camera, outside the usable %.1f-%.1f m",
                  f.distance_m, sensors.min_distance_m, sensors.max_distance_m);
    f.why = text;
    return f;
  }
  // The sheet must face the camera (its back would show no pattern).
  if (camera_normal.dot(cam_from_board.translation()) <= 0 ||
      f.camera_incidence_deg > options.max_incidence_deg) {
    f.why = TooOblique("camera", f.camera_incidence_deg, options.max_incidence_deg);
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
  // The smallest square's width in pixels, at the pattern's centre.
  const double s = sensors.board.square_size;
  const auto a = sensors.camera.Project(cam_from_board * Vec3(0, 0, 0));
  const auto b = sensors.camera.Project(cam_from_board * Vec3(s, 0, 0));
  const auto c = sensors.camera.Project(cam_from_board * Vec3(0, s, 0));
  if (a && b && c && std::min((*b - *a).norm(), (*c - *a).norm()) < options.min_square_px) {
    std::snprintf(text, sizeof(text), "the squares would be under %.0f px wide in the image",
                  options.min_square_px);
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
  pair.lidar_covariance =
      LidarPlaneBoundCovariance(returns.points, pair.lidar_plane, sensors.range_sigma_m);
  pair.lidar_edges = returns.edges;
  pair.camera_from_board = cam_from_board;
  pair.sheet_half_size_m =
      Vec2(0.5 * sensors.board.SheetWidth(), 0.5 * sensors.board.SheetHeight());
  return pair;
}

namespace {

// One pose of the candidate grid (camera frame, BoardSpec's board frame).
struct Candidate {
  Pose cam_from_board = Pose::Identity();
  bool middle_row = false;    // in the image's middle band
  double turn_deg = 0.0;      // |yaw| + |pitch| + |roll| of the grid
  double off_axis = 0.0;      // |bearing − optical axis|
  double off_centre_m = 0.0;  // distance from the middle of the usable range
  bool moderate = false;      // |yaw|, |pitch| <= 30 degrees
};

// Distances across the usable range × image cells × the tilts of GuidanceOptions.
std::vector<Candidate> CandidateGrid(const SensorGeometry& sensors,
                                     const GuidanceOptions& options) {
  std::vector<Candidate> grid;
  const double middle = 0.5 * (sensors.min_distance_m + sensors.max_distance_m);
  for (int di = 0; di < options.distance_steps; ++di) {
    const double distance =
        options.distance_steps == 1
            ? middle
            : sensors.min_distance_m + (sensors.max_distance_m - sensors.min_distance_m) * di /
                                           (options.distance_steps - 1);
    for (int col = 0; col < options.image_columns; ++col) {
      for (int row = 0; row < options.image_rows; ++row) {
        const Vec2 pixel(sensors.camera.width * (col + 0.5) / options.image_columns,
                         sensors.camera.height * (row + 0.5) / options.image_rows);
        const auto bearing = sensors.camera.Unproject(pixel);
        if (!bearing) continue;
        for (double yaw : options.yaw_deg) {
          for (double pitch : options.pitch_deg) {
            for (double roll : options.roll_deg) {
              Candidate c;
              c.cam_from_board.linear() = BoardRotation(*bearing, yaw, pitch, roll);
              c.cam_from_board.translation() = distance * bearing->normalized();
              c.middle_row = options.image_rows == 1 || row == options.image_rows / 2;
              c.turn_deg = std::abs(yaw) + std::abs(pitch) + std::abs(roll);
              c.off_axis = (bearing->normalized() - Vec3::UnitZ()).norm();
              c.off_centre_m = std::abs(distance - middle);
              c.moderate = std::abs(yaw) <= 30 && std::abs(pitch) <= 30;
              grid.push_back(c);
            }
          }
        }
      }
    }
  }
  return grid;
}

// A board where one was already held adds what that pose added: if the model over-promises there
// (a detection noisier than its bound), suggesting it again would repeat the disappointment.
bool NearAHeldBoard(const Pose& cam_from_board, const std::vector<Pose>& seen,
                    const GuidanceOptions& options) {
  for (const Pose& held : seen)
    if ((held.translation() - cam_from_board.translation()).norm() < options.repeat_distance_m &&
        RotationAngle(held.linear(), cam_from_board.linear()) <
            options.repeat_angle_deg * kDegToRad)
      return true;
  return false;
}

// Without a solution: unlike what was seen (normals and positions), frontal first; ties by the
// distance from the middle of the usable range. Lower is better.
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

// How many of the cells the intrinsics still need a candidate puts board corners in.
int CellsCovered(const SensorGeometry& sensors, const Pose& cam_from_board,
                 const std::vector<Eigen::AlignedBox2d>& cells) {
  if (cells.empty()) return 0;
  std::vector<char> hit(cells.size(), 0);
  for (const Vec3& corner : BoardCornerPoints(sensors.board)) {
    const auto pixel = sensors.camera.Project(cam_from_board * corner);
    if (!pixel) continue;
    for (size_t k = 0; k < cells.size(); ++k) hit[k] |= cells[k].contains(*pixel);
  }
  return static_cast<int>(std::count(hit.begin(), hit.end(), 1));
}

std::pair<double, double> StarterScore(const Candidate& c, const std::vector<Pose>& seen) {
  if (seen.empty()) return {c.turn_deg + c.off_axis, c.off_centre_m};
  double nearest = 1e9;
  for (const Pose& s : seen) {
    const double angle =
        std::acos(std::clamp(s.linear().col(2).dot(c.cam_from_board.linear().col(2)), -1.0, 1.0));
    nearest = std::min(nearest, angle + (s.translation() - c.cam_from_board.translation()).norm());
  }
  return {-nearest, c.off_centre_m};
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

std::optional<PoseSuggestion> NextBestPose(const SensorGeometry& sensors,
                                           const std::optional<SolverResult>& solution,
                                           const std::vector<Pose>& seen, const CaptureGoal& goal,
                                           const GuidanceOptions& options,
                                           const SolverOptions& solver_options, std::string* why) {
  if (!sensors.Check(why) || !goal.Check(why) || !options.Check(why)) return std::nullopt;
  const std::optional<Pose> cam_from_lidar =
      solution ? std::optional<Pose>(solution->cam_from_lidar) : std::nullopt;
  Mat6 current_information = Mat6::Zero();
  if (solution) {
    Eigen::LDLT<Mat6> ldlt(solution->covariance);
    if (ldlt.info() == Eigen::Success && ldlt.isPositive())
      current_information = ldlt.solve(Mat6::Identity());
  }
  const Mat6 discount = solution ? InformationDiscount(*solution) : Mat6::Identity();
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
      // The model's information, discounted by how much wider than the model the reported
      // covariance is (the pairs' scatter on real sensors): a new pair is expected to help as
      // much as the ones seen so far did.
      const Mat6 model_added = ExpectedPoseInformation(
          {PlannedPair(sensors, *cam_from_lidar, c.cam_from_board, returns)}, *cam_from_lidar,
          solver_options, solution->plane_variance_factor, solution->edge_variance_factor);
      const Mat6 added = discount * model_added * discount.transpose();
      const Mat6 predicted = (current_information + added).inverse();
      // The sum of squared σ/goal over the six axes (A-optimal in units of the goal: the weakest
      // axis dominates it), the largest ratio breaking ties. Chasing the largest ratio alone
      // alternates between axes and took more poses in the guided sweep (OS0-128 + fisheye: 16
      // against 11.5 poses, median of 4 seeds).
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
  std::optional<PoseSuggestion> best =
      LowestScore(&feasible, cam_from_lidar.has_value(), options.intrinsics_cover_weight);
  if (!best) {
    *why = "none of the " + std::to_string(grid.size()) +
           " candidate board poses is feasible or new" +
           (last_reason.empty() ? std::string() : " (the last refused: " + last_reason + ")");
    return std::nullopt;
  }
  best->words = DescribeBoardPose(sensors.camera, best->cam_from_board);
  if (best->intrinsics_cells_covered > 0)
    best->words += "; it puts corners in " + std::to_string(best->intrinsics_cells_covered) +
                   " of the " + std::to_string(options.intrinsics_cells_to_cover.size()) +
                   " image cells the intrinsics still lack";
  return best;
}

SuggestionMatch MatchSuggestion(const Pose& cam_from_board, const PoseSuggestion& suggestion,
                                const GuidanceOptions& options) {
  SuggestionMatch match;
  match.offset_m = (cam_from_board.translation() - suggestion.cam_from_board.translation()).norm();
  const double cosine =
      cam_from_board.linear().col(2).dot(suggestion.cam_from_board.linear().col(2));
  match.angle_deg = std::acos(std::clamp(cosine, -1.0, 1.0)) * kRadToDeg;
  match.matches =
      match.offset_m <= options.repeat_distance_m && match.angle_deg <= options.repeat_angle_deg;
  char tolerance[80] = "";
  if (!match.matches)
    std::snprintf(tolerance, sizeof(tolerance), " (within %.0f mm and %.0f deg counts)",
                  options.repeat_distance_m * 1e3, options.repeat_angle_deg);
  char text[200];
  std::snprintf(text, sizeof(text), "%s the ghost board: %.0f mm from it, tilted %.0f deg%s",
                match.matches ? "matches" : "does not match", match.offset_m * 1e3, match.angle_deg,
                tolerance);
  match.words = text;
  return match;
}

}  // namespace calibench
