// CalibrateDataset and ExtractDatasetPairs (pipeline.h) one step at a time, for a front end that
// must not block on a camera's whole calibration (the workbench's rig solve runs each step as a
// background job on its worker, between the user's edits; docs/architecture.md, "Threads"). The
// steps: the scene's background model (every selected cloud read once), the pairs' features a
// few at a time (each chunk in parallel), then the solve. The functions in pipeline.h are these
// steps in a row, so the results are the same whichever way they run.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "core/lidar_camera/pipeline.h"
#include "core/target/scene_background.h"

namespace calibench {

class DatasetExtraction {
 public:
  // `dataset` and the entries `selected` points to must outlive the extraction, in place.
  // pairs_per_thread: how many pairs a step extracts per thread (options.threads); 0: all in one
  // step, which balances the threads best (a slow pair does not hold the others' next chunk), for
  // a caller that runs the steps in a row anyway.
  DatasetExtraction(const Dataset& dataset, std::vector<const PairEntry*> selected,
                    const PipelineOptions& options, ProgressCallback progress, PairEdits edits,
                    size_t pairs_per_thread = 0);
  DatasetExtraction(const DatasetExtraction&) = delete;
  DatasetExtraction& operator=(const DatasetExtraction&) = delete;

  // Runs the next step (the background, then the next chunk of pairs); false when that was the
  // last, or none was left.
  bool Step();
  // Once every step ran: the pairs' features in `selected` order, and why no background model
  // was used when one was wanted (*background_note).
  std::vector<PairFeatures> Take(std::string* background_note);
  const std::vector<const PairEntry*>& selected() const { return selected_; }
  const PipelineOptions& options() const { return options_; }
  const PairEdits& edits() const { return edits_; }

 private:
  const Dataset& dataset_;
  std::vector<const PairEntry*> selected_;
  PipelineOptions options_;
  ProgressCallback progress_;
  PairEdits edits_;
  bool background_done_ = false;
  std::optional<SceneBackground> background_;
  std::string background_note_;
  std::vector<std::optional<LidarCloud>> clouds_;  // read once, for the background and the pair
  FrameBoards frames_;                             // a moving capture's frames, each posed once
  std::vector<PairFeatures> features_;
  size_t pairs_per_step_ = 0;  // 0: every pair in one step
  size_t next_pair_ = 0;
};

class DatasetCalibration {
 public:
  // `dataset` must outlive the calibration, in place. pairs_per_thread as DatasetExtraction's.
  DatasetCalibration(const Dataset& dataset, const PipelineOptions& options, PairEdits edits = {},
                     ProgressCallback progress = {}, size_t pairs_per_thread = 0);
  // Runs the next step (extraction's, then the solve, a step of its own); false when that was the
  // last.
  bool Step();
  // Once every step ran: what CalibrateDataset returns.
  CalibrationOutcome Take();

 private:
  const Dataset& dataset_;
  DatasetExtraction extraction_;  // holds the options and the edits the solve takes too
  bool extracted_ = false;        // every extraction step ran; the solve is next
  std::optional<CalibrationOutcome> outcome_;
};

}  // namespace calibench
