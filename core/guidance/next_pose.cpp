#include "core/guidance/next_pose.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

#include "core/estimation/uncertainty.h"
#include "core/sim/crlb.h"

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
  if (min_rings < 1 || min_points < 3) return *why = "min_rings >= 1 and min_points >= 3", false;
  if (!(max_incidence_deg > 0 && max_incidence_deg < 90))
    return *why = "max_incidence_deg must be in (0, 90)", false;
  if (distance_steps < 1 || image_columns < 1 || image_rows < 1)
    return *why = "the candidate grid needs at least one step in each dimension", false;
  if (yaw_deg.empty() || pitch_deg.empty() || roll_deg.empty())
    return *why = "the candidate tilts must not be empty", false;
  return true;
}

namespace {

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}

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

BeamTable LearnBeamTable(const std::vector<const LidarCloud*>& clouds) {
  std::map<int, std::vector<double>> elevations;
  std::vector<double> gaps;
  for (const LidarCloud* cloud : clouds) {
    if (!cloud || !cloud->HasRing()) continue;
    std::map<int, std::vector<double>> azimuths;
    for (size_t i = 0; i < cloud->size(); ++i) {
      const Eigen::Vector3f& p = cloud->points[i];
      if (!p.allFinite() || p.squaredNorm() < 1e-6f) continue;
      elevations[cloud->ring[i]].push_back(std::atan2(p.z(), std::hypot(p.x(), p.y())));
      azimuths[cloud->ring[i]].push_back(std::atan2(p.y(), p.x()));
    }
    for (auto& [ring, values] : azimuths) {
      if (values.size() < 20) continue;
      std::sort(values.begin(), values.end());
      for (size_t k = 1; k < values.size(); ++k)
        if (values[k] - values[k - 1] > 1e-5) gaps.push_back(values[k] - values[k - 1]);
    }
  }
  BeamTable table;
  for (auto& [ring, values] : elevations)
    if (values.size() >= 20) table.elevations_rad.push_back(Median(values));
  std::sort(table.elevations_rad.begin(), table.elevations_rad.end());
  const double gap = Median(gaps);
  table.azimuth_steps = gap > 0 ? static_cast<int>(std::lround(2 * M_PI / gap)) : 0;
  return table;
}

std::optional<SensorGeometry> LearnSensorGeometry(const CameraModel& camera, const BoardSpec& board,
                                                  const BeamTable& lidar,
                                                  const std::vector<PairFeatures>& pairs,
                                                  std::string* why) {
  std::vector<double> distances, range_rms, corner_sigmas;
  for (const PairFeatures& p : pairs) {
    if (p.status != PairStatus::kAccepted || !p.lidar || !p.camera) continue;
    distances.push_back(p.camera->cam_from_board.translation().norm());
    range_rms.push_back(p.lidar->rms_m);
    corner_sigmas.push_back(p.camera->corner_sigma_px);
  }
  if (distances.empty()) {
    *why = "no accepted pair yet: the distances and the sensors' noise are learnt from the data";
    return std::nullopt;
  }
  if (lidar.elevations_rad.size() < 2 || lidar.azimuth_steps < 1) {
    *why = "the clouds carry no ring numbers: the LiDAR's beams cannot be learnt";
    return std::nullopt;
  }
  SensorGeometry sensors;
  sensors.camera = camera;
  sensors.board = board;
  sensors.lidar = lidar;
  const auto [nearest, farthest] = std::minmax_element(distances.begin(), distances.end());
  double low = *nearest * 0.9, high = *farthest * 1.1;
  if (high - low < 1.0) {
    const double centre = 0.5 * (low + high);
    low = centre - 0.5;
    high = centre + 0.5;
  }
  sensors.min_distance_m = std::max({low, *nearest - 0.5, 0.3});
  sensors.max_distance_m = std::max(high, sensors.min_distance_m + 0.5);
  sensors.range_sigma_m = std::max(Median(range_rms), 1e-3);
  sensors.corner_sigma_px = std::max(Median(corner_sigmas), 0.05);
  return sensors;
}

