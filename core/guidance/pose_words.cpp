// People's side of a board pose: the frame shown to them and the words to hold it by.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/guidance/next_pose.h"

namespace calibench {

Pose ShownFromBoardSpec() {
  Pose pose = Pose::Identity();
  pose.linear() = Eigen::AngleAxisd(M_PI, Vec3::UnitX()).toRotationMatrix();
  return pose;
}

std::string TooOblique(const char* sensor, double angle_deg, double max_deg) {
  char text[120];
  std::snprintf(text, sizeof(text), "too oblique to the %s (%.0f deg, at most %.0f)", sensor,
                angle_deg, max_deg);
  return text;
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

SuggestionMatch MatchSuggestion(const Pose& cam_from_board, const PoseSuggestion& suggestion,
                                const GuidanceOptions& options) {
  SuggestionMatch match;
  const Vec3 offset = cam_from_board.translation() - suggestion.cam_from_board.translation();
  match.offset_m = offset.norm();
  const double cosine =
      cam_from_board.linear().col(2).dot(suggestion.cam_from_board.linear().col(2));
  match.angle_deg = std::acos(std::clamp(cosine, -1.0, 1.0)) * kRadToDeg;
  // The suggestion's own tolerance (per axis, as the hand's error is drawn), else the repeat
  // distance (of the centre).
  const bool own = suggestion.tolerance.translation_m > 0 || suggestion.tolerance.rotation_deg > 0;
  const double metres = own ? suggestion.tolerance.translation_m : options.repeat_distance_m;
  const double degrees = own ? suggestion.tolerance.rotation_deg : options.repeat_angle_deg;
  match.matches = (own ? offset.cwiseAbs().maxCoeff() : match.offset_m) <= metres + 1e-9 &&
                  match.angle_deg <= degrees + 1e-9;
  char tolerance[80] = "";
  if (!match.matches)
    std::snprintf(tolerance, sizeof(tolerance), " (within %.0f mm%s and %.0f deg counts)",
                  metres * 1e3, own ? " per axis" : "", degrees);
  char text[200];
  std::snprintf(text, sizeof(text), "%s the ghost board: %.0f mm from it, tilted %.0f deg%s",
                match.matches ? "matches" : "does not match", match.offset_m * 1e3, match.angle_deg,
                tolerance);
  match.words = text;
  return match;
}

}  // namespace calibench
