// Which noise model a ring-less LiDAR's planes get, chosen by what the data say rather than by
// the cloud's shape (docs/architecture.md, "The LiDAR's noise model"). A cloud without rings
// cannot show by itself whether its ranges run along rays from one origin (a non-repetitive or
// swept scan, its board ranges along its rays) or whether it is a crop that holds too little to
// tell: the classifier's extent threshold decided that from geometry alone, and judged a swept
// scan that is mostly board a "segment". Here every pair's board is fitted under both candidate
// models (the extraction keeps the other one as LidarPlaneFit::alternative) and the calibration is
// cross-validated: solved on all pairs but one fold, each held-out pair's board corners (where
// the camera sees them) compared with its LiDAR plane moved into the camera at that solve. The
// model whose solves predict the held-out boards better wins, compared pair by pair (the camera's
// own error of a board is common to both); the margin is the geometric mean ratio of the two
// errors, and where it is within its noise the data cannot tell them apart and each pair keeps
// the look's model. Rings are evidence of rays from one centre: clouds with rings are not asked.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/lidar/lidar_geometry.h"  // LidarModelEvidence and its options
#include "core/lidar_camera/pipeline.h"

namespace calibench {

// How the reason of a model the held-out pairs chose against the cloud's look begins (the
// extraction fits the alternative with this reason, followed by the look's).
inline constexpr const char* kChosenByHeldOutPairs =
    "chosen by the held-out pairs over the cloud's look: ";

// Chooses between each usable pair's fit and its alternative (LidarPlaneFit::alternative) by
// cross-validation under `options.solver`, and gives every pair the chosen model's fit (the
// other kept as its alternative, so that a second call decides alike). nullopt when no pair has
// an alternative (clouds with rings, a model the user forced) or when too few have (then nothing
// changes).
std::optional<LidarModelEvidence> ChooseLidarModelByEvidence(
    std::vector<PairFeatures>* pairs, const PipelineOptions& options,
    const LidarModelEvidenceOptions& evidence_options = {});

}  // namespace calibench