PredictedReturns PredictBoardReturns(const SensorGeometry& sensors, const Pose& lidar_from_board) {
  PredictedReturns out;
  const BeamTable& beams = sensors.lidar;
  if (beams.azimuth_steps < 1) return out;
  const Vec3 normal = lidar_from_board.linear().col(2);
  const Vec3 origin = lidar_from_board.translation();
  const double offset = normal.dot(origin);
  const Vec2 half(0.5 * sensors.board.SheetWidth(), 0.5 * sensors.board.SheetHeight());
  // Only the azimuths the sheet spans (around its centre's), plus one step each side.
  const double step = 2 * M_PI / beams.azimuth_steps;
  const double centre_azimuth = std::atan2(origin.y(), origin.x());
  double half_span = 0.0;
  for (const Vec3& c : SheetCorners(sensors.board)) {
    const Vec3 p = lidar_from_board * c;
    double d = std::atan2(p.y(), p.x()) - centre_azimuth;
    d = std::remainder(d, 2 * M_PI);
    half_span = std::max(half_span, std::abs(d));
  }
  const int first = static_cast<int>(std::floor((centre_azimuth - half_span) / step)) - 1;
  const int last = static_cast<int>(std::ceil((centre_azimuth + half_span) / step)) + 1;
  auto hit = [&](double elevation, double azimuth, Vec3* point, bool* on_sheet) {
    const Vec3 ray(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                   std::sin(elevation));
    const double denominator = normal.dot(ray);
    if (std::abs(denominator) < 1e-9) return false;
    const double range = offset / denominator;
    if (!(range > 0.3) || range > beams.max_range_m) return false;
    *point = range * ray;
    const Vec3 local = lidar_from_board.linear().transpose() * (*point - origin);
    *on_sheet = std::abs(local.x()) <= half.x() && std::abs(local.y()) <= half.y();
    return true;
  };
  for (int ring = 0; ring < static_cast<int>(beams.elevations_rad.size()); ++ring) {
    const double elevation = beams.elevations_rad[ring];
    int count = 0;
    Vec3 previous = Vec3::Zero();
    bool previous_on = false, previous_valid = false;
    for (int a = first; a <= last; ++a) {
      Vec3 point = Vec3::Zero();
      bool on = false;
      const bool valid = hit(elevation, a * step, &point, &on);
      if (valid && on) {
        out.points.push_back(point);
        out.ring.push_back(ring);
        ++count;
      }
      // A crossing of the sheet's edge: midway between the last return on the sheet and the
      // first beyond it, on the plane (as ExtractBoardEdgePoints measures it).
      if (valid && previous_valid && on != previous_on) {
        LidarEdgePoint edge;
        const Vec3& inside = on ? point : previous;
        const Vec3& outside = on ? previous : point;
        edge.point = 0.5 * (inside + outside);
        edge.along_ring = (outside - inside).normalized();
        edge.sigma_along_m = (outside - inside).norm() / std::sqrt(12.0);
        out.edges.push_back(edge);
      }
      previous = point;
      previous_on = on;
      previous_valid = valid;
    }
    out.rings += count >= 3;
  }
  return out;
}

Feasibility CheckFeasible(const SensorGeometry& sensors, const std::optional<Pose>& cam_from_lidar,
                          const Pose& cam_from_board, const GuidanceOptions& options,
                          PredictedReturns* returns) {
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
    std::snprintf(text, sizeof(text), "too oblique to the camera (%.0f deg, at most %.0f)",
                  f.camera_incidence_deg, options.max_incidence_deg);
    f.why = text;
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
      std::snprintf(text, sizeof(text), "too oblique to the LiDAR (%.0f deg, at most %.0f)",
                    f.lidar_incidence_deg, options.max_incidence_deg);
      f.why = text;
      return f;
    }
    PredictedReturns predicted = PredictBoardReturns(sensors, lidar_from_board);
    f.rings = predicted.rings;
    f.points = static_cast<int>(predicted.points.size());
    if (f.rings < options.min_rings || f.points < options.min_points) {
      std::snprintf(text, sizeof(text),
                    "too few LiDAR returns on the sheet (%d rings, %d points; at least %d and %d)",
                    f.rings, f.points, options.min_rings, options.min_points);
      f.why = text;
      return f;
    }
    if (returns) *returns = std::move(predicted);
  }
  f.feasible = true;
  return f;
}

