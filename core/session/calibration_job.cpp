#include "core/session/calibration_job.h"

#include <algorithm>
#include <utility>

#include "core/io/cloud_io.h"
#include "core/lidar_camera/result_io.h"
#include "core/lidar_camera/time_offset.h"

namespace calibench {
namespace {

constexpr const char* kNoBoardToFind = "no board to find: the dataset has no target.json";

// Each pair's status and reason as its steps left them (`verdicts`, by pair id) into `session`;
// a rejection stands (the user's word, or pre-flight's while following a capture).
void WriteVerdicts(const std::vector<std::pair<std::string, PairFeatures>>& verdicts,
                   Session* session) {
  for (const auto& [id, features] : verdicts) {
    PairState* saved = FindPair(session, id);
    if (!saved || saved->status == PairStatus::kRejected) continue;
    saved->status = features.status;
    saved->reason = features.reason;
  }
}

}  // namespace

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
  {
    std::lock_guard lock(pairs_mutex_);
    for (size_t i = 0; i < features.size(); ++i) {
      JobPair& pair = pairs_[i];
      pair.detected = std::move(features[i]);
      pair.completed.reset();
      pair.lidar_failure = pair.camera_failure = pair.detected.reason;
      pair.lidar_tried = true;
      ++pair.detections;
    }
  }
  RecordStatuses();
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
  PairFeatures features;
  if (cached) {
    features = *cached;
  } else {
    PairEdit edit = EditOf(entry.id);
    edit.rejected = false;  // applies at the solve
    features = ExtractPairFeatures(dataset_, entry, pipeline, edit, Background(),
                                   cloud ? &*cloud : nullptr, &frames_);
  }
  {
    std::lock_guard lock(pairs_mutex_);
    JobPair& pair = pairs_[index];
    pair.detected = std::move(features);
    pair.lidar_failure = pair.camera_failure = pair.detected.reason;
    pair.lidar_tried = true;
    ++pair.detections;
  }
  RecordStatuses();
  if (events_.detected) events_.detected(size(), size(), entry.id);
  return pairs_[index].detected;  // only this thread writes it
}

int CalibrationJob::AppendPair(const PairEntry& entry) {
  dataset_.pairs.push_back(entry);
  record_.AddPair(entry.id);
  JobPair pair;
  pair.detected.id = entry.id;
  std::lock_guard lock(pairs_mutex_);
  pairs_.push_back(std::move(pair));
  return size() - 1;
}

std::optional<PairInputs> CalibrationJob::ReadPair(int index, CameraFeatures* camera,
                                                   std::string* why) {
  std::optional<PairInputs> inputs = LoadPairInputs(dataset_, dataset_.pairs.at(index), why);
  // No target (a drive opened for the targetless check): no board to see on either side.
  const bool no_target = !dataset_.missing_target_file.empty();
  std::vector<TimedObservation> track;  // a moving capture's frames, as ExtractPairFeatures
  if (inputs && !no_target) {
    *camera = ExtractCameraFeatures(dataset_, inputs->image, options_.advise.pipeline);
    const PairEntry& entry = dataset_.pairs.at(index);
    if (!entry.images.empty())
      track = TrackBoard(dataset_, entry, options_.advise.pipeline, &frames_);
  }
  {
    std::lock_guard lock(pairs_mutex_);
    JobPair& pair = pairs_[index];
    if (!inputs) {
      pair.detected.input_error = true;
      pair.lidar_failure = pair.camera_failure = *why;
      pair.lidar_tried = true;
    } else if (no_target) {
      pair.camera_failure = pair.lidar_failure = kNoBoardToFind;
      pair.lidar_tried = true;
    } else {
      pair.detected.camera = camera->observation;
      pair.detected.camera_track = std::move(track);
      pair.detected.edge_width_px = camera->edge_width_px;
      pair.detection = camera->detection;
      pair.camera_failure = camera->failure;
    }
    Restatus(&pair);
  }
  RecordStatuses();
  return inputs;
}

std::string CalibrationJob::PictureOn(int index, const LidarCloud& cloud,
                                      std::shared_ptr<const LidarImage> image) {
  const PairEntry& entry = dataset_.pairs.at(index);
  const std::optional<PairState> saved = record_.Pair(entry.id);
  std::string dropped;
  if (saved && saved->brush && !saved->brush_from_seed &&
      !BrushFitsImage(*saved->brush, image->rows, image->columns, &dropped)) {
    record_.Adjust([&](Session* session) { ForgetBrush(session, entry.id); });
    dropped = "pair " + entry.id +
              ": its brush from the session was dropped: " + entry.cloud.string() + ": " + dropped;
  } else {
    dropped.clear();
  }
  // The seed's region pictured as its brush: the session file keeps the picture, and reopening
  // pictures it again (EditsFromSession skips it). Not over a brush the user painted.
  const bool painted = saved && saved->brush && !saved->brush_from_seed && dropped.empty();
  if (entry.lidar_seed && !painted) {
    std::vector<int> pixels;
    for (int i : SelectSeedRegion(cloud, *entry.lidar_seed))
      if (image->pixel_of_point[i] >= 0) pixels.push_back(image->pixel_of_point[i]);
    std::sort(pixels.begin(), pixels.end());
    pixels.erase(std::unique(pixels.begin(), pixels.end()), pixels.end());
    record_.Edit(
        [&](Session* session) {
          PairState* pair = FindPair(session, entry.id);
          if (!pair) return;
          pair->brush = BrushMask{image->rows, image->columns, std::move(pixels)};
          pair->brush_from_seed = true;
        },
        /*amend=*/true);
  }
  std::lock_guard lock(pairs_mutex_);
  pairs_[index].image = std::move(image);
  return dropped;
}

