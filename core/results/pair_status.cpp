#include "core/results/pair_status.h"

namespace calibench {

std::string PairStatusName(PairStatus status) {
  switch (status) {
    case PairStatus::kPending:
      return "pending";
    case PairStatus::kAccepted:
      return "accepted";
    case PairStatus::kRejected:
      return "rejected";
    case PairStatus::kFailed:
      return "failed";
  }
  return "unknown";
}

std::optional<PairStatus> ParsePairStatus(const std::string& name) {
  for (PairStatus status :
       {PairStatus::kPending, PairStatus::kAccepted, PairStatus::kRejected, PairStatus::kFailed})
    if (PairStatusName(status) == name) return status;
  return std::nullopt;
}

}  // namespace calibench
