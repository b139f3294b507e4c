// How far this rig's board detector reaches, measured on the pairs so far: the smallest pattern
// square (pixels, foreshortening included) and the steepest view at which the camera found the
// board, against the pairs where it did not. Guidance proposes only poses inside that reach, and
// a pair lost near its edge is told why in words ("board too small in the image at 1.9 m").
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/board/board.h"
#include "core/camera/camera.h"
#include "core/lidar_camera/pipeline.h"

namespace calibench {

// What a board pose looks like to the detector.
struct BoardAppearance {
  double distance_m = 0.0;     // sheet centre from the camera
  double square_px = 0.0;      // a pattern square's narrowest width in the image, at the centre
  double incidence_deg = 0.0;  // the sheet's normal against the ray to its centre
  double off_axis_deg = 0.0;   // the ray to the sheet's centre against the optical axis
};

// cam_from_board in BoardSpec's frame (z away from the camera). The narrowest width is taken over
// eight directions in the sheet's plane, so it does not depend on the pattern's turn in its
// plane (which a LiDAR plane cannot tell).
BoardAppearance AppearanceOf(const CameraModel& camera, const BoardSpec& board,
                             const Pose& cam_from_board);

// The measured reach. 0 / 90 / 180 mean nothing measured: the options' defaults hold.
struct DetectionReach {
  double min_square_px = 0.0;
  double max_incidence_deg = 90.0;
  double max_off_axis_deg = 180.0;  // towards the image's rim (a fisheye's detector fails there)
  int boards_found = 0;             // pairs whose board the camera found
  int boards_missed = 0;            // pairs where it did not, with the board's place known
};

// The narrowest pattern square a detector can read with nothing measured yet: a chessboard's
// corners need about 8 px squares; a ChArUco marker about 1.5 px per cell of its bits and border
// (DICT_4X4: 6 cells), scaled from the marker to the square.
double DetectableSquarePx(const BoardSpec& board);

// Why the camera missed one pair's board, when the board's place is known (from its LiDAR plane
// and the current extrinsic): "board too small in the image at 1.9 m (squares 8 px wide; the
// detector needs about 12 px)".
struct MissedBoard {
  std::string id;
  BoardAppearance appearance;
  std::string words;
};

struct DetectionReachOptions {
  // A learned limit never relaxes the options' (GuidanceOptions' usable limits); it is set just
  // past a miss (by these margins) on the side of the boards found.
  double square_margin = 1.05;        // the miss's width × this is still a miss
  double incidence_margin_deg = 2.0;  // also for the angle off the optical axis
  // What no detector's failure is blamed on, however few boards were seen: squares wider than
  // this many times DetectableSquarePx, tilts under this, or the image's middle (angles off the
  // axis under this share of the half field of view along the image's width).
  double max_square_factor = 2.5;
  double min_incidence_deg = 40.0;
  double min_off_axis_share = 0.6;
  bool Check(std::string* why) const;
};

// From the pairs (PairFeatures as the pipeline left them): a camera detection is a board found
// (its PnP pose); a pair whose camera failed while its LiDAR plane was fitted is a board missed,
// placed by cam_from_lidar (no extrinsic: misses cannot be placed and nothing is learnt). Each
// limit (square width, then tilt, then the rim, each on the misses the one before leaves
// unexplained) is the one that misclassifies the fewest boards, the more cautious on ties.
DetectionReach LearnDetectionReach(const CameraModel& camera, const BoardSpec& board,
                                   const std::vector<PairFeatures>& pairs,
                                   const std::optional<Pose>& cam_from_lidar,
                                   const DetectionReachOptions& options,
                                   std::vector<MissedBoard>* missed = nullptr);

}  // namespace calibench
