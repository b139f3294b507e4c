// The candidate board poses guidance chooses from (candidate_grid.h).
#include "core/guidance/candidate_grid.h"

#include <algorithm>
#include <cmath>

namespace calibench {

namespace {

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

}  // namespace

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

bool NearAHeldBoard(const Pose& cam_from_board, const std::vector<Pose>& seen,
                    const GuidanceOptions& options) {
  for (const Pose& held : seen)
    if ((held.translation() - cam_from_board.translation()).norm() < options.repeat_distance_m &&
        RotationAngle(held.linear(), cam_from_board.linear()) <
            options.repeat_angle_deg * kDegToRad)
      return true;
  return false;
}

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

}  // namespace calibench
