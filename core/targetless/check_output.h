// What a check leaves: text for a terminal, the `check --json` object, a result file.
#pragma once

#include <filesystem>
#include <string>

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

}  // namespace calibench