PlanePair PlannedPair(const SensorGeometry& sensors, const Pose& cam_from_lidar,
                      const Pose& cam_from_board, const PredictedReturns& returns) {
  PlanePair pair;
  pair.id = "planned";
  // Camera plane: normal towards the camera (BoardSpec's z points away from it).
  const Vec3 camera_normal = -cam_from_board.linear().col(2);
  pair.camera_plane = Plane{camera_normal, -camera_normal.dot(cam_from_board.translation())};
  pair.camera_covariance = CameraPlaneBoundCovariance(
      sensors.camera, BoardCornerPoints(sensors.board), cam_from_board, sensors.corner_sigma_px);
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

Pose ShownFromBoardSpec() {
  Pose pose = Pose::Identity();
  pose.linear() = Eigen::AngleAxisd(M_PI, Vec3::UnitX()).toRotationMatrix();
  return pose;
}

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
  std::optional<PoseSuggestion> best;
  double best_score = std::numeric_limits<double>::infinity(), best_tie = best_score;
  int candidates = 0;
  std::string last_reason;
  for (int di = 0; di < options.distance_steps; ++di) {
    const double distance =
        options.distance_steps == 1
            ? 0.5 * (sensors.min_distance_m + sensors.max_distance_m)
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
              Pose cam_from_board = Pose::Identity();
              cam_from_board.linear() = BoardRotation(*bearing, yaw, pitch, roll);
              cam_from_board.translation() = distance * bearing->normalized();
              PredictedReturns returns;
              ++candidates;
              const Feasibility f =
                  CheckFeasible(sensors, cam_from_lidar, cam_from_board, options, &returns);
              if (!f.feasible) {
                last_reason = f.why;
                continue;
              }
              double score = 0.0, tie = 0.0;
              Vec3 sigma_t = Vec3::Zero(), sigma_r = Vec3::Zero();
              // A board where one was already held adds what that pose added: if the model
              // over-promises there (a detection noisier than its bound), suggesting it again
              // would repeat the same disappointment.
              bool repeat = false;
              for (const Pose& held : seen)
                repeat |= (held.translation() - cam_from_board.translation()).norm() <
                              options.repeat_distance_m &&
                          RotationAngle(held.linear(), cam_from_board.linear()) <
                              options.repeat_angle_deg * kDegToRad;
              if (repeat) continue;
              if (cam_from_lidar) {
                const PlanePair planned =
                    PlannedPair(sensors, *cam_from_lidar, cam_from_board, returns);
                // The model's information, discounted by how much wider than the model the
                // reported covariance is (the pairs' scatter on real sensors): a new pair is
                // expected to help as much as the ones seen so far did.
                const Mat6 added =
                    ExpectedPoseInformation({planned}, *cam_from_lidar, solver_options,
                                            solution->plane_variance_factor,
                                            solution->edge_variance_factor) /
                    std::max(1.0, solution->covariance_inflation);
                const Mat6 predicted = (current_information + added).inverse();
                // The sum of squared σ/goal over the six axes (A-optimal in units of the goal:
                // the weakest axis dominates it), the largest ratio breaking ties. Chasing the
                // largest ratio alone alternates between axes and took more poses in the
                // guided sweep (OS0-128 + fisheye: 16 against 11.5 poses, median of 4 seeds).
                std::tie(tie, score) = GoalScore(predicted, *cam_from_lidar, goal);
                sigma_t = SigmaT(predicted, *cam_from_lidar);
                sigma_r = RotationStdDeg(predicted, *cam_from_lidar);
              } else {
                // No solution yet: the LiDAR cannot be checked, so stay where a spinning LiDAR
                // beside the camera sees most (the image's middle band, moderate turns), unlike
                // what was seen (normals and positions), frontal first.
                if (options.image_rows > 1 && row != options.image_rows / 2) continue;
                if (std::abs(yaw) > 30 || std::abs(pitch) > 30) continue;
                double nearest = 1e9;
                for (const Pose& s : seen) {
                  const double angle = std::acos(
                      std::clamp(s.linear().col(2).dot(cam_from_board.linear().col(2)), -1.0, 1.0));
                  nearest = std::min(
                      nearest, angle + (s.translation() - cam_from_board.translation()).norm());
                }
                score = seen.empty() ? std::abs(yaw) + std::abs(pitch) + std::abs(roll) +
                                           (bearing->normalized() - Vec3::UnitZ()).norm()
                                     : -nearest;
                tie = std::abs(distance - 0.5 * (sensors.min_distance_m + sensors.max_distance_m));
              }
              if (score < best_score - 1e-12 || (score <= best_score + 1e-12 && tie < best_tie)) {
                best_score = score;
                best_tie = tie;
                PoseSuggestion suggestion;
                suggestion.cam_from_board = cam_from_board;
                if (cam_from_lidar)
                  suggestion.lidar_from_board =
                      cam_from_lidar->inverse() * cam_from_board * ShownFromBoardSpec();
                suggestion.predicted_sigma_t_mm = sigma_t;
                suggestion.predicted_sigma_r_deg = sigma_r;
                suggestion.score = score;
                suggestion.feasibility = f;
                best = suggestion;
              }
            }
          }
        }
      }
    }
  }
  if (!best) {
    *why = "none of the " + std::to_string(candidates) +
           " candidate board poses is feasible or new" +
           (last_reason.empty() ? std::string() : " (the last refused: " + last_reason + ")");
    return std::nullopt;
  }
  best->words = DescribeBoardPose(sensors.camera, best->cam_from_board);
  return best;
}

