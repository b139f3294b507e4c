// Where the LiDAR's rings leave the board: points on the sheet's boundary that constrain the
// extrinsic within the board plane (issue 5, board-edge constraints). Planes fix a board's tilt
// and distance only; its in-plane position comes from other poses, so with few pairs the
// translation along the boards is weak. The sheet's edges, seen by the camera through the board
// pose and by the LiDAR as the ends of each ring's run of board returns, tie it down.
#pragma once

#include <string>
#include <vector>

#include "core/geometry/geometry.h"
#include "core/lidar/board_returns.h"  // LidarEdgePoint
#include "core/lidar/cloud.h"

namespace calibench {

struct BoardEdgeOptions {
  // The return beyond the board must lie at least this far behind the board plane along its ray
  // (metres): a return in front is an occluder, one on the plane a coplanar neighbour (a hand,
  // the stand), and neither shows where the sheet ends.
  double min_background_gap_m = 0.15;
  // Neighbouring returns further apart than this (degrees of azimuth) leave the crossing too
  // uncertain (a dropped return): no edge point there.
  double max_azimuth_gap_deg = 0.6;
  // A ring-less scan (a Livox-class rosette, a nodding fan) stored in firing order: consecutive
  // returns further apart than this (degrees between their rays), or than firing_step_over_median
  // times the board's median step when that is wider, are not neighbours on the beam's path (a
  // dropped return, the pattern's jump), so no crossing lies between them. A laser of a scanner
  // that shares its point rate among several (an Avia's six) steps farther than one alone.
  double max_firing_step_deg = 0.6;
  double firing_step_over_median = 2.0;
  // The cloud counts as stored in firing order when the median angle between consecutive board
  // returns is below this (degrees) and at least min_consecutive_fraction of the board's returns
  // are followed by another: a cloud sorted or filtered otherwise keeps no beam path.
  double max_median_firing_step_deg = 0.8;
  double min_consecutive_fraction = 0.5;
  bool Check(std::string* why) const;
};

// What the ring ends of a board said about its edges: how many ends there were, how many gave an
// edge point, and why the others did not (observed, per end).
struct BoardEdgeEnds {
  int ends = 0;         // ends of rings with at least two board returns
  int edge_points = 0;  // ends that gave an edge point
  int no_return = 0;    // no return beyond the board on the ring (or one too far in azimuth)
  int not_behind = 0;   // the return beyond lies in front of or on the board's plane
  bool operator==(const BoardEdgeEnds&) const = default;
};

// Ring ends of the inliers of a fitted board plane (n·x + d = 0, LiDAR frame). Uses the cloud's
// rings (or infers them); a ring whose neighbouring return is missing, occluding or coplanar
// gives no point at that end. `ends` (optional) receives the tally.
std::vector<LidarEdgePoint> ExtractBoardEdgePoints(const LidarCloud& cloud,
                                                   const std::vector<int>& inliers,
                                                   const Plane& plane,
                                                   const BoardEdgeOptions& options,
                                                   BoardEdgeEnds* ends = nullptr);

// Where the beam of a ring-less scan crosses the sheet's border: the returns of a fitted board
// plane whose neighbour in firing order (the cloud's storage order) missed the board and lies well
// behind it. A rosette crosses a board's border hundreds of times in a second's hold, every
// crossing an edge point like a ring's end. Returns none, with *no_search saying why, when the
// cloud does not keep its firing order (judged from the board's own returns).
std::vector<LidarEdgePoint> ExtractBeamCrossingEdgePoints(
    const LidarCloud& cloud, const std::vector<int>& inliers, const Plane& plane,
    const BoardEdgeOptions& options, BoardEdgeEnds* ends, std::string* no_search);

// Residual of one edge point against the sheet (half sizes in metres, board frame as BoardSpec):
// the signed distance, in the board plane, from the point to the sheet edge nearest to it
// (positive outside). `camera_from_board` is the PnP pose. With `jacobian`, d/d(delta) for the
// right perturbation cam_from_lidar·Exp(delta), [rho; phi]; with `sigma_m`, the residual's
// standard deviation from the crossing's uncertainty along the ring and `floor_sigma_m`. With
// `board_pose_jacobian`, d/d(xi) for the right perturbation camera_from_board·Exp(xi) of the
// camera's board pose, [rho; phi]: every edge point of a pair shares that pose's error.
double BoardEdgeResidual(const Pose& cam_from_lidar, const Pose& camera_from_board,
                         const Vec2& sheet_half_size_m, const LidarEdgePoint& edge,
                         double floor_sigma_m, Eigen::Matrix<double, 1, 6>* jacobian,
                         double* sigma_m,
                         Eigen::Matrix<double, 1, 6>* board_pose_jacobian = nullptr);

}  // namespace calibench
