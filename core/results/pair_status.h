// Where a pair stands in a calibration: both methods, the CLI, the workbench and the files.
#pragma once

#include <optional>
#include <string>

namespace calibench {

enum class PairStatus { kPending, kAccepted, kRejected, kFailed };
std::string PairStatusName(PairStatus status);  // "pending", "accepted", "rejected", "failed"
// The reason given for a pair the user rejected.
inline constexpr const char* kRejectedByUser = "rejected by the user";

// The inverse of PairStatusName; nullopt for any other text.
std::optional<PairStatus> ParsePairStatus(const std::string& name);

}  // namespace calibench
