// The sensor models of the LiDARs Calibench simulates and plans for: which LiDAR (by name) and
// its beam table, the rays it fires. Guidance predicts board returns from a table (learnt from
// the clouds, or a model's); the simulator scans with one.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/base/types.h"
#include "core/lidar/risley_pattern.h"

namespace calibench {

// Spinning LiDARs (one centre, rings) and a swept single-line laser: a 2D scanner on a rotary
// stage whose scan plane turns about the stage's vertical axis, its mirror off that axis (the
// rays start on the moving mirror, not at the frame's origin; no rings), as the SICK LMS400 on a
// rotary stage of public swept sets; and Livox-class non-repetitive scanners (one beam steered by
// a Risley prism pair, or the 360° kind: core/lidar/risley_pattern.h), whose rays all start at the
// origin but follow no rings.
// A nodding line scanner (kNodding2d): a 2D scanner's horizontal fan tilted up and down by a
// stage, its mirror a few centimetres off the tilt axis — a narrow whole scan of a room (28° of
// azimuth, 40° of tilt), not a board crop.
enum class LidarModel { kHdl64, kVlp16, kOs0_128, kSwept2d, kMid40, kAvia, kMid360, kNodding2d };
// "hdl64", "vlp16", "os0-128", "swept-2d", "mid40", "avia", "mid360", "nodding-2d"
std::string LidarModelName(LidarModel model);
std::optional<LidarModel> ParseLidarModelName(const std::string& name);
std::string LidarModelNames();  // "hdl64, vlp16, ...", for messages

// Learnt rays (BeamTable::rays) by 1° cell of azimuth (360) × elevation (180): the rays' field,
// and where to look for the rays a sheet can return (CastBoardReturns casts only those).
struct LearntRayCells {
  static constexpr int kCells = 360 * 180;
  std::vector<int> start;    // cell c's rays are by_cell[start[c], start[c + 1]), in firing order
  std::vector<int> by_cell;  // ray indices
  // A unit direction's cell: elevation index (0 = straight down) × 360 + azimuth index (0 = −π).
  static int CellOf(const Vec3& unit);
  bool Occupied(int cell) const { return start[cell + 1] > start[cell]; }
};

// A spinning LiDAR's beam table: elevation per ring (radians, ring 0 = lowest) and azimuth bins.
struct BeamTable {
  std::vector<double> elevations_rad;
  int azimuth_steps = 0;
  double max_range_m = 100.0;
  // A swept scanner (kSwept2d): elevations are the scanner's beam angles in its scan plane,
  // azimuth steps the stage's; every ray of a stage step starts at the mirror, this offset
  // (stage frame at azimuth 0) turned with the stage. Its clouds carry no rings.
  bool swept = false;
  Vec3 mirror_offset_m = Vec3::Zero();
  // A Livox-class scanner: no elevation table and no azimuth steps; its rays are the pattern's
  // over `frame_s` seconds (one 0.1 s frame, or a still hold integrated into one cloud), from the
  // origin, in firing order. Its clouds carry no rings.
  std::optional<RisleyPattern> risley;
  double frame_s = 0.1;
  // A nodding scanner (kNodding2d, with `swept`): elevations are the fan's beam angles (azimuths
  // in the scan plane) and azimuth steps the stage's tilt steps from tilt_first_rad to
  // tilt_last_rad (rotation about y; positive tilts the fan down); the mirror offset turns with
  // the tilt.
  bool nodding = false;
  double tilt_first_rad = 0.0, tilt_last_rad = 0.0;
  // A ring-less scanner of no known model, learnt from its own cloud (LearnBeamTable): the
  // directions of the cloud's returns, unit, from the origin, in the cloud's (firing) order. Over
  // the cloud's integration these are the rays it fires wherever something returned them; the
  // board, held where the scene was, returns the rays that fall on it. Shared: tables are copied
  // per candidate pose.
  std::shared_ptr<const std::vector<Vec3>> rays;
  std::shared_ptr<const LearntRayCells> ray_cells;  // the learnt rays by cell

  bool HasRings() const { return !swept && !Fired(); }
  // Whether its rays are a fired sequence (a Risley pattern's or learnt ones), not rings.
  bool Fired() const { return risley.has_value() || (rays && !rays->empty()); }
  // Whether a direction (LiDAR frame, any length) lies inside the rays' field.
  bool InField(const Vec3& direction) const;
  // The firing phases one sweep may start at: [0, PhaseSpanRad()) (a table's: one azimuth step;
  // a Risley pattern's: 2π, read as a start time within the pattern's first second).
  double PhaseSpanRad() const;
};
BeamTable MakeBeamTable(LidarModel model);

// A table of learnt rays (BeamTable::rays and their cells) from a ring-less cloud's returns: their
// directions from the origin, in the cloud's order (returns nearer than 1 cm skipped).
BeamTable LearntRayTable(const std::vector<Vec3>& returns);

}  // namespace calibench