std::string DescribeBoardPose(const CameraModel& camera, const Pose& cam_from_board) {
  const Vec3 centre = cam_from_board.translation();
  char text[400];
  std::string words;
  std::snprintf(text, sizeof(text), "about %.1f m away", centre.norm());
  words = text;
  // Where in the image.
  const auto pixel = camera.Project(centre);
  if (pixel) {
    const double u = pixel->x() / camera.width, v = pixel->y() / camera.height;
    const char* column = u < 1.0 / 3 ? "left third" : u > 2.0 / 3 ? "right third" : "centre";
    const char* row = v < 1.0 / 3 ? "upper part" : v > 2.0 / 3 ? "lower part" : "";
    words += ", ";
    words += column;
    words += std::string(" of the image") + (row[0] ? std::string(", ") + row : "");
  }
  // The normal out of the print (towards the camera) in the frame that faces the camera.
  const Vec3 z = centre.normalized();
  const Vec3 x = (Vec3::UnitX() - Vec3::UnitX().dot(z) * z).normalized();
  const Vec3 y = z.cross(x);  // down in the image
  const Vec3 normal = -cam_from_board.linear().col(2);
  const double yaw = std::atan2(normal.dot(x), -normal.dot(z)) * kRadToDeg;
  const double pitch = std::atan2(normal.dot(y), -normal.dot(z)) * kRadToDeg;
  auto rounded = [](double deg) { return static_cast<int>(std::lround(std::abs(deg) / 5.0) * 5); };
  if (rounded(yaw) >= 10) {
    // The normal turned towards +x (right): the right edge went further, the left came nearer.
    std::snprintf(text, sizeof(text), ", turn it ~%d° about its vertical axis (%s edge nearer)",
                  rounded(yaw), yaw > 0 ? "left" : "right");
    words += text;
  }
  if (rounded(pitch) >= 10) {
    // The normal turned down (+y): the bottom edge went further, the top came nearer.
    std::snprintf(text, sizeof(text), ", tilt it ~%d° about its horizontal axis (%s edge nearer)",
                  rounded(pitch), pitch > 0 ? "top" : "bottom");
    words += text;
  }
  // In-plane rotation: the sheet's width axis against the image's horizontal. A rectangle looks
  // the same turned by 180°, so the angle is folded into (-90°, 90°].
  const Vec3 width_axis = cam_from_board.linear().col(0);
  double roll = std::atan2(width_axis.dot(y), width_axis.dot(x)) * kRadToDeg;
  if (roll > 90) roll -= 180;
  if (roll <= -90) roll += 180;
  if (rounded(roll) < 10) {
    words += ", keep it upright";
  } else {
    std::snprintf(text, sizeof(text), ", rotate it ~%d° %s in its own plane%s", rounded(roll),
                  roll > 0 ? "clockwise" : "anticlockwise",
                  rounded(roll) >= 35 && rounded(roll) <= 55 ? " (a diamond)" : "");
    words += text;
  }
  return words;
}

}  // namespace calibench
