// One calibration job that grows pair by pair: what `calibench watch` runs while a capture is
// written. Each new pair is detected once (with the scene's background once three clouds are in),
// then every pair so far is solved again from the last solution, camera-guided completion looks
// again where a LiDAR board failed, pre-flight checks judge each pair and guidance says whether
// the goal is met and where to hold the board next — the steps of `calibrate` and `advise`
// (core/lidar_camera/pipeline.h, core/guidance/advise.h), one pair at a time.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/guidance/advise.h"
#include "core/session/session.h"
#include "core/target/scene_background.h"

namespace calibench {

struct CaptureJobOptions {
  AdviseOptions advise;  // goal, stop rule, guidance, pre-flight and the pipeline's options
  // The background model holds one range per angular cell and cloud: the first this many clouds
  // make it (the static scene does not change after that), bounding memory on long captures.
  int max_background_clouds = 40;
  bool Check(std::string* why) const;
};

class CaptureJob {
 public:
  // `setup`: the dataset's camera and target (its pairs, if any, are added as new pairs).
  CaptureJob(Dataset setup, CaptureJobOptions options);

  // Reads and detects one new pair (its id must be new); it is not detected again, except by
  // camera-guided completion where its LiDAR board failed. Never throws for bad data: the pair
  // fails with the reason (an unreadable file is named). With `cached` (its features from an
  // earlier run, core/session/feature_cache.h) nothing is detected: only the cloud is read, for
  // the background model.
  const PairFeatures& AddPair(const PairEntry& entry, const PairFeatures* cached = nullptr);

  // Solves every pair so far, warm-started from the last solution; then camera-guided completion,
  // pre-flight and guidance (AdviseCapture). The advice's pairs carry each pair's final status.
  const CaptureAdvice& Solve();

  const Dataset& dataset() const { return dataset_; }
  const std::vector<PairFeatures>& pairs() const { return pairs_; }
  const std::optional<CaptureAdvice>& advice() const { return advice_; }
  // Why no background model is used yet (fewer than 3 clouds, or the scene does not repeat).
  const std::string& background_note() const { return background_note_; }

  // The job as a workbench session over `dataset_path` (the watched folder): each pair's status
  // and reason as the last solve left them, the last solution. `calibrate --session` and
  // `gui --session` reopen it.
  Session ToSession(const std::filesystem::path& dataset_path) const;

 private:
  void AddToBackground(const LidarCloud& cloud);

  Dataset dataset_;
  CaptureJobOptions options_;
  std::vector<PairFeatures> pairs_;
  SceneBackground background_accumulator_;
  std::optional<SceneBackground> background_;  // finished, when usable
  std::string background_note_ = "fewer than 3 clouds so far";
  std::optional<SolverResult> last_solution_;
  std::optional<CaptureAdvice> advice_;
};

}  // namespace calibench
