// The beam pattern of a non-repetitive scanner (Livox-class): one beam steered by two wedge prisms
// turning at different rates (a Risley pair), so that the field fills as a rosette whose petals
// never repeat; or, for the 360° kind, a spinning head whose elevation sweeps on a rate that never
// locks to the spin. A sensor model: the simulator fires it, and code that needs to know where a
// Livox-class scanner looks (coverage of a hold, expected returns) can ask it.
#pragma once

#include <string>
#include <vector>

#include "core/base/types.h"

namespace calibench {

// Field of view and timing of one scanner. Angles in degrees, rates in Hz.
struct RisleyPattern {
  std::string name;                   // "mid40", "avia", "mid360"
  bool spinning = false;              // 360° about z (Mid-360-like) rather than a cone about +x
  double half_fov_h_deg = 19.2;       // cone: half width across azimuth (spinning: unused)
  double half_fov_v_deg = 19.2;       // cone: half height; spinning: half of the elevation band
  double centre_elevation_deg = 0.0;  // spinning: the elevation band's centre
  double points_per_s = 100000.0;
  double prism1_hz = 121.7;  // the two prisms' turning rates (opposite signs: a rosette)
  double prism2_hz = -83.3;
  double spin_hz = 10.0;  // spinning only
  double max_range_m = 90.0;
  double min_range_m = 0.5;
  // Lasers sharing the prisms (a Livox driver's "line": Avia 6, Mid-360 4, Mid-40 1), sharing
  // points_per_s. A cone's lasers sit in a column: each draws the rosette shifted by
  // laser_spacing_deg in elevation. The 360° kind's lasers are spread over its elevation sweep's
  // phase instead. (Their exact layout is not published: an assumed geometry, denser per frame.)
  int lasers = 1;
  double laser_spacing_deg = 0.0;
};

// "mid40" (38.4° circle, 100 k points/s, 1 laser), "avia" (70.4° × 77.2°, 240 k/s as its triple
// echo; here 200 k/s, 6 lasers), "mid360" (360° × 59°, −7° to 52°, 200 k/s, 4 lasers). Throws
// std::invalid_argument naming the known ones for any other name.
RisleyPattern MakeRisleyPattern(const std::string& name);
std::string RisleyPatternNames();  // "mid40, avia, mid360"

// The unit ray directions (LiDAR frame: x forward, z up) fired from time start_s for duration_s,
// each with its time offset from start_s (seconds): laser by laser, each laser's in firing order
// (as `import` stores a Livox driver's interleaved returns), with each ray's laser.
struct RisleyRays {
  std::vector<Vec3> directions;
  std::vector<double> time_offsets_s;
  std::vector<int> laser;
};
// Whether a direction (LiDAR frame, any length) lies inside the pattern's field of view: the
// rosette's ellipse of azimuth × elevation about +x, or the 360° kind's band of elevation.
bool InRisleyField(const RisleyPattern& pattern, const Vec3& direction);

RisleyRays FireRisleyPattern(const RisleyPattern& pattern, double start_s, double duration_s);

}  // namespace calibench
