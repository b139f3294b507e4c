// The offset between the camera's and the LiDAR's clocks, from a waved board
// (docs/architecture.md "Time"): each moving pair's LiDAR board is compared with the camera's
// board where it was at the LiDAR's instant on the camera's clock (board_track.h); the offset
// that lets every pair's planes agree best under one extrinsic is the estimate.
//
// The search is the profile likelihood of the offset: at each offset of a grid over the search
// window, the extrinsic is solved (planes whitened by both covariances, no robust weights, so the
// costs compare) and its cost kept; a finer grid about the best, a parabola through its lowest
// points gives the offset and, from its curvature scaled by the fit's variance factor, σ — the
// offset's marginal σ as the joint covariance of (extrinsic, offset) would give it. How the pose
// moves with the offset (pose_rate) then widens the pose's covariance by the offset's σ.
#pragma once

#include "core/lidar_camera/pipeline.h"

namespace calibench {

// The LiDAR's instant of a pair's board: the median of its inliers' times (LidarPlaneFit::
// inlier_times_s), seconds after its lidar_stamp_ns; 0 where the cloud had no per-point times.
double LidarInstantS(const PairFeatures& pair);

// Whether the camera saw the pair's board move (its track, fast enough to tell an offset).
bool BoardMoved(const PairFeatures& pair, const TimeOffsetOptions& options);

// A moving pair's camera board at its LiDAR instant + offset (`camera` replaced); false, and
// `camera` untouched, where its frames do not hold that instant. Still pairs: true, unchanged.
bool PlaceCameraBoardAt(PairFeatures* pair, double camera_minus_lidar_s,
                        const TimeOffsetOptions& options);

// The accepted pairs' offset as the module's comment says; options.fixed_s is taken as given.
// `initial`: where each solve starts (the planes' closed form, or the user's guess).
TimeOffsetEstimate EstimateTimeOffset(const std::vector<PairFeatures>& pairs,
                                      const PipelineOptions& options, const Pose& initial);

// A moving capture's clocks (EstimateTimeOffset, into outcome->time_offset), and each moving
// pair's camera board where it was at its LiDAR instant under that offset; a pair whose frames do
// not hold that instant is left out, saying so. Without an offset (still holds, or one the motion
// cannot tell) each pair keeps the board of its frame nearest the sweep. SolveFromFeatures' step
// before the solve.
void PlaceBoardsInTime(const PipelineOptions& options, CalibrationOutcome* outcome);

// "time offset: camera - LiDAR +40.3 ms +- 1.2 ms (the camera's stamps late), from 57 moving
// pairs" or why there is none.
std::string DescribeTimeOffset(const TimeOffsetEstimate& estimate);

}  // namespace calibench
