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

// Which pair, where it stands and why: declared once here, and carried by every struct that
// speaks of one pair (the pipelines' features, the session file's state, the job's record,
// advice, the report's rows, the workbenches' rows), so that one copies into another whole
// (a slice) rather than field by field.
struct PairStanding {
  std::string id;  // the dataset's pair id
  PairStatus status = PairStatus::kPending;
  std::string reason;  // why failed / rejected, human-readable; empty otherwise

  bool operator==(const PairStanding&) const = default;
};

}  // namespace calibench
