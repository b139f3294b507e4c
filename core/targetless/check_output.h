// What a check leaves: text for a terminal, the `check --json` object, a result file.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/targetless/check.h"

namespace calibench {

std::string FormatCheckReport(const CheckReport& report);

// One JSON object (no newline): verdict ("consistent" | "miscalibrated" | "cannot tell"),
// frames_used, frames_given, why, unconstrained_axes (words), reference_cam_from_lidar (4x4),
// cam_from_lidar (4x4), sigma_t_mm [3], sigma_r_deg [3], change_t_mm [3], change_r_deg [3],
// change_sigmas (null without an estimate), matched_edges, image_cells, axes.
std::string CheckReportJson(const CheckReport& report);

// The estimate as a calibench.result.v1 file (written atomically) whose provenance says
// targetless and names the result checked. Requires report.has_estimate.
void WriteCheckResult(const std::filesystem::path& path, const CheckReport& report,
                      const std::filesystem::path& checked_result);

// The words of a targetless estimate's provenance: made `by` (a command, the workbench) around
// the calibration `checked`.
std::string TargetlessProvenanceText(const std::string& checked, const std::string& by);

// A targetless estimate kept elsewhere (the workbench's adopted one) as a result file: method and
// provenance kind "targetless", `provenance_text`, no pairs. Written atomically.
void WriteTargetlessResult(const std::filesystem::path& path, const Pose& cam_from_lidar,
                           const Mat6& right_covariance,
                           const std::vector<std::string>& weak_directions,
                           const std::string& provenance_text);

}  // namespace calibench
