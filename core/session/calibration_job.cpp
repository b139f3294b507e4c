#include "core/session/calibration_job.h"

#include <utility>

#include "core/io/cloud_io.h"
#include "core/lidar_camera/result_io.h"

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
  // The record: a new session over the pairs, with the options' settings and the edits given.
  Session session = NewSession(dataset_);
  session.settings = JobSettings::Of(options_.advise.pipeline);
  for (const auto& [id, edit] : edits) SetEdit(&session, id, edit);
  record_.Reset(std::move(session));
}

PairState& CalibrationJob::SetEdit(Session* session, const std::string& pair_id,
                                   const PairEdit& edit) {
  PairState* pair = FindPair(session, pair_id);
  if (!pair) {  // a pair that has not arrived yet takes its edit when it does
    pair = &session->pairs.emplace_back();
    pair->id = pair_id;
  }
  if (edit.rejected) {
    pair->status = PairStatus::kRejected;
    if (pair->reason.empty()) pair->reason = kRejectedByUser;
  }
  if (edit.brush_pixels) {
    pair->brush = BrushMask{edit.brush_rows, edit.brush_columns, *edit.brush_pixels};
    pair->brush_from_seed = false;
  }
  return *pair;
}

PairEdit CalibrationJob::EditOf(const std::string& pair_id) const {
  return record_.EditOf(pair_id);
}

PipelineOptions CalibrationJob::Pipeline() const {
  PipelineOptions pipeline = options_.advise.pipeline;
  record_.ApplyOptions(&pipeline);
  return pipeline;
}

CalibrationJobOptions CalibrationJob::options() const {
  CalibrationJobOptions options = options_;
  options.advise.pipeline = Pipeline();
  return options;
}

bool CalibrationJob::HasBrush(const std::string& pair_id) const {
  return EditOf(pair_id).brush_pixels.has_value();
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
  PairEdits brushes = record_.Edits();
  for (auto& [id, edit] : brushes) edit.rejected = false;
  std::vector<PairFeatures> features = ExtractDatasetPairs(
      dataset_, entries, Pipeline(), events_.detected, brushes, &background_note_);
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
  const PipelineOptions pipeline = Pipeline();
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
  record_.AddPair(entry.id);
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
    fit = ExtractLidarFeatures(dataset_, cloud, *hint, Pipeline(), &why, &origin);
  }
  pair.detected.lidar = std::move(fit);
  pair.detected.board_origin = origin;
  pair.lidar_failure = pair.detected.lidar ? "" : why;
  Restatus(&pair);
  return pair.detected;
}

void CalibrationJob::SetBrush(const std::string& pair_id, std::optional<PairEdit> brush,
                              bool amend) {
  record_.Edit(
      [&](Session* session) {
        if (brush && brush->brush_pixels) {
          brush->rejected = false;
          SetEdit(session, pair_id, *brush);
        } else {
          ForgetBrush(session, pair_id);
        }
      },
      amend);
}

void CalibrationJob::SetRejected(const std::string& pair_id, bool rejected,
                                 const std::string& reason) {
  record_.Edit([&](Session* session) {
    if (rejected) {
      PairEdit rejection;
      rejection.rejected = true;
      SetEdit(session, pair_id, rejection).reason = reason.empty() ? kRejectedByUser : reason;
      return;
    }
    // Taken back: the pair's status follows from its planes again.
    PairState* pair = FindPair(session, pair_id);
    if (!pair || pair->status != PairStatus::kRejected) return;
    pair->status = PairStatus::kPending;
    pair->reason.clear();
  });
}

void CalibrationJob::Resume(const Session& session) {
  record_.Reset(session);
  for (const PairEntry& pair : dataset_.pairs) record_.AddPair(pair.id);
}

void CalibrationJob::SetSettings(const JobSettings& settings) {
  settings.Apply(&options_.advise.pipeline);
  record_.Edit([&](Session* session) { session->settings = settings; });
}

void CalibrationJob::SetGoal(const CaptureGoal& goal) { options_.advise.goal = goal; }

void CalibrationJob::SetHandTolerance(double translation_m, double rotation_deg) {
  options_.advise.guidance.hand_tolerance_m = translation_m;
  options_.advise.guidance.hand_tolerance_deg = rotation_deg;
}

