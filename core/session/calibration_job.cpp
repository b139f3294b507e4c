#include "core/session/calibration_job.h"

#include "core/io/cloud_io.h"

namespace calibench {

bool CalibrationJobOptions::Check(std::string* why) const {
  if (!advise.Check(why)) return false;
  if (max_background_clouds < 3)
    return *why = "max_background_clouds must be >= 3 (a background needs 3 clouds)", false;
  return true;
}

CalibrationJob::CalibrationJob(Dataset dataset, CalibrationJobOptions options, PairEdits edits,
                               JobEvents events)
    : options_(std::move(options)), events_(std::move(events)) {
  std::vector<PairEntry> selected;
  for (const PairEntry* pair : SelectedPairs(dataset, options_.advise.pipeline))
    selected.push_back(*pair);
  dataset.pairs = std::move(selected);
  dataset_ = std::move(dataset);
  for (const PairEntry& entry : dataset_.pairs) {
    JobPair pair;
    pair.detected.id = entry.id;
    pairs_.push_back(std::move(pair));
  }
  for (auto& [id, edit] : edits) {
    SetRejected(id, edit.rejected);
    if (edit.brush_pixels) SetBrush(id, edit);
  }
}

PairEdit CalibrationJob::EditOf(const std::string& pair_id) const {
  const auto found = brushes_.find(pair_id);
  PairEdit edit = found == brushes_.end() ? PairEdit{} : found->second;
  edit.rejected = rejections_.count(pair_id) > 0;
  return edit;
}

void CalibrationJob::Restatus(JobPair* pair) const {
  SetStatusFromFeatures(&pair->detected, pair->lidar_failure, pair->camera_failure);
}

void CalibrationJob::DetectAll() {
  std::vector<const PairEntry*> entries;
  for (const PairEntry& entry : dataset_.pairs) entries.push_back(&entry);
  // Rejections apply at the solve (DetectedPairs); detection sees the brushes only. The note says
  // why there is no background model once all clouds are read: none when it was built, or when no
  // pair needed detection (seeds, brushes).
  background_note_.clear();
  std::vector<PairFeatures> features = ExtractDatasetPairs(
      dataset_, entries, options_.advise.pipeline, events_.detected, brushes_, &background_note_);
  for (size_t i = 0; i < features.size(); ++i) {
    pairs_[i].detected = std::move(features[i]);
    pairs_[i].lidar_failure = pairs_[i].camera_failure = pairs_[i].detected.reason;
  }
}

bool CalibrationJob::AddToBackground(int index, const LidarCloud& cloud) {
  const PipelineOptions& pipeline = options_.advise.pipeline;
  if (!pipeline.detect_board || !pipeline.background_model) return false;
  if (background_accumulator_.clouds() >= options_.max_background_clouds) return false;
  if (!in_background_.insert(index).second) return false;
  const bool had_background = background_.has_value();
  background_accumulator_.Add(cloud);
  std::string why;
  if (background_accumulator_.Finish(&why)) {
    background_ = background_accumulator_;
    background_note_.clear();
  } else {
    background_.reset();
    background_note_ = why;
  }
  return background_ && !had_background;
}

const PairFeatures& CalibrationJob::AddPair(const PairEntry& entry, const PairFeatures* cached) {
  const int index = AppendPair(entry);
  // The cloud is read once: for the background model (as DetectAll reads every cloud first) and
  // then for the pair itself.
  std::optional<LidarCloud> cloud;
  const PipelineOptions& pipeline = options_.advise.pipeline;
  if (pipeline.detect_board && pipeline.background_model &&
      background_accumulator_.clouds() < options_.max_background_clouds) {
    try {
      cloud = LoadCloud(entry.cloud);
      AddToBackground(index, *cloud);
    } catch (const IoError&) {  // the pair reports it when it is extracted
    }
  }
  JobPair& pair = pairs_[index];
  if (cached) {
    pair.detected = *cached;
  } else {
    PairEdit edit = EditOf(entry.id);
    edit.rejected = false;  // applies at the solve
    pair.detected = ExtractPairFeatures(dataset_, entry, pipeline, edit, Background(),
                                        cloud ? &*cloud : nullptr);
  }
  pair.lidar_failure = pair.camera_failure = pair.detected.reason;
  if (events_.detected) events_.detected(size(), size(), entry.id);
  return pair.detected;
}

int CalibrationJob::AppendPair(const PairEntry& entry) {
  dataset_.pairs.push_back(entry);
  JobPair pair;
  pair.detected.id = entry.id;
  pairs_.push_back(std::move(pair));
  return size() - 1;
}

std::optional<PairInputs> CalibrationJob::ReadPair(int index, CameraFeatures* camera,
                                                   std::string* why) {
  JobPair& pair = pairs_.at(index);
  std::optional<PairInputs> inputs = LoadPairInputs(dataset_, dataset_.pairs[index], why);
  if (!inputs) {
    pair.detected.input_error = true;
    pair.lidar_failure = pair.camera_failure = *why;
  } else {
    *camera = ExtractCameraFeatures(dataset_, inputs->image, options_.advise.pipeline);
    pair.detected.camera = camera->observation;
    pair.detected.edge_width_px = camera->edge_width_px;
    pair.camera_failure = camera->failure;
  }
  Restatus(&pair);
  return inputs;
}

const PairFeatures& CalibrationJob::DetectLidar(int index, const LidarCloud& cloud,
                                                const LidarImage* image, bool use_seed) {
  JobPair& pair = pairs_.at(index);
  PairEntry entry = dataset_.pairs[index];
  if (!use_seed) entry.lidar_seed.reset();
  std::string why;
  BoardOrigin origin;
  std::optional<LidarPlaneFit> fit;
  if (std::optional<BoardHint> hint = BoardHintFor(entry, EditOf(entry.id), image, &why)) {
    hint->background = Background();
    fit = ExtractLidarFeatures(dataset_, cloud, *hint, options_.advise.pipeline, &why, &origin);
  }
  pair.detected.lidar = std::move(fit);
  pair.detected.board_origin = origin;
  pair.lidar_failure = pair.detected.lidar ? "" : why;
  Restatus(&pair);
  return pair.detected;
}

void CalibrationJob::SetBrush(const std::string& pair_id, std::optional<PairEdit> brush) {
  if (!brush || !brush->brush_pixels) {
    brushes_.erase(pair_id);
    return;
  }
  brush->rejected = false;
  brushes_[pair_id] = std::move(*brush);
}

void CalibrationJob::SetRejected(const std::string& pair_id, bool rejected,
                                 const std::string& reason) {
  if (rejected)
    rejections_[pair_id] = reason.empty() ? kRejectedByUser : reason;
  else
    rejections_.erase(pair_id);
}

void CalibrationJob::Resume(const Session& session) {
  ApplySessionOptions(session, &options_.advise.pipeline);
  // What is the user's word, as `calibrate --session` reads it; the reasons are the session's.
  const PairEdits edits = EditsFromSession(session);
  for (const PairState& pair : session.pairs) {
    const auto edit = edits.find(pair.id);
    const bool edited = edit != edits.end();
    SetRejected(pair.id, edited && edit->second.rejected, pair.reason);
    SetBrush(pair.id, edited ? std::optional(edit->second) : std::nullopt);
  }
  view_json_ = session.view_json;
}

void CalibrationJob::SetSolverOptions(const SolverOptions& solver) {
  options_.advise.pipeline.solver = solver;
}

void CalibrationJob::SetGoal(const CaptureGoal& goal) { options_.advise.goal = goal; }

void CalibrationJob::SetHandTolerance(double translation_m, double rotation_deg) {
  options_.advise.guidance.hand_tolerance_m = translation_m;
  options_.advise.guidance.hand_tolerance_deg = rotation_deg;
}

std::vector<PairFeatures> CalibrationJob::DetectedPairs() const {
  std::vector<PairFeatures> features;
  for (const JobPair& pair : pairs_) {
    features.push_back(pair.detected);
    const auto rejected = rejections_.find(pair.detected.id);
    if (rejected == rejections_.end()) continue;
    features.back().status = PairStatus::kRejected;
    features.back().reason = rejected->second;
  }
  return features;
}

const CalibrationOutcome& CalibrationJob::Solve() {
  PipelineOptions pipeline = options_.advise.pipeline;
  // Warm start: the last solution is a better start than the closed form, and the same minimum.
  if (options_.warm_start && last_solution_ && !pipeline.initial_cam_from_lidar)
    pipeline.initial_cam_from_lidar = last_solution_->cam_from_lidar;
  std::vector<const PairEntry*> entries;
  for (const PairEntry& pair : dataset_.pairs) entries.push_back(&pair);
  PairEdits edits = brushes_;
  for (const auto& [id, reason] : rejections_) edits[id].rejected = true;
  // Every solve starts from what detection found, as `calibrate` does: a board completion
  // rescued is rescued again, one the camera disagrees with is looked at again.
  outcome_ =
      SolveExtractedPairs(dataset_, entries, DetectedPairs(), pipeline, edits, events_.iteration);
  outcome_->background_note = background_note_;
  if (outcome_->solution) last_solution_ = outcome_->solution;
  advice_.reset();
  return *outcome_;
}

const CaptureAdvice& CalibrationJob::Advise(const std::optional<SolverResult>& at) {
  CalibrationOutcome outcome;
  if (outcome_) outcome = *outcome_;
  if (!outcome_) outcome.pairs = DetectedPairs();
  if (at) outcome.solution = at;
  // The pairs of that solve: those appended since are judged after the next one.
  Dataset solved = dataset_;
  solved.pairs.resize(outcome.pairs.size());
  advice_ = AdviseCapture(solved, outcome, options_.advise);
  return *advice_;
}

Session CalibrationJob::ToSession(const std::filesystem::path& dataset_path) const {
  Session session = NewSession(dataset_);
  session.dataset = NormalizeSessionPath(dataset_path);
  const PipelineOptions& pipeline = options_.advise.pipeline;
  session.method = pipeline.solver.method;
  session.huber_delta = pipeline.solver.huber_delta;
  session.estimate_range_offset = pipeline.solver.estimate_range_offset;
  session.max_iterations = pipeline.solver.max_iterations;
  session.ransac_threshold_m = pipeline.lidar_plane.ransac_threshold_m;
  // NewSession's pairs, pairs_, the outcome's and the advice's pairs all follow dataset_.pairs.
  const std::vector<PairFeatures> detected = DetectedPairs();
  for (size_t i = 0; i < session.pairs.size(); ++i) {
    const PairFeatures* last = &detected[i];
    if (outcome_ && i < outcome_->pairs.size()) last = &outcome_->pairs[i];
    const bool judged = advice_ && i < advice_->pairs.size();
    session.pairs[i].status = judged ? advice_->pairs[i].status : last->status;
    session.pairs[i].reason = judged ? advice_->pairs[i].reason : last->reason;
    const auto brush = brushes_.find(session.pairs[i].id);
    if (brush != brushes_.end())
      session.pairs[i].brush = BrushMask{brush->second.brush_rows, brush->second.brush_columns,
                                         *brush->second.brush_pixels};
  }
  session.view_json = view_json_;
  const std::optional<SolverResult>& solution = advice_ ? advice_->solution : last_solution_;
  if (solution) session.result = SessionResultFromSolver(*solution);
  return session;
}

}  // namespace calibench
