// The rays a LiDAR fires and what a board sheet alone returns of them: the one ray caster the
// simulator (which adds the room, the panels, noise and intensities on top) and guidance (which
// asks whether a pose would be seen, and where the rings would cross the sheet's border) share,
// so that what guidance predicts is what the simulator scans (docs/architecture.md, "Sensor
// models").
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/base/types.h"
#include "core/lidar/beam_table.h"

namespace calibench {

// One crossing of a ring over the sheet's edge, on the board plane (LiDAR frame).
struct LidarEdgePoint {
  Vec3 point = Vec3::Zero();        // the crossing: midway between the last board return and
                                    // the first return beyond the board, on the plane
  Vec3 along_ring = Vec3::UnitX();  // unit, LiDAR frame: the ring's direction there, outwards
  // The crossing lies somewhere in the gap between those two returns: its standard deviation
  // along the ring is the gap's length / √12 (uniform).
  double sigma_along_m = 0.0;
};

// A ray: where it starts (the LiDAR's centre, or a swept scanner's mirror) and its unit direction.
struct BeamRay {
  Vec3 origin = Vec3::Zero();
  Vec3 direction = Vec3::UnitX();
};

// The rays of a beam table, ring by ring and azimuth step by step, with the firing phase of one
// sweep (the azimuth of step 0). Elevation sines and cosines are computed once. A Livox-class
// table's rays are one "ring" whose steps are the pattern's rays in firing order over the
// table's frame, starting phase / 2π seconds into the pattern: consecutive rays are neighbours on
// the rosette, so the crossings of a sheet's border are found as a ring's are.
class BeamRays {
 public:
  BeamRays(const BeamTable& beams, double azimuth_offset_rad);
  int rings() const { return static_cast<int>(cos_elevation_.size()); }
  int steps() const { return steps_; }
  bool fired() const { return fired_ != nullptr; }  // a fired sequence (Risley, learnt), not rings
  bool nodding() const { return nodding_; }
  double StepRad() const;
  // Step may be any integer: it wraps around the sweep.
  BeamRay Ray(int ring, int step) const;
  // When a step fires, as the fraction of the sweep after its start: a Risley pattern's rays at
  // their own times (its lasers' rays interleave in time though listed laser by laser), any
  // other's step / steps.
  double FiredFraction(int step) const;

 private:
  // A Risley pattern's directions, or a table's learnt rays.
  std::shared_ptr<const std::vector<Vec3>> fired_;
  std::shared_ptr<const std::vector<double>> fired_fraction_;  // a Risley pattern's, per ray
  bool nodding_ = false;  // steps tilt a fan (BeamTable::nodding) rather than turn it
  double tilt_first_rad_ = 0.0, tilt_step_rad_ = 0.0;
  std::vector<double> fan_rad_;
  std::vector<double> cos_elevation_, sin_elevation_;
  int steps_ = 0;
  double azimuth_offset_rad_ = 0.0;
  Vec3 mirror_offset_m_ = Vec3::Zero();
};

// Returns nearer than this are suppressed, as real sensors do (metres).
constexpr double kLidarMinRangeM = 0.3;

// A rectangle in the LiDAR frame: its frame (x, y in its plane, z its normal; the origin at its
// centre) and half its size (metres).
struct LidarRectangle {
  Pose lidar_from_rectangle = Pose::Identity();
  Vec2 half_size_m = Vec2::Zero();
};

// Where a ray meets a rectangle's plane in front of its origin: the range along the ray, the
// point in the rectangle's axes, and whether it lies on the rectangle. nullopt when the ray is
// parallel to the plane or meets it behind.
struct RectangleHit {
  double range_m = 0.0;
  Vec2 xy = Vec2::Zero();
  bool inside = false;
};
std::optional<RectangleHit> HitRectangle(const BeamRay& ray, const LidarRectangle& rectangle);

// A sheet's noise-free returns with nothing in front of it, and per ring where it leaves the
// sheet (between consecutive steps whose rays meet the sheet's plane within range, one on the
// sheet and one beside it: where the board-edge extraction measures a crossing).
struct BoardReturns {
  std::vector<Vec3> points;  // LiDAR frame, in firing order per ring
  std::vector<int> ring;
  std::vector<LidarEdgePoint> edges;
  std::vector<int> points_per_ring;  // one entry per ring of the table
  // A fired sequence's (a rosette, learnt rays: BeamTable::Fired): one "ring", no rings to count.
  bool fired = false;
};
// Casts only the steps whose azimuths the sheet spans (every step when it spans more than half
// the sweep), plus one each side.
BoardReturns CastBoardReturns(const BeamTable& beams, const LidarRectangle& sheet,
                              double azimuth_offset_rad = 0.0);

// Whether a board's returns are enough to find it and fit its plane: this many rings with at
// least this many returns each (a ring that only grazes a corner does not help a plane fit), and
// this many returns in all. A fired sequence's returns have no rings: their count decides.
struct BoardReturnsRule {
  int min_rings = 4;
  int min_points_per_ring = 3;
  int min_points = 40;
  bool Check(std::string* why) const;
  int RingsCovered(const BoardReturns& returns) const;
  // *why (optional): "N rings and M returns on the board, under the K rings and L returns ...".
  bool Met(const BoardReturns& returns, std::string* why = nullptr) const;
};

}  // namespace calibench
