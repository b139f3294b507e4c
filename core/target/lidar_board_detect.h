// The board found in a LiDAR cloud without a seed or a brush: planar segments grown over the
// sensor's angular neighbourhoods, kept when their outline matches the sheet and they stand free of
// what lies behind them, optionally checked against a background model of the dataset's static
// scene (the board moves between pairs, walls and cabinets do not).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/board/board.h"
#include "core/geometry/geometry.h"
#include "core/lidar/cloud.h"
#include "core/target/scene_background.h"

namespace calibench {

struct LidarBoardDetectionOptions {
  // Growing a planar segment: a neighbour joins when it lies within plane_tolerance_m of the
  // segment's plane and, where its own neighbourhood is planar, its normal is within
  // normal_tolerance_deg of the segment's. ~3σ of a VLP-16's range noise.
  double plane_tolerance_m = 0.03;
  double normal_tolerance_deg = 25.0;
  // Half size of the neighbourhood a return's local plane is fitted over (metres), at least one
  // ring step.
  double neighbourhood_half_size_m = 0.05;
  // A neighbourhood is planar when its RMS about its own plane is below this (metres).
  double planar_rms_m = 0.025;
  int min_points = 25;  // fewer = no candidate (a VLP-16 sees ~60 returns on an A3 sheet at 3 m)
  // Outline: the segment's minimum-area rectangle may exceed the sheet by this much per side
  // (beam width and edge returns), and its convex hull must cover at least min_fill of the sheet
  // (sparse rings cut a sheet's top and bottom off; 3 rings over an 0.85 m sheet cover ~40%).
  double size_tolerance_m = 0.10;
  double min_fill = 0.3;
  double max_fill = 1.3;
  // Without a sheet size (BoardSpec::board_width = 0) the sheet is taken as at least the pattern
  // plus this margin per side and at most the pattern plus max_unknown_margin_m per side.
  double min_unknown_margin_m = 0.01;
  double max_unknown_margin_m = 0.25;
  // Standing free: along the segment's border the next return must lie at least edge_jump_m
  // behind the segment's plane (or be missing) for at least min_free_edge_fraction of the border.
  double edge_jump_m = 0.04;
  double min_free_edge_fraction = 0.5;
  // A candidate whose returns sit on the static background (SceneBackground) for more than this
  // fraction is rejected: a board-sized panel on a wall stays put, the board moves.
  double max_static_fraction = 0.5;
  // Two candidates whose scores are within this ratio are ambiguous: the pair fails naming both.
  double ambiguity_ratio = 0.85;
  double min_range_m = 0.3;   // closer returns are the rig itself
  double max_range_m = 40.0;  // farther returns cannot resolve a printed sheet
  // Ring-less clouds (swept or solid-state LiDARs): cells of an azimuth x elevation grid, in
  // degrees; 0 = from the cloud's angular density (about one return per cell).
  double angular_cell_deg = 0.0;
  bool Check(std::string* why) const;
};

// A planar segment that could be the board.
struct LidarBoardCandidate {
  std::vector<int> indices;      // into the cloud
  Plane plane;                   // LiDAR frame, normal towards the LiDAR (d > 0)
  Vec3 centre = Vec3::Zero();    // centroid of the returns, metres
  Vec2 extent_m = Vec2::Zero();  // minimum-area rectangle: long side, short side
  double hull_area_m2 = 0.0;     // convex hull of the returns in the plane
  double rms_m = 0.0;            // about the plane
  int rings = 0;                 // rows of the angular grid it spans
  double free_edge_fraction = 0.0;
  double static_fraction = 0.0;  // on the background model; 0 without one
  double score = 0.0;            // 0..1, higher is more board-like
  std::string rejection;         // why it is not the board; empty for a candidate
  // "a 0.79 x 0.58 m plane at 2.9 m, azimuth 12 deg": width x height in the order of the board's
  // own size (board_size: the longer side first for a board wider than tall).
  std::string Describe(const BoardSpec& board) const;
};

struct LidarBoardDetection {
  std::optional<LidarBoardCandidate> board;      // absent when nothing matched or it was ambiguous
  double confidence = 0.0;                       // 0..1; the score, discounted by a close second
  std::vector<LidarBoardCandidate> candidates;   // that passed every test, best first
  std::vector<LidarBoardCandidate> near_misses;  // the best few that failed a test, best first
  std::string reason;  // why `board` is absent, naming the best near-miss or both rivals
  // The cloud's flat neighbourhoods' median RMS about their planes (metres, about half the range
  // noise): the planarity and growing thresholds widen to 3 and 5 times it where it exceeds
  // what the options assume.
  double local_rms_m = 0.0;
};

// Finds the board in one cloud (BoardSpec::SheetWidth/Height, or the pattern's extent plus a
// margin when the sheet size is unknown). `background` may be null.
LidarBoardDetection DetectLidarBoard(const LidarCloud& cloud, const BoardSpec& board,
                                     const LidarBoardDetectionOptions& options,
                                     const SceneBackground* background = nullptr);

}  // namespace calibench
