// The LRF method's calibration job, the counterpart of core/session/calibration_job.h for the
// 2D laser rangefinder: what `calibench lrf-calibrate` and the LRF workbench both run. The job owns
// the pairs — each as extraction found it (core/lrf/pipeline.h) and the user's word on it (a
// rejection) — and the solve. Front ends differ only in how the pairs are extracted: all at once
// on the pipeline's workers (ExtractAll: the command line), or one at a time (ExtractPair: the
// workbench's worker, so that the rows fill in as they come). Not thread-safe: one thread drives
// a job.
#pragma once

#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/lrf/pipeline.h"

namespace calibench {

class LrfCalibrationJob {
 public:
  // `dataset`'s pairs that options.pair_ids selects (all when empty), none extracted yet.
  LrfCalibrationJob(LrfDataset dataset, LrfPipelineOptions options);

  // Every pair not extracted yet, on options.threads workers; `progress` after each.
  void ExtractAll(const ProgressCallback& progress = {});
  // Pair `index`'s features (extracted now unless they were). Never throws for bad data: the
  // pair fails with the reason, naming the file.
  std::shared_ptr<const LrfPairFeatures> ExtractPair(int index);

  // The user's word: a rejected pair stays out of the solve until taken back.
  void SetRejected(const std::string& pair_id, bool rejected);
  void SetMethod(LrfMethod method) { options_.solver.method = method; }

  // Solves from the extracted pairs with the user's rejections (SolveLrfFromFeatures).
  const LrfCalibrationOutcome& Solve();

  // The pairs as extraction left them, the user's rejections applied; pending until extracted.
  std::vector<LrfPairFeatures> ExtractedPairs() const;
  const LrfDataset& dataset() const { return dataset_; }
  const LrfPipelineOptions& options() const { return options_; }
  int size() const { return static_cast<int>(dataset_.pairs.size()); }
  const std::optional<LrfCalibrationOutcome>& outcome() const { return outcome_; }

 private:
  LrfDataset dataset_;
  LrfPipelineOptions options_;
  std::vector<std::shared_ptr<const LrfPairFeatures>> features_;  // by pair; null until extracted
  std::set<std::string> rejected_;                                // the user's, by pair id
  std::optional<LrfCalibrationOutcome> outcome_;
};

}  // namespace calibench
