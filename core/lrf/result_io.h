// The LRF result: calibench.result.v1 (core/results) with cam_from_lrf and the LRF solver's
// figures, and its summary for the terminal.
#pragma once

#include <filesystem>
#include <string>

#include "core/lrf/pipeline.h"

namespace calibench {

// calibench.result.v1 with cam_from_lrf / lrf_from_cam; per pair: status, reason, corner and
// face figures. Requires outcome.solution. WriteLrfResult writes atomically (IoError on failure).
void WriteLrfResult(const std::filesystem::path& path, const LrfCalibrationOutcome& outcome,
                    const LrfPipelineOptions& options);
std::string FormatLrfSummary(const LrfCalibrationOutcome& outcome);

// The solution's residual in words: the Eq. (12) mean corner-to-line distance for the three-face
// target, the RMS point-to-plane distance of the board scan points for the checkerboard.
std::string LrfResidualText(const LrfSolution& solution, LrfTargetType target);

}  // namespace calibench
