#include "core/lidar_camera/board_track.h"

#include <algorithm>
#include <cmath>

#include "core/geometry/geometry.h"

namespace calibench {

bool BoardTrackOptions::Check(std::string* why) const {
  if (max_gap_s > 0 && std::isfinite(max_gap_s)) return true;
  if (why) *why = "the largest gap between a track's frames must be > 0 s";
  return false;
}

std::optional<CameraBoardObservation> BoardAtTime(const std::vector<TimedObservation>& track,
                                                  double stamp_s,
                                                  const BoardTrackOptions& options) {
  if (track.empty() || stamp_s < track.front().stamp_s || stamp_s > track.back().stamp_s)
    return std::nullopt;
  if (track.size() == 1) return track.front().observation;
  // The segment [i, i + 1] holding the instant.
  const auto after =
      std::upper_bound(track.begin(), track.end(), stamp_s,
                       [](double t, const TimedObservation& o) { return t < o.stamp_s; });
  const size_t i =
      std::min<size_t>(std::max<std::ptrdiff_t>(after - track.begin(), 1), track.size() - 1) - 1;
  const TimedObservation& a = track[i];
  const TimedObservation& b = track[i + 1];
  const double h = b.stamp_s - a.stamp_s;
  if (h <= 0 || h > options.max_gap_s) return std::nullopt;
  const double u = (stamp_s - a.stamp_s) / h;
  // Positions and rotations (in a's tangent space) of the frames around the segment; a
  // neighbour beyond a gap gives no tangent (one-sided there).
  auto usable = [&](size_t k) {
    return k < track.size() &&
           std::abs(track[k].stamp_s - (k < i ? a.stamp_s : b.stamp_s)) <= options.max_gap_s;
  };
  const Mat3 ra_t = a.observation.cam_from_board.linear().transpose();
  auto state = [&](size_t k) {
    Vec6 x;
    x.head<3>() = track[k].observation.cam_from_board.translation();
    x.tail<3>() = LogSO3(ra_t * track[k].observation.cam_from_board.linear());
    return x;
  };
  const Vec6 xa = state(i), xb = state(i + 1);
  const Vec6 chord = (xb - xa) / h;
  const Vec6 ma = i >= 1 && usable(i - 1)
                      ? Vec6((xb - state(i - 1)) / (b.stamp_s - track[i - 1].stamp_s))
                      : chord;
  const Vec6 mb =
      usable(i + 2) ? Vec6((state(i + 2) - xa) / (track[i + 2].stamp_s - a.stamp_s)) : chord;
  // Cubic Hermite basis.
  const double u2 = u * u, u3 = u2 * u;
  const double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2,
               h11 = u3 - u2;
  const Vec6 x = h00 * xa + h10 * h * ma + h01 * xb + h11 * h * mb;
  CameraBoardObservation out = u < 0.5 ? a.observation : b.observation;
  out.cam_from_board.translation() = x.head<3>();
  out.cam_from_board.linear() = a.observation.cam_from_board.linear() * ExpSO3(x.tail<3>());
  out.pose_covariance = (1 - u) * a.observation.pose_covariance + u * b.observation.pose_covariance;
  SetBoardPlaneFromPose(&out);
  return out;
}

TrackMotion MotionOf(const std::vector<TimedObservation>& track) {
  TrackMotion motion;
  std::vector<double> speeds;
  for (size_t k = 0; k + 1 < track.size(); ++k) {
    const Pose& p = track[k].observation.cam_from_board;
    const Pose& q = track[k + 1].observation.cam_from_board;
    const double dt = track[k + 1].stamp_s - track[k].stamp_s;
    if (dt <= 0) continue;
    speeds.push_back((q.translation() - p.translation()).norm() / dt);
    motion.largest_step_deg = std::max(
        motion.largest_step_deg, LogSO3(p.linear().transpose() * q.linear()).norm() * kRadToDeg);
  }
  if (!speeds.empty()) {
    std::nth_element(speeds.begin(), speeds.begin() + speeds.size() / 2, speeds.end());
    motion.speed_mps = speeds[speeds.size() / 2];
  }
  return motion;
}

}  // namespace calibench
