#include "core/report/resolve_notes.h"

#include <algorithm>
#include <cstdio>

#include "core/lidar_camera/rig.h"

namespace calibench {

std::string ResolveNote(const Pose& solved, const Pose& reported, const std::string& what,
                        const std::string& data, const std::string& consequence) {
  const double moved_mm = 1000.0 * (solved.translation() - reported.translation()).norm();
  const double turned_deg =
      Eigen::AngleAxisd(solved.linear().transpose() * reported.linear()).angle() * kRadToDeg;
  if (moved_mm <= 0.1 && turned_deg <= 0.01) return "";
  char amount[96];
  std::snprintf(amount, sizeof(amount), " by %.1f mm and %.3f deg: ", moved_mm, turned_deg);
  return what + " differs from a re-solve of " + data + amount + consequence;
}

std::vector<std::string> ResolveNotes(const RigOutcome& outcome,
                                      const std::vector<std::pair<std::string, Pose>>& reported,
                                      const std::string& result_path,
                                      const std::string& data_path) {
  CALIBENCH_CHECK(outcome.joint.has_value());
  std::vector<std::string> notes;
  for (const auto& [name, pose] : reported) {
    const auto at = std::find(outcome.camera_names.begin(), outcome.camera_names.end(), name);
    if (at == outcome.camera_names.end()) {
      notes.push_back(result_path + " has a camera '" + name + "' that " + data_path + " has not.");
      continue;
    }
    const Pose& solved = outcome.joint->cam_from_lidar[at - outcome.camera_names.begin()];
    std::string note =
        outcome.Several()
            ? ResolveNote(solved, pose, result_path + ": camera " + name,
                          "this rig with these options", "the figures below are the re-solve's.")
            : ResolveNote(solved, pose, result_path, "this data with these options",
                          "the result, per-pair figures and views below are the re-solve's. Pass "
                          "the options calibrate was run with (or its session).");
    if (!note.empty()) notes.push_back(std::move(note));
  }
  return notes;
}

}  // namespace calibench
