#include "core/results/pair_status.h"

#include "core/base/names.h"

namespace calibench {
namespace {
constexpr EnumName<PairStatus> kPairStatusNames[] = {{PairStatus::kPending, "pending"},
                                                     {PairStatus::kAccepted, "accepted"},
                                                     {PairStatus::kRejected, "rejected"},
                                                     {PairStatus::kFailed, "failed"}};
}  // namespace

std::string PairStatusName(PairStatus status) { return NameIn(kPairStatusNames, status); }

std::optional<PairStatus> ParsePairStatus(const std::string& name) {
  return ValueIn(kPairStatusNames, name);
}

}  // namespace calibench
