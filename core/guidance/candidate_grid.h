// The candidate board poses guidance chooses from (next_pose.h, NextBestPose): a grid of
// distances, image cells and tilts, and what tells candidates apart before there is a solution.
// Internal to core/guidance.
#pragma once

#include <utility>
#include <vector>

#include "core/guidance/next_pose.h"

namespace calibench {

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
std::vector<Candidate> CandidateGrid(const SensorGeometry& sensors, const GuidanceOptions& options);

// A board where one was already held adds what that pose added: if the model over-promises there
// (a detection noisier than its bound), suggesting it again would repeat the disappointment.
bool NearAHeldBoard(const Pose& cam_from_board, const std::vector<Pose>& seen,
                    const GuidanceOptions& options);

// How many of the cells the intrinsics still need a candidate puts board corners in.
int CellsCovered(const SensorGeometry& sensors, const Pose& cam_from_board,
                 const std::vector<Eigen::AlignedBox2d>& cells);

// Without a solution: unlike what was seen (normals and positions), frontal first; ties by the
// distance from the middle of the usable range. Lower is better.
std::pair<double, double> StarterScore(const Candidate& c, const std::vector<Pose>& seen);

}  // namespace calibench
