// A report is drawn from a re-solve of the result's data (`calibench report`): what it says when
// that re-solve is not the result it reports, so the reader knows which of the two the figures
// show.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "core/geometry/geometry.h"

namespace calibench {

struct RigOutcome;  // core/lidar_camera/rig.h

// "" when `solved` and `reported` agree to 0.1 mm and 0.01 deg; else "<what> differs from a
// re-solve of <data> by .. mm and .. deg: <consequence>".
std::string ResolveNote(const Pose& solved, const Pose& reported, const std::string& what,
                        const std::string& data, const std::string& consequence);

// Each camera of a re-solved LiDAR-camera outcome (outcome.joint needed; one camera's dataset is
// a rig of one) against the poses the result file `result_path` reports, by camera name: a note
// per camera that differs (ResolveNote), and one per camera of the file that the data `data_path`
// has not. A rig of one's note says what to pass to get the result's solve.
std::vector<std::string> ResolveNotes(const RigOutcome& outcome,
                                      const std::vector<std::pair<std::string, Pose>>& reported,
                                      const std::string& result_path, const std::string& data_path);

}  // namespace calibench
