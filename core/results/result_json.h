// JSON building blocks of calibench.result.v1 shared by both methods' writers. Internal: include
// it from .cpp files only (it pulls in nlohmann/json).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "core/estimation/uncertainty.h"
#include "core/results/pair_status.h"
#include "core/results/result_file.h"

namespace calibench {

// format, direction in words, <target>_from_<source> and its inverse, covariance with its
// convention, standard deviations in camera axes and the observability report.
nlohmann::json ResultHeaderJson(const ResultNames& names, const Pose& target_from_source,
                                const Mat6& covariance, const ObservabilityReport& observability);

// A pair's entry: id, status and reason; the method adds its features.
nlohmann::json PairEntryJson(const std::string& id, PairStatus status, const std::string& reason);

// Which test ended an iterative solve: {"test": "function_tolerance", "value", "tolerance",
// "cap" (the iteration cap only), "text": in words}.
nlohmann::json TerminationToJson(const Termination& termination);

// Writes the document atomically (2-space indented, newline-terminated); IoError naming the file.
void WriteResultJson(const std::filesystem::path& path, const nlohmann::json& root);

}  // namespace calibench
