#include "core/session/capture_job.h"

#include "core/io/cloud_io.h"

namespace calibench {

bool CaptureJobOptions::Check(std::string* why) const {
  if (!advise.Check(why)) return false;
  if (max_background_clouds < 3)
    return *why = "max_background_clouds must be >= 3 (a background needs 3 clouds)", false;
  return true;
}

CaptureJob::CaptureJob(Dataset setup, CaptureJobOptions options) : options_(std::move(options)) {
  std::vector<PairEntry> existing = std::move(setup.pairs);
  setup.pairs.clear();
  dataset_ = std::move(setup);
  for (const PairEntry& pair : existing) AddPair(pair);
}

void CaptureJob::AddToBackground(const LidarCloud& cloud) {
  if (background_accumulator_.clouds() >= options_.max_background_clouds) return;
  background_accumulator_.Add(cloud);
  std::string why;
  if (background_accumulator_.Finish(&why)) {
    background_ = background_accumulator_;
    background_note_.clear();
  } else {
    background_.reset();
    background_note_ = why;
  }
}

const PairFeatures& CaptureJob::AddPair(const PairEntry& entry, const PairFeatures* cached) {
  const PipelineOptions& pipeline = options_.advise.pipeline;
  dataset_.pairs.push_back(entry);
  // The cloud is read once: for the background model (as CalibrateDataset's
  // BuildSceneBackground reads every cloud first) and then for the pair itself.
  std::optional<LidarCloud> cloud;
  if (pipeline.detect_board && pipeline.background_model &&
      background_accumulator_.clouds() < options_.max_background_clouds) {
    try {
      cloud = LoadCloud(entry.cloud);
      AddToBackground(*cloud);
    } catch (const IoError&) {  // the pair reports it when it is extracted
    }
  }
  if (cached) {
    pairs_.push_back(*cached);
    return pairs_.back();
  }
  pairs_.push_back(ExtractPairFeatures(dataset_, entry, pipeline, PairEdit{},
                                       background_ ? &*background_ : nullptr,
                                       cloud ? &*cloud : nullptr));
  return pairs_.back();
}

const CaptureAdvice& CaptureJob::Solve() {
  PipelineOptions pipeline = options_.advise.pipeline;
  // Warm start: the last solution is a better start than the closed form, and the same minimum.
  if (last_solution_ && !pipeline.initial_cam_from_lidar)
    pipeline.initial_cam_from_lidar = last_solution_->cam_from_lidar;
  // The steps `calibrate` runs after extraction (solve, camera-guided completion, intrinsics).
  std::vector<const PairEntry*> entries;
  for (const PairEntry& pair : dataset_.pairs) entries.push_back(&pair);
  CalibrationOutcome outcome = SolveExtractedPairs(dataset_, entries, pairs_, pipeline);
  // A board found at the camera's prediction stays found; one the camera disagrees with is
  // looked at again after the next pair.
  if (pipeline.camera_guided && outcome.solution) pairs_ = outcome.pairs;
  if (outcome.solution) last_solution_ = outcome.solution;
  AdviseOptions advise = options_.advise;
  advise.pipeline = pipeline;
  advice_ = AdviseCapture(dataset_, outcome, advise);
  return *advice_;
}

Session CaptureJob::ToSession(const std::filesystem::path& dataset_path) const {
  Session session = NewSession(dataset_);
  session.dataset = NormalizeSessionPath(dataset_path);
  const PipelineOptions& pipeline = options_.advise.pipeline;
  session.method = pipeline.solver.method;
  session.huber_delta = pipeline.solver.huber_delta;
  session.estimate_range_offset = pipeline.solver.estimate_range_offset;
  session.max_iterations = pipeline.solver.max_iterations;
  session.ransac_threshold_m = pipeline.lidar_plane.ransac_threshold_m;
  // NewSession's pairs, pairs_ and the advice's pairs all follow dataset_.pairs: one index.
  for (size_t i = 0; i < session.pairs.size() && i < pairs_.size(); ++i) {
    const bool judged = advice_ && i < advice_->pairs.size();
    session.pairs[i].status = judged ? advice_->pairs[i].status : pairs_[i].status;
    session.pairs[i].reason = judged ? advice_->pairs[i].reason : pairs_[i].reason;
  }
  if (advice_ && advice_->solution) session.result = SessionResultFromSolver(*advice_->solution);
  return session;
}

}  // namespace calibench