const PairFeatures& CalibrationJob::DetectLidar(int index, const LidarCloud& cloud,
                                                const LidarImage* image, bool use_seed) {
  PairEntry entry = dataset_.pairs[index];
  if (!use_seed) entry.lidar_seed.reset();
  std::string why;
  BoardOrigin origin;
  std::optional<LidarPlaneFit> fit;
  if (std::optional<BoardHint> hint = BoardHintFor(entry, EditOf(entry.id), image, &why)) {
    hint->background = Background();
    fit = ExtractLidarFeatures(dataset_, cloud, *hint, Pipeline(), &why, &origin);
  }
  {
    std::lock_guard lock(pairs_mutex_);
    JobPair& pair = pairs_.at(index);
    pair.detected.lidar = std::move(fit);
    pair.detected.board_origin = origin;
    pair.lidar_failure = pair.detected.lidar ? "" : why;
    pair.lidar_tried = true;
    pair.completed.reset();  // completion's board answered the detection before this one
    ++pair.detections;
    Restatus(&pair);
  }
  RecordStatuses();
  return pairs_[index].detected;  // only this thread writes it
}

void CalibrationJob::RecordStatuses() {
  std::vector<std::pair<std::string, PairFeatures>> now;
  {
    std::lock_guard lock(pairs_mutex_);
    for (const JobPair& pair : pairs_) {
      if (!pair.lidar_tried) continue;  // pending until both sides were looked at
      now.emplace_back(pair.detected.id, pair.Now());
    }
  }
  record_.Edit([&](Session* session) { WriteVerdicts(now, session); }, /*amend=*/true);
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
  if (!rejected) RecordStatuses();
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
  const Session record = record_.Current();
  std::lock_guard lock(pairs_mutex_);
  return DetectedPairs(record);
}

const CalibrationOutcome& CalibrationJob::Solve() {
  // The record read once: the edits, the rejections and the settings of one moment, which
  // CommitOutcome compares with the record's when the solve is done.
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
  std::vector<PairFeatures> detected;
  {
    std::lock_guard lock(pairs_mutex_);
    detected = DetectedPairs(record);
    solved_detections_.clear();
    for (const JobPair& pair : pairs_) solved_detections_.push_back(pair.detections);
  }
  iterations_.clear();
  const IterationCallback on_iteration = [this](const IterationReport& it) {
    iterations_.push_back(it);
    if (events_.iteration) events_.iteration(it);
  };
  // Every solve starts from what detection found, as `calibrate` does: a board completion
  // rescued is rescued again, one the camera disagrees with is looked at again.
  outcome_ = SolveExtractedPairs(dataset_, entries, std::move(detected), pipeline, solved_edits_,
                                 on_iteration);
  outcome_->background_note = background_note_;
  outcome_->estimated_intrinsics = options_.estimated_intrinsics;
  solved_with_ = pipeline.solver;
  if (outcome_->solution) last_solution_ = outcome_->solution;
  advice_.reset();
  return *outcome_;
}

bool CalibrationJob::CommitOutcome(bool own_step) {
  if (!outcome_) return false;
  const Session record = record_.Current();
  if (EditsFromSession(record) != solved_edits_ || record.settings != solved_settings_) {
    outcome_.reset();
    advice_.reset();
    return false;
  }
  // Completion's boards and verdicts, for the pairs still on the detection the solve started from.
  std::vector<std::pair<std::string, PairFeatures>> verdicts;
  {
    std::lock_guard lock(pairs_mutex_);
    for (size_t i = 0; i < outcome_->pairs.size() && i < pairs_.size(); ++i) {
      JobPair& pair = pairs_[i];
      if (i >= solved_detections_.size() || pair.detections != solved_detections_[i]) continue;
      pair.completed = outcome_->pairs[i];
      verdicts.emplace_back(pair.detected.id, outcome_->pairs[i]);
    }
  }
  std::optional<SessionResult> result;
  if (outcome_->solution) {
    result = SessionResultFromSolver(*outcome_->solution);
    for (const std::string& note :
         {DescribeLidarModel(*outcome_), DescribeLearnedLidarNoise(*outcome_),
          DescribeLidarTimes(*outcome_), CountResiduals(*outcome_).note})
      if (!note.empty()) result->notes.push_back(note);
    // A moving capture's clocks, as the summary says them (still holds: nothing to say).
    if (outcome_->time_offset.camera_minus_lidar_s || outcome_->time_offset.moving_pairs > 0)
      result->notes.push_back(DescribeTimeOffset(outcome_->time_offset));
    for (const IterationReport& it : iterations_) {
      result->step_history.push_back(it.step_norm);
      result->estimate_history.push_back(it.cam_from_lidar);
      if (it.reweighted) result->reweighted_iterations.push_back(it.iteration);
    }
  }
  record_.Edit(
      [&](Session* session) {
        WriteVerdicts(verdicts, session);
        session->result = std::move(result);
      },
      /*amend=*/!own_step);
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
  std::vector<PairFeatures> detected;
  {
    std::lock_guard lock(pairs_mutex_);
    detected = DetectedPairs(record);
  }
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
