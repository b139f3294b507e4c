#include "core/lrf/pair_extraction.h"

#include "core/base/parallel.h"

namespace calibench {

LrfPairExtraction::LrfPairExtraction(LrfDataset dataset, LrfPipelineOptions options)
    : options_(std::move(options)) {
  const std::set<std::string> wanted(options_.pair_ids.begin(), options_.pair_ids.end());
  std::vector<LrfPairEntry> selected;
  for (LrfPairEntry& pair : dataset.pairs)
    if (wanted.empty() || wanted.count(pair.id)) selected.push_back(std::move(pair));
  dataset.pairs = std::move(selected);
  dataset_ = std::move(dataset);
  features_.resize(dataset_.pairs.size());
}

void LrfPairExtraction::ExtractAll(const ProgressCallback& progress) {
  std::vector<size_t> missing;
  for (size_t i = 0; i < features_.size(); ++i)
    if (!features_[i]) missing.push_back(i);
  ParallelFor(
      missing.size(), options_.threads,
      [&](size_t k) {
        const size_t i = missing[k];
        features_[i] = std::make_shared<const LrfPairFeatures>(
            ExtractLrfPairFeatures(dataset_, dataset_.pairs[i], options_));
      },
      [&](int finished, size_t k) {
        if (progress)
          progress(finished, static_cast<int>(missing.size()), dataset_.pairs[missing[k]].id);
      });
}

std::shared_ptr<const LrfPairFeatures> LrfPairExtraction::ExtractPair(int index) {
  std::shared_ptr<const LrfPairFeatures>& features = features_.at(index);
  if (!features)
    features = std::make_shared<const LrfPairFeatures>(
        ExtractLrfPairFeatures(dataset_, dataset_.pairs[index], options_));
  return features;
}

std::vector<LrfPairFeatures> LrfPairExtraction::Pairs(const std::set<std::string>& rejected) const {
  std::vector<LrfPairFeatures> pairs;
  for (size_t i = 0; i < features_.size(); ++i) {
    if (!features_[i]) {
      LrfPairFeatures pending;
      pending.id = dataset_.pairs[i].id;
      pending.reason = "not extracted yet";
      pairs.push_back(std::move(pending));
      continue;
    }
    pairs.push_back(*features_[i]);
    if (rejected.count(pairs.back().id)) {
      pairs.back().status = PairStatus::kRejected;
      pairs.back().reason = kRejectedByUser;
    }
  }
  return pairs;
}

LrfCalibrationOutcome LrfPairExtraction::Solve(const std::set<std::string>& rejected,
                                               const LrfPipelineOptions& options) const {
  // Pairs not extracted yet stay out (SolveLrfFromFeatures uses accepted ones with features).
  std::vector<LrfPairFeatures> pairs;
  for (LrfPairFeatures& pair : Pairs(rejected))
    if (pair.status != PairStatus::kPending) pairs.push_back(std::move(pair));
  return SolveLrfFromFeatures(std::move(pairs), dataset_, options);
}

LrfCalibrationOutcome CalibrateLrfDataset(const LrfDataset& dataset,
                                          const LrfPipelineOptions& options,
                                          const ProgressCallback& progress) {
  LrfPairExtraction extraction(dataset, options);
  extraction.ExtractAll(progress);
  return extraction.Solve({}, options);
}

}  // namespace calibench
