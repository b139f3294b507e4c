// The 3D LiDAR ↔ camera result: calibench.result.v1 (core/results) with the plane solver's figures,
// and its summary for the terminal.
#pragma once

#include <filesystem>
#include <string>

#include "core/lidar_camera/pipeline.h"
#include "core/results/result_file.h"

namespace calibench {

// Writes the result atomically; throws IoError naming the file. Requires outcome.solution.
void WriteResult(const std::filesystem::path& path, const CalibrationOutcome& outcome,
                 const SolverOptions& options, const ResultNames& names = {});

// Human-readable summary: both directions in words, standard deviations, observability, pairs.
std::string FormatSummary(const CalibrationOutcome& outcome, const ResultNames& names = {});

}  // namespace calibench
