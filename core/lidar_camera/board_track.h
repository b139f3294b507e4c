// A waved board as the camera saw it over time (docs/architecture.md "Time"): the PnP poses of a
// moving capture's frames, and the board between them — where it was at the instant the LiDAR's
// returns saw it, on the camera's clock, for a time offset between the two clocks.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/target/board_camera.h"

namespace calibench {

// One frame's board: its stamp (camera clock) minus its pair's lidar_stamp_ns, in seconds.
struct TimedObservation {
  double stamp_s = 0.0;
  CameraBoardObservation observation;
};

struct BoardTrackOptions {
  // Two frames farther apart than this (seconds) hold no board between them: the detector missed
  // the frames in between, and the board may have turned.
  double max_gap_s = 0.25;
  bool Check(std::string* why) const;
};

// The board at `stamp_s` (same origin as the track's stamps), between the frames around it: a
// cubic Hermite spline (Catmull-Rom tangents from the neighbouring frames) through the positions
// and, in the tangent space of the segment's first frame, through the rotations — a spline on
// SE(3) through the PnP poses; the pose covariance blended from the two frames around it, the
// plane and its covariance from those (SetBoardPlaneFromPose). nullopt before the first frame,
// after the last, or across a gap. `track` in stamp order.
std::optional<CameraBoardObservation> BoardAtTime(const std::vector<TimedObservation>& track,
                                                  double stamp_s,
                                                  const BoardTrackOptions& options = {});

// How far the board moves over the track (metres between its first and last centre, and the
// largest turn between frames, degrees): whether the frames can tell a time offset at all.
struct TrackMotion {
  double speed_mps = 0.0;  // median over the frames' steps
  double largest_step_deg = 0.0;
};
TrackMotion MotionOf(const std::vector<TimedObservation>& track);

// The offset between the camera's and the LiDAR's clocks (core/lidar_camera/time_offset.h).
struct TimeOffsetOptions {
  double search_s = 0.25;         // --time-offset-search: half-width of the search (seconds)
  std::optional<double> fixed_s;  // --time-offset: known, not searched
  double step_s = 0.005;          // the grid's step about the best; the finest a fifth of it
  // The whole window is first searched this many steps apart (a board at 0.5 m/s moves 1.25 cm
  // in 25 ms: the profile's basin spans several such steps), then every step about its best.
  int coarse_steps = 5;
  // A pair tells the offset when the camera saw its board move at least this fast (m/s).
  double min_speed_mps = 0.05;
  int min_moving_pairs = 6;
  BoardTrackOptions track;
  bool Check(std::string* why) const;
};

struct TimeOffsetEstimate {
  // A camera stamp minus the LiDAR clock's time of the same instant (seconds; +0.040: the
  // camera's stamps are 40 ms late); absent where the motion cannot tell it (`why`).
  std::optional<double> camera_minus_lidar_s;
  double std_s = 0.0;
  bool fixed = false;      // given, not estimated
  int moving_pairs = 0;    // pairs whose board moved (their frames' track)
  int profiled_pairs = 0;  // of those, covered over the whole search window
  std::string why;         // why it is absent, or how it was found
  // The profile: the solve's cost against the offset (the report plots it).
  std::vector<double> profile_offsets_s, profile_costs;
  // How the pose moves per second of offset at the estimate (right perturbation [rho; phi]):
  // the pose's covariance gains rate σ² rateᵀ.
  Vec6 pose_rate = Vec6::Zero();
};

}  // namespace calibench
