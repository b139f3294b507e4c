// The job's views of its pairs (core/session/calibration_job.h): each pair's record as a front
// end shows it, the pairs as they stand at a solution shown, and the record edits a front end
// makes for them beyond the steps (an adopted estimate, a followed capture's rejections).
#include <algorithm>

#include "core/lidar_camera/time_offset.h"
#include "core/session/calibration_job.h"

namespace calibench {

std::vector<PairFeatures> CalibrationJob::PairsNow(const Session& record) const {
  std::vector<PairFeatures> pairs;
  for (const JobPair& job_pair : pairs_) {
    PairFeatures features = job_pair.Now();
    // The record's status: what the steps left (a reopened session's until its pairs are read
    // again) and the user's rejections.
    const PairState* saved = FindPair(record, features.id);
    features.status = saved ? saved->status : PairStatus::kPending;
    features.reason = saved ? saved->reason : "";
    // An accepted pair that lost a plane cannot be solved with.
    if (features.status == PairStatus::kAccepted && !(features.lidar && features.camera))
      features.status = PairStatus::kFailed;
    pairs.push_back(std::move(features));
  }
  return pairs;
}

CalibrationOutcome CalibrationJob::OutcomeAt(const SolverResult& shown,
                                             const std::vector<std::string>& solved_ids) const {
  const Session record = record_.Current();
  std::lock_guard lock(pairs_mutex_);
  return OutcomeAt(record, shown, solved_ids);
}

CalibrationOutcome CalibrationJob::OutcomeAt(const Session& record, const SolverResult& shown,
                                             const std::vector<std::string>& solved_ids) const {
  CalibrationOutcome outcome;
  outcome.pairs = PairsNow(record);
  outcome.solution = shown;
  PipelineOptions pipeline = options_.advise.pipeline;
  record.settings.Apply(&pipeline);
  // The clocks as the last solve found them (a still capture's "cannot tell" costs nothing to
  // say again), each moving pair's camera board placed in time as that solve placed it.
  outcome.time_offset = outcome_
                            ? outcome_->time_offset
                            : EstimateTimeOffset(outcome.pairs, pipeline, shown.cam_from_lidar);
  if (const auto offset = outcome.time_offset.camera_minus_lidar_s)
    for (PairFeatures& pair : outcome.pairs)
      PlaceCameraBoardAt(&pair, *offset, pipeline.time_offset);
  std::vector<std::string> accepted;
  for (const PairFeatures& pair : outcome.pairs)
    if (pair.status == PairStatus::kAccepted) accepted.push_back(pair.id);
  // The solve's own figures while its pairs are still the accepted ones (they include the
  // outliers it gated); after accept/reject since, or after a reload, the solver's residuals at
  // the shown estimate over the pairs accepted now.
  if (accepted == solved_ids && shown.residuals.size() == accepted.size()) return outcome;
  EvaluateAtSolution(outcome.pairs, pipeline.solver, &*outcome.solution);
  return outcome;
}

std::vector<PairRecord> CalibrationJob::Records(const SolverResult* shown,
                                                const std::vector<std::string>& solved_ids) const {
  const Session record = record_.Current();
  std::lock_guard lock(pairs_mutex_);
  std::optional<CalibrationOutcome> at;
  if (shown) at = OutcomeAt(record, *shown, solved_ids);
  const std::vector<PairFeatures> now = at ? at->pairs : PairsNow(record);
  std::vector<PairRecord> records;
  size_t solved = 0;  // the solution's residuals follow the pairs solved with, in order
  for (size_t i = 0; i < pairs_.size(); ++i) {
    const JobPair& pair = pairs_[i];
    const PairFeatures& features = now[i];
    PairRecord& r = records.emplace_back();
    static_cast<PairStanding&>(r) = features;
    // An accepted pair without both planes (a reopened session's, before its files are read
    // again) shows the record's status; the solver leaves it out.
    if (const PairState* saved = FindPair(record, r.id)) r.status = saved->status;
    r.lidar = features.lidar;
    r.board_origin = features.board_origin;
    r.lidar_failure =
        pair.completed ? (features.lidar ? "" : pair.completed->reason) : pair.lidar_failure;
    r.camera = features.camera;
    r.detection = pair.detection;
    r.camera_failure = pair.camera_failure;
    // The brush: the user's, the seed's picture, or the board found (detection's or completion's)
    // drawn on the pair's image.
    const PairState* saved = FindPair(record, r.id);
    if (saved && saved->brush) {
      r.brush_origin = saved->brush_from_seed ? BrushOrigin::kSeeded : BrushOrigin::kPainted;
      r.brush_pixels = saved->brush->pixels;
    } else if (pair.image && features.lidar &&
               (features.board_origin.source == BoardSource::kDetected ||
                features.board_origin.source == BoardSource::kCameraGuided)) {
      for (int k : features.lidar->inliers)
        if (pair.image->pixel_of_point[k] >= 0)
          r.brush_pixels.push_back(pair.image->pixel_of_point[k]);
      std::sort(r.brush_pixels.begin(), r.brush_pixels.end());
      r.brush_pixels.erase(std::unique(r.brush_pixels.begin(), r.brush_pixels.end()),
                           r.brush_pixels.end());
    }
    if (at && features.status == PairStatus::kAccepted) {
      if (solved < at->solution->residuals.size()) r.residual = at->solution->residuals[solved];
      if (solved < at->solution->robust_weights.size())
        r.robust_weight = at->solution->robust_weights[solved];
      ++solved;
    }
    if (advice_ && i < advice_->pairs.size() && advice_->pairs[i].id == r.id)
      r.findings = advice_->pairs[i].findings;
  }
  return records;
}

std::vector<PairFeatures> CalibrationJob::DetectedPairs(const Session& record) const {
  std::vector<PairFeatures> features;
  for (const JobPair& pair : pairs_) {
    features.push_back(pair.detected);
    std::string reason;
    if (!IsRejected(record, pair.detected.id, &reason)) continue;
    features.back().status = PairStatus::kRejected;
    features.back().reason = reason;
  }
  return features;
}

void CalibrationJob::AdoptSolution(const SolverResult& solution, const std::string& provenance,
                                   const std::vector<std::string>& notes) {
  SessionResult result = SessionResultFromSolver(solution);
  result.targetless_provenance = provenance;
  result.notes = notes;
  record_.Edit([&](Session* session) { session->result = result; });
}

bool CalibrationJob::ApplyPreflightRejections() {
  if (!advice_) return false;
  bool rejected = false;
  record_.Edit(
      [&](Session* session) {
        for (const PairAdvice& judged : advice_->pairs) {
          PairState* saved = FindPair(session, judged.id);
          if (!saved || judged.status != PairStatus::kRejected ||
              saved->status != PairStatus::kAccepted)
            continue;
          saved->status = PairStatus::kRejected;
          saved->reason = judged.reason;
          rejected = true;
        }
      },
      /*amend=*/true);
  return rejected;
}

}  // namespace calibench