std::vector<PairFeatures> CalibrationJob::DetectedPairs() const {
  return DetectedPairs(record_.Current());
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

const CalibrationOutcome& CalibrationJob::Solve() {
  // The record read once: the edits, the rejections and the settings of one moment, which
  // DiscardStaleOutcome compares with the record's when the solve is done.
  const Session record = record_.Current();
  PipelineOptions pipeline = options_.advise.pipeline;
  record.settings.Apply(&pipeline);
  // Warm start: the last solution is a better start than the closed form, and the same minimum.
  if (options_.warm_start && last_solution_ && !pipeline.initial_cam_from_lidar)
    pipeline.initial_cam_from_lidar = last_solution_->cam_from_lidar;
  std::vector<const PairEntry*> entries;
  for (const PairEntry& pair : dataset_.pairs) entries.push_back(&pair);
  solved_edits_ = EditsFromSession(record);
  solved_settings_ = record.settings;
  // Every solve starts from what detection found, as `calibrate` does: a board completion
  // rescued is rescued again, one the camera disagrees with is looked at again.
  outcome_ = SolveExtractedPairs(dataset_, entries, DetectedPairs(record), pipeline, solved_edits_,
                                 events_.iteration);
  outcome_->background_note = background_note_;
  outcome_->estimated_intrinsics = options_.estimated_intrinsics;
  solved_with_ = pipeline.solver;
  if (outcome_->solution) last_solution_ = outcome_->solution;
  advice_.reset();
  return *outcome_;
}

bool CalibrationJob::DiscardStaleOutcome() {
  if (!outcome_) return false;
  const Session record = record_.Current();
  if (EditsFromSession(record) == solved_edits_ && record.settings == solved_settings_)
    return false;
  outcome_.reset();
  advice_.reset();
  return true;
}

void CalibrationJob::ExtractAll(const ProgressCallback& progress) {
  if (!progress) return DetectAll();
  const ProgressCallback detected = std::exchange(events_.detected, progress);
  DetectAll();
  events_.detected = detected;
}

JobVerdict CalibrationJob::Calibrate() {
  const CalibrationOutcome& outcome = Solve();
  return VerdictOf(
      outcome, [](const SolverResult& solution) { return solution.cam_from_lidar; },
      FormatSummary(outcome), dataset_.cam_from_lidar_ground_truth);
}

void CalibrationJob::WriteResultFile(const std::filesystem::path& path) const {
  CALIBENCH_CHECK(outcome_ && outcome_->solution);
  WriteResult(path, *outcome_, solved_with_);
}

const CaptureAdvice& CalibrationJob::Advise(const std::optional<SolverResult>& at) {
  CalibrationOutcome outcome;
  if (outcome_) outcome = *outcome_;
  if (!outcome_) outcome.pairs = DetectedPairs();
  if (at) outcome.solution = at;
  // The pairs of that solve: those appended since are judged after the next one.
  Dataset solved = dataset_;
  solved.pairs.resize(outcome.pairs.size());
  AdviseOptions options = options_.advise;
  options.pipeline = Pipeline();
  advice_ = AdviseCapture(solved, outcome, options);
  return *advice_;
}

Session CalibrationJob::ToSession(const std::filesystem::path& dataset_path) const {
  // The record's settings and views over the job's pairs, with the verdicts of the last solve.
  Session record = record_.Current();
  Session session = NewSession(dataset_);
  session.dataset = NormalizeSessionPath(dataset_path);
  session.settings = record.settings;
  session.view_json = record.view_json;
  // NewSession's pairs, pairs_, the outcome's and the advice's pairs all follow dataset_.pairs.
  const std::vector<PairFeatures> detected = DetectedPairs();
  for (size_t i = 0; i < session.pairs.size(); ++i) {
    const PairFeatures* last = &detected[i];
    if (outcome_ && i < outcome_->pairs.size()) last = &outcome_->pairs[i];
    const bool judged = advice_ && i < advice_->pairs.size();
    session.pairs[i].status = judged ? advice_->pairs[i].status : last->status;
    session.pairs[i].reason = judged ? advice_->pairs[i].reason : last->reason;
    // The user's painted brushes; none pictured from a seed (`calibrate` reads the seed itself).
    const PairState* saved = FindPair(&record, session.pairs[i].id);
    if (saved && saved->brush && !saved->brush_from_seed) session.pairs[i].brush = saved->brush;
  }
  const std::optional<SolverResult>& solution = advice_ ? advice_->solution : last_solution_;
  if (solution) session.result = SessionResultFromSolver(*solution);
  return session;
}

}  // namespace calibench
