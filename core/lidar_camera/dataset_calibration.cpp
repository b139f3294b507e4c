#include "core/lidar_camera/dataset_calibration.h"

#include <algorithm>

#include "core/base/parallel.h"

namespace calibench {
namespace {

// Whether some pair will need detection: no brush painted and no seed in the manifest.
bool AnyPairToDetect(const std::vector<const PairEntry*>& pairs, const PairEdits& edits) {
  return std::any_of(pairs.begin(), pairs.end(), [&](const PairEntry* pair) {
    const auto edit = edits.find(pair->id);
    const bool brushed = edit != edits.end() && edit->second.brush_pixels;
    return !brushed && !pair->lidar_seed;
  });
}

}  // namespace

DatasetExtraction::DatasetExtraction(const Dataset& dataset, std::vector<const PairEntry*> selected,
                                     const PipelineOptions& options, ProgressCallback progress,
                                     PairEdits edits, size_t pairs_per_thread)
    : dataset_(dataset),
      selected_(std::move(selected)),
      options_(options),
      progress_(std::move(progress)),
      edits_(std::move(edits)),
      features_(selected_.size()),
      pairs_per_step_(pairs_per_thread *
                      static_cast<size_t>(options.threads > 0 ? options.threads : 1)) {}

bool DatasetExtraction::Step() {
  if (!background_done_) {
    // The background model over all the selected clouds first (where a pair is left to
    // detection); the clouds it read are kept for their pairs.
    background_done_ = true;
    if (options_.detect_board && options_.background_model && AnyPairToDetect(selected_, edits_))
      background_ = BuildSceneBackground(selected_, options_.threads, &background_note_, &clouds_);
    return next_pair_ < selected_.size();
  }
  if (next_pair_ >= selected_.size()) return false;
  const size_t first = next_pair_, left = selected_.size() - first,
               count = pairs_per_step_ > 0 ? std::min(left, pairs_per_step_) : left;
  next_pair_ += count;
  ParallelFor(
      count, options_.threads,
      [&](size_t k) {
        const size_t i = first + k;
        const auto edit = edits_.find(selected_[i]->id);
        LidarCloud* preloaded = i < clouds_.size() && clouds_[i] ? &*clouds_[i] : nullptr;
        features_[i] = ExtractPairFeatures(
            dataset_, *selected_[i], options_, edit == edits_.end() ? PairEdit{} : edit->second,
            background_ ? &*background_ : nullptr, preloaded, &frames_);
        if (preloaded) clouds_[i].reset();  // its memory goes with the pair
      },
      [&](int finished, size_t k) {
        if (progress_)
          progress_(static_cast<int>(first) + finished, static_cast<int>(selected_.size()),
                    selected_[first + k]->id);
      });
  return next_pair_ < selected_.size();
}

std::vector<PairFeatures> DatasetExtraction::Take(std::string* background_note) {
  CALIBENCH_CHECK(background_done_ && next_pair_ >= selected_.size());
  if (background_note) *background_note = background_note_;
  return std::move(features_);
}

std::vector<PairFeatures> ExtractDatasetPairs(const Dataset& dataset,
                                              const std::vector<const PairEntry*>& selected,
                                              const PipelineOptions& options,
                                              const ProgressCallback& progress,
                                              const PairEdits& edits,
                                              std::string* background_note) {
  DatasetExtraction extraction(dataset, selected, options, progress, edits);
  while (extraction.Step()) {
  }
  return extraction.Take(background_note);
}

DatasetCalibration::DatasetCalibration(const Dataset& dataset, const PipelineOptions& options,
                                       PairEdits edits, ProgressCallback progress,
                                       size_t pairs_per_thread)
    : dataset_(dataset),
      extraction_(dataset, SelectedPairs(dataset, options), options, std::move(progress),
                  std::move(edits), pairs_per_thread) {}

bool DatasetCalibration::Step() {
  if (outcome_) return false;
  if (!extracted_) {
    extracted_ = !extraction_.Step();
    return true;
  }
  std::string background_note;
  std::vector<PairFeatures> features = extraction_.Take(&background_note);
  outcome_ = SolveExtractedPairs(dataset_, extraction_.selected(), std::move(features),
                                 extraction_.options(), extraction_.edits());
  outcome_->background_note = background_note;
  return false;
}

CalibrationOutcome DatasetCalibration::Take() {
  CALIBENCH_CHECK(outcome_.has_value());
  return std::move(*outcome_);
}

CalibrationOutcome CalibrateDataset(const Dataset& dataset, const PipelineOptions& options,
                                    const ProgressCallback& progress, const PairEdits& edits) {
  DatasetCalibration calibration(dataset, options, edits, progress);
  while (calibration.Step()) {
  }
  return calibration.Take();
}

}  // namespace calibench
