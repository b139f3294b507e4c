// The LRF method's pairs as extraction finds them: the dataset's selected pairs, each extracted
// once (core/lrf/pipeline.h) — all at once on the pipeline's workers (ExtractAll: the command line)
// or one at a time (ExtractPair: the workbench's worker, so that its rows fill in as they come).
// It holds no decisions: the user's word on the pairs is the session's (the LRF calibration job,
// core/session/lrf_calibration_job.h, which owns one of these). Not thread-safe: one thread drives
// it.
#pragma once

#include <memory>
#include <set>
#include <string>
#include <vector>

#include "core/lrf/pipeline.h"

namespace calibench {

class LrfPairExtraction {
 public:
  // `dataset`'s pairs that options.pair_ids selects (all when empty), none extracted yet.
  LrfPairExtraction(LrfDataset dataset, LrfPipelineOptions options);

  // Every pair not extracted yet, on options.threads workers; `progress` after each.
  void ExtractAll(const ProgressCallback& progress = {});
  // Pair `index`'s features (extracted now unless they were). Never throws for bad data: the
  // pair fails with the reason, naming the file.
  std::shared_ptr<const LrfPairFeatures> ExtractPair(int index);

  // The pairs as extraction left them, those in `rejected` (ids) marked rejected by the user;
  // pending until extracted.
  std::vector<LrfPairFeatures> Pairs(const std::set<std::string>& rejected = {}) const;
  // Solves from the extracted pairs less `rejected` (SolveLrfFromFeatures); pairs not extracted
  // yet stay out.
  LrfCalibrationOutcome Solve(const std::set<std::string>& rejected,
                              const LrfPipelineOptions& options) const;

  const LrfDataset& dataset() const { return dataset_; }
  const LrfPipelineOptions& options() const { return options_; }
  int size() const { return static_cast<int>(dataset_.pairs.size()); }

 private:
  LrfDataset dataset_;
  LrfPipelineOptions options_;
  std::vector<std::shared_ptr<const LrfPairFeatures>> features_;  // by pair; null until extracted
};

}  // namespace calibench
