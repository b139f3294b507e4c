// The sensor models of the LiDARs Calibench simulates and plans for: which LiDAR (by name) and
// its beam table, the rays it fires. Guidance predicts board returns from a table (learnt from
// the clouds, or a model's); the simulator scans with one.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/base/types.h"

namespace calibench {

// Spinning LiDARs (one centre, rings) and a swept single-line laser: a 2D scanner on a rotary
// stage whose scan plane turns about the stage's vertical axis, its mirror off that axis (the
// rays start on the moving mirror, not at the frame's origin; no rings), as the SICK LMS400 on a
// rotary stage of public swept sets.
enum class LidarModel { kHdl64, kVlp16, kOs0_128, kSwept2d };
std::string LidarModelName(LidarModel model);  // "hdl64", "vlp16", "os0-128", "swept-2d"
std::optional<LidarModel> ParseLidarModelName(const std::string& name);
std::string LidarModelNames();  // "hdl64, vlp16, os0-128, swept-2d", for messages

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
};
BeamTable MakeBeamTable(LidarModel model);

}  // namespace calibench
