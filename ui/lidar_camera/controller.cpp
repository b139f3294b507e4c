#include "ui/lidar_camera/controller.h"

#include <algorithm>
#include <cmath>
#include <ctime>

#include "core/base/allocator.h"
#include "core/base/atomic_file.h"
#include "core/io/cloud_io.h"
#include "core/io/image_io.h"
#include "core/lidar_camera/result_io.h"

namespace calibench::ui {
namespace {

constexpr int kThumbnailWidth = 160;  // pixels

std::vector<int> SeedBrush(const LidarCloud& cloud, const LidarImage& image,
                           const LidarSeed& seed) {
  std::vector<int> pixels;
  for (int i : SelectSeedRegion(cloud, seed))
    if (image.pixel_of_point[i] >= 0) pixels.push_back(image.pixel_of_point[i]);
  std::sort(pixels.begin(), pixels.end());
  pixels.erase(std::unique(pixels.begin(), pixels.end()), pixels.end());
  return pixels;
}

// Pixels of a circle on the LiDAR image; columns wrap around (azimuth is periodic).
std::vector<int> CirclePixels(int rows, int columns, int row, int column, float radius) {
  std::vector<int> pixels;
  const int r = static_cast<int>(std::ceil(radius));
  for (int dr = -r; dr <= r; ++dr) {
    const int y = row + dr;
    if (y < 0 || y >= rows) continue;
    for (int dc = -r; dc <= r; ++dc) {
      if (dr * dr + dc * dc > radius * radius) continue;
      const int x = ((column + dc) % columns + columns) % columns;
      pixels.push_back(y * columns + x);
    }
  }
  std::sort(pixels.begin(), pixels.end());
  return pixels;
}

// The brush a loading pair starts with: the session's painted brush (`painted`, null when none)
// replaces the seed; otherwise the seed selects the region and the brush only pictures it (as
// EditsFromSession tells `calibench calibrate --session`). A mask painted on another image layout
// would mark other returns: it is refused, not reread, and the returned text says why (empty
// when nothing was refused).
std::string StartBrush(const PairEntry& entry, const LidarCloud& cloud, const LidarImage& image,
                       const BrushMask* painted, const std::vector<int>& painted_pixels,
                       PairView* loaded) {
  std::string dropped;
  if (painted && BrushFitsImage(*painted, image.rows, image.columns, &dropped)) {
    loaded->brush_pixels = painted_pixels;
    return "";
  }
  if (entry.lidar_seed) {
    loaded->brush_pixels = SeedBrush(cloud, image, *entry.lidar_seed);
    loaded->brush_from_seed = true;
  }
  if (!painted) return "";
  return "pair " + entry.id + ": its brush from the session was dropped: " + entry.cloud.string() +
         ": " + dropped;
}

}  // namespace

Controller::Controller(PipelineOptions options) : pipeline_(std::move(options)) {}

Controller::~Controller() { StopWorker(); }

namespace {

// Moves `path` aside to `<path>.<YYYYmmdd-HHMMSS>.bak` (a new name each time) and returns it.
std::filesystem::path BackUpSession(const std::filesystem::path& path) {
  const std::time_t now = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof(stamp), "%Y%m%d-%H%M%S", std::localtime(&now));
  std::filesystem::path backup = path.string() + "." + stamp + ".bak";
  for (int n = 2; std::filesystem::exists(backup); ++n)
    backup = path.string() + "." + stamp + "-" + std::to_string(n) + ".bak";
  std::error_code ec;
  std::filesystem::rename(path, backup, ec);
  if (ec)
    throw IoError(path.string() + ": cannot move the session aside to " + backup.string() + " (" +
                  ec.message() + "); it was left as it is");
  return backup;
}

}  // namespace

namespace {

// The session in `path`, checked against the dataset it names. Throws IoError.
std::pair<Session, Dataset> LoadSessionAndDataset(const std::filesystem::path& session_path) {
  Session session = LoadSession(session_path);  // throws IoError; never rewrites the file
  Dataset dataset = LoadDataset(session.dataset);
  if (session.pairs.size() != dataset.pairs.size())
    throw IoError(session_path.string() + ": the session has " +
                  std::to_string(session.pairs.size()) + " pairs but " + dataset.manifest.string() +
                  " has " + std::to_string(dataset.pairs.size()));
  for (size_t i = 0; i < dataset.pairs.size(); ++i)
    if (session.pairs[i].id != dataset.pairs[i].id)
      throw IoError(session_path.string() + ": pair " + std::to_string(i) + " is '" +
                    session.pairs[i].id + "' in the session but '" + dataset.pairs[i].id +
                    "' in the dataset");
  return {std::move(session), std::move(dataset)};
}

}  // namespace

void Controller::OpenDataset(const std::filesystem::path& dataset_path,
                             std::filesystem::path session_path, ExistingSession existing) {
  const Dataset dataset = LoadDataset(dataset_path);
  Session session = NewSession(dataset);
  session.dataset = dataset.manifest;
  if (existing == ExistingSession::kInMemory) {
    Open(dataset, std::move(session), {}, "", std::nullopt);
    return;
  }
  if (session_path.empty()) {
    const auto folder = std::filesystem::is_directory(dataset.manifest)
                            ? dataset.manifest
                            : dataset.manifest.parent_path();
    session_path = folder / "calibench.session.json";
  }
  std::string note;
  std::optional<FileLock> lock = LockSession(session_path, &note);
  if (existing != ExistingSession::kReplace && std::filesystem::exists(session_path)) {
    if (existing == ExistingSession::kResume) {
      try {
        OpenSessionFile(session_path,
                        "resumed the session in " + session_path.string() +
                            " (calibench gui --fresh starts over and keeps it as a backup)",
                        &lock);
        return;
      } catch (const IoError& e) {
        note = "the session there did not open (" + std::string(e.what()) + "): ";
      }
      if (ResumeBackup(session_path, note, &lock)) return;
    }
    note += "kept the old session as " + BackUpSession(session_path).string();
  }
  Open(dataset, std::move(session), session_path, note, std::move(lock));
}

void Controller::OpenSession(const std::filesystem::path& session_path, bool save) {
  if (!save) {
    auto [session, dataset] = LoadSessionAndDataset(session_path);
    Open(dataset, std::move(session), {}, "", std::nullopt);
    return;
  }
  std::string note;
  std::optional<FileLock> lock = LockSession(session_path, &note);
  OpenSessionFile(session_path, note, &lock);
}

std::optional<FileLock> Controller::LockSession(const std::filesystem::path& session,
                                                std::string* note) {
  std::error_code ec;
  if (session_lock_ && std::filesystem::weakly_canonical(session_lock_->locked(), ec) ==
                           std::filesystem::weakly_canonical(session, ec))
    return std::nullopt;  // this controller has it open already
  std::string holder;
  try {
    std::optional<FileLock> lock = FileLock::TryLock(session, &holder);
    if (!lock)
      throw IoError(session.string() + ": the session is open in another Calibench workbench (" +
                    holder + "); close it there first, or open a copy of the file");
    return lock;
  } catch (const IoError& e) {
    if (!holder.empty()) throw;
    // No lock file can be made, so no session file either: editing goes on, saving will fail
    // and say so.
    *note = std::string("cannot lock the session (") + e.what() + ")";
    return std::nullopt;
  }
}

bool Controller::ResumeBackup(const std::filesystem::path& session_path, const std::string& note,
                              std::optional<FileLock>* lock) {
  for (int n = 1; n <= AutosaveOptions{}.backups; ++n) {
    const std::filesystem::path backup = SessionBackupPath(session_path, n);
    if (!std::filesystem::exists(backup)) continue;
    try {
      auto [session, dataset] = LoadSessionAndDataset(backup);
      const std::string kept = BackUpSession(session_path).string();
      Open(dataset, std::move(session), session_path,
           note + "resumed its newest backup that opens, " + backup.string() +
               "; the one that did not open is kept as " + kept,
           std::move(*lock));
      return true;
    } catch (const IoError&) {
      // An older backup, then.
    }
  }
  return false;
}

void Controller::OpenSessionFile(const std::filesystem::path& session_path, const std::string& note,
                                 std::optional<FileLock>* lock) {
  auto [session, dataset] = LoadSessionAndDataset(session_path);
  Open(dataset, std::move(session), session_path, note, std::move(*lock));
}

void Controller::Open(const Dataset& dataset, Session session, std::filesystem::path session_path,
                      const std::string& note, std::optional<FileLock> session_lock) {
  WaitIdle();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (session_lock)
      session_lock_ = std::move(session_lock);
    else if (session_path.empty() || !session_lock_ || session_lock_->locked() != session_path)
      session_lock_.reset();
    state_ = Snapshot{};
    state_.dataset = dataset;
    state_.dataset_path = dataset.manifest;
    state_.session_path = session_path;
    state_.pairs.resize(dataset.pairs.size());
    for (size_t i = 0; i < dataset.pairs.size(); ++i) state_.pairs[i].id = dataset.pairs[i].id;
    state_.loading_total = static_cast<int>(dataset.pairs.size());
    load_warnings_.clear();
    open_note_ = note;
    session_ = std::move(session);
    ApplySessionToState(session_);
    history_.Reset(session_);
    autosaver_ = session_path.empty() ? nullptr : std::make_unique<Autosaver>(session_path);
    SetStatus("loading " + std::to_string(dataset.pairs.size()) + " pairs from " +
                  dataset.manifest.string(),
              false);
  }
  // The selected pair and its image first, so that it is on screen while the others load.
  int first = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    first = std::max(0, state_.selected);
  }
  if (!dataset.pairs.empty()) {
    worker_.Enqueue([this, first] { LoadPair(first); });
    worker_.Enqueue([this] { EnsureSelectedImage(); });
  }
  for (int i = 0; i < static_cast<int>(dataset.pairs.size()); ++i)
    if (i != first) worker_.Enqueue([this, i] { LoadPair(i); });
}

void Controller::ApplySessionToState(const Session& session) {
  ApplySessionOptions(session, &pipeline_);
  state_.view = session.view;
  state_.method = session.method;
  state_.huber_delta = session.huber_delta;
  state_.max_iterations = session.max_iterations;
  state_.estimate_range_offset = session.estimate_range_offset;
  for (size_t i = 0; i < session.pairs.size() && i < state_.pairs.size(); ++i) {
    PairView& pair = state_.pairs[i];
    pair.status = session.pairs[i].status;
    pair.reason = session.pairs[i].reason;
    if (session.pairs[i].brush) pair.brush_pixels = session.pairs[i].brush->pixels;
    pair.brush_from_seed = session.pairs[i].brush_from_seed;
    pair.brush_edited = session.pairs[i].brush.has_value() && !pair.brush_from_seed;
  }
  state_.selected = -1;
  for (size_t i = 0; i < state_.pairs.size(); ++i)
    if (state_.pairs[i].id == session.view.selected_pair) state_.selected = static_cast<int>(i);
  if (state_.selected < 0 && !state_.pairs.empty()) state_.selected = 0;
  state_.solver = SolverView{};
  if (session.result) {
    state_.solver.result = SolverResultFromSession(*session.result, session.method);
    // The recorded convergence, so that the solver panel and the replay look as they did.
    const auto& costs = session.result->cost_history;
    const auto& steps = session.result->step_history;
    const auto& estimates = session.result->estimate_history;
    if (steps.size() == costs.size() && estimates.size() == costs.size())
      for (size_t i = 0; i < costs.size(); ++i)
        state_.solver.iterations.push_back({static_cast<int>(i), costs[i], steps[i], estimates[i]});
    for (int k : session.result->reweighted_iterations)
      if (k >= 0 && k < static_cast<int>(state_.solver.iterations.size()))
        state_.solver.iterations[k].reweighted = true;
  }
  state_.can_undo = history_.CanUndo();
  state_.can_redo = history_.CanRedo();
  ++state_.generation;
}

void Controller::CommitEdit() {
  const bool had_selected =
      state_.selected >= 0 && state_.selected < static_cast<int>(state_.pairs.size());
  state_.view.selected_pair = had_selected ? state_.pairs[state_.selected].id : "";
  session_.view = state_.view;
  session_.method = state_.method;
  session_.huber_delta = state_.huber_delta;
  session_.max_iterations = state_.max_iterations;
  session_.estimate_range_offset = state_.estimate_range_offset;
  for (size_t i = 0; i < state_.pairs.size(); ++i) {
    PairState& p = session_.pairs[i];
    const PairView& v = state_.pairs[i];
    p.status = v.status;
    p.reason = v.reason;
    // No brush for a pair left to detection: reopened (or calibrated with --session) it is
    // detected again, while an erased brush stays erased.
    if (v.lidar_image && (v.brush_edited || v.brush_from_seed)) {
      BrushMask mask{v.lidar_image->rows, v.lidar_image->columns, v.brush_pixels};
      p.brush = mask;
      p.brush_from_seed = v.brush_from_seed;
    } else if (v.lidar_image) {
      p.brush.reset();
      p.brush_from_seed = false;
    }
  }
  session_.result.reset();
  if (state_.solver.result) {
    session_.result = SessionResultFromSolver(*state_.solver.result);
    for (const IterationReport& it : state_.solver.iterations) {
      session_.result->step_history.push_back(it.step_norm);
      session_.result->estimate_history.push_back(it.cam_from_lidar);
      if (it.reweighted) session_.result->reweighted_iterations.push_back(it.iteration);
    }
  }
  if (stroke_open_)
    history_.Amend(session_);
  else
    history_.Push(session_);
  state_.can_undo = history_.CanUndo();
  state_.can_redo = history_.CanRedo();
  Autosave();
  ++state_.generation;
}

void Controller::Autosave() {
  try {
    if (autosaver_) autosaver_->Save(session_);
    state_.save_error.clear();
  } catch (const IoError& e) {
    state_.save_error = e.what();
    SetStatus(std::string("autosave failed: ") + e.what(), true);
  }
}

void Controller::OnAllPairsLoaded() {
  worker_.Enqueue([this] { DetectWithBackground(); });
  // What went wrong while loading stays on the status line (in the warning colour).
  std::string loaded_line = "loaded " + std::to_string(state_.loading_total) + " pairs";
  if (!open_note_.empty()) loaded_line += "; " + open_note_;
  for (const std::string& warning : load_warnings_) loaded_line += "; " + warning;
  SetStatus(loaded_line, !load_warnings_.empty());
  load_warnings_.clear();
  // A reopened session with a result shows its reprojection again.
  const int selected = state_.selected;
  if (state_.solver.result) worker_.Enqueue([this, selected] { ComputeReprojection(selected); });
}

void Controller::LoadPair(int index) {
  PairEntry entry;
  Dataset dataset;
  std::vector<int> saved_brush;
  std::optional<BrushMask> saved_mask;
  bool painted = false;  // the session holds a brush the user painted (or erased)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    entry = state_.dataset->pairs[index];
    dataset = *state_.dataset;
    saved_brush = state_.pairs[index].brush_pixels;
    const PairState& saved = session_.pairs[index];
    painted = saved.brush.has_value() && !saved.brush_from_seed;
    saved_mask = saved.brush;
  }
  std::string brush_dropped;  // why the session's brush does not fit this pair's cloud
  // The pipeline's own steps (core/lidar_camera/pipeline.h), as `calibench calibrate` runs them.
  PairView loaded;
  std::string why;
  auto inputs = LoadPairInputs(dataset, entry, &why);
  bool selected = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    selected = index == state_.selected;
  }
  if (inputs) {
    auto cloud = std::make_shared<LidarCloud>(std::move(inputs->cloud));
    auto lidar_image = std::make_shared<LidarImage>(ProjectById(*cloud, LidarImageOptions{}));
    loaded.thumbnail = std::make_shared<ImageU8>(ResizeImage(inputs->image, kThumbnailWidth));
    CameraFeatures camera = ExtractCameraFeatures(dataset, inputs->image, pipeline_);
    loaded.detection = std::move(camera.detection);
    loaded.camera = std::move(camera.observation);
    loaded.camera_failure = camera.failure;
    brush_dropped = StartBrush(entry, *cloud, *lidar_image, painted ? &*saved_mask : nullptr,
                               saved_brush, &loaded);
    painted = painted && brush_dropped.empty();
    loaded.cloud = cloud;
    loaded.lidar_image = lidar_image;
    // The camera view shows the selected pair's image: decoded once, here.
    if (selected)
      KeepDecodedImage(entry.image, std::make_shared<const ImageU8>(std::move(inputs->image)));
  } else {
    loaded.camera_failure = why;
  }
  bool refit_now = false;  // the selected pair's plane comes before the other pairs load
  {
    std::lock_guard<std::mutex> lock(mutex_);
    PairView& pair = state_.pairs[index];
    // Loading is the pair's first job after Open: besides its header nothing was derived yet.
    static_cast<PairHeader&>(loaded) = pair;
    loaded.loaded = true;
    pair = std::move(loaded);
    ++state_.loading_done;
    ++state_.generation;
    if (!brush_dropped.empty()) {
      session_.pairs[index].brush.reset();
      session_.pairs[index].brush_from_seed = false;
      load_warnings_.push_back(brush_dropped);
      SetStatus(brush_dropped, true);
    }
    // Detection waits for every cloud: the background model over them keeps static board-sized
    // panels out (as CalibrateDataset does).
    const bool detects = !pair.brush_from_seed && !painted;
    refit_now = pair.cloud && !detects && index == state_.selected &&
                state_.loading_done < state_.loading_total;
    if (pair.cloud && !detects && !refit_now) worker_.Enqueue([this, index] { RefitLidar(index); });
    if (pair.cloud && detects)
      pair.lidar_failure = "finding the board once every pair is loaded ...";
    if (!pair.cloud) {
      pair.status = PairStatus::kFailed;
      pair.reason = pair.camera_failure;
    }
    if (state_.loading_done == state_.loading_total) OnAllPairsLoaded();
  }
  if (refit_now) RefitLidar(index);
}

void Controller::DetectWithBackground() {
  std::vector<std::shared_ptr<const LidarCloud>> clouds;
  std::vector<int> detect;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (size_t i = 0; i < state_.pairs.size(); ++i) {
      const PairView& pair = state_.pairs[i];
      if (!pair.cloud) continue;
      clouds.push_back(pair.cloud);
      if (!pair.brush_from_seed && !pair.brush_edited) detect.push_back(static_cast<int>(i));
    }
  }
  background_.reset();
  if (!detect.empty() && pipeline_.background_model) {
    SceneBackground background;
    for (const auto& cloud : clouds) background.Add(*cloud);
    std::string why;
    if (background.Finish(&why)) {
      background_ = std::move(background);
    } else {
      std::lock_guard<std::mutex> lock(mutex_);
      SetStatus("board detection without a background model: " + why, false);
    }
  }
  for (int index : detect) RefitLidar(index);
  // Loading is over: what its transient buffers took goes back (core/base/allocator.h).
  ReleaseFreedMemory();
}

void Controller::RefitLidar(int index) {
  std::shared_ptr<const LidarCloud> cloud;
  std::shared_ptr<const LidarImage> image;
  std::vector<int> brush;
  bool brush_from_seed = false;
  bool brush_edited = false;
  Dataset dataset;
  std::optional<LidarSeed> seed;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    dataset = *state_.dataset;
    seed = dataset.pairs[index].lidar_seed;
    cloud = state_.pairs[index].cloud;
    image = state_.pairs[index].lidar_image;
    brush = state_.pairs[index].brush_pixels;
    brush_from_seed = state_.pairs[index].brush_from_seed;
    brush_edited = state_.pairs[index].brush_edited;
  }
  if (!cloud || !image) return;
  // The same choice of region as `calibench calibrate`: the seed itself while the brush only
  // pictures it; once painted (or erased), the brush.
  BoardHint hint;
  hint.image = image.get();
  // Seed, else the user's brush (an erased one means "no board here"), else detection.
  if (brush_from_seed)
    hint.seed = seed;
  else if (brush_edited)
    hint.brush_pixels = &brush;
  hint.detect = !brush_edited;
  hint.background = background_ ? &*background_ : nullptr;  // written on this thread only
  std::string why;
  BoardOrigin origin;
  const std::optional<LidarPlaneFit> fit =
      ExtractLidarFeatures(dataset, *cloud, hint, pipeline_, &why, &origin);
  std::lock_guard<std::mutex> lock(mutex_);
  PairView& pair = state_.pairs[index];
  if (pair.brush_pixels != brush) return;  // a newer stroke queued its own refit
  pair.lidar = fit;
  pair.lidar_failure = fit ? "" : why;
  pair.board_origin = origin;
  // A detected board shows as the brush (in its own colour) until the user edits it.
  if (origin.source == BoardSource::kDetected) {
    pair.brush_pixels.clear();
    if (fit)
      for (int i : fit->inliers)
        if (pair.lidar_image->pixel_of_point[i] >= 0)
          pair.brush_pixels.push_back(pair.lidar_image->pixel_of_point[i]);
    std::sort(pair.brush_pixels.begin(), pair.brush_pixels.end());
    pair.brush_detected = true;
  }
  // A pair with both planes is usable and accepted unless the user rejected it; one that lost a
  // plane fails with the reason.
  if (pair.status != PairStatus::kRejected) {
    PairFeatures features = FeaturesOf(pair);
    SetStatusFromFeatures(&features, pair.lidar_failure, pair.camera_failure);
    pair.status = features.status;
    pair.reason = features.reason;
  }
  ++state_.generation;
  if (state_.loading_done == state_.loading_total) {
    RecomputeResiduals();
    CommitEdit();
  }
}

bool Controller::SolvesWith(const PairView& pair) {
  return pair.status == PairStatus::kAccepted && pair.lidar && pair.camera;
}

SolverResult Controller::ResultForCurrentPairs() const {
  SolverResult result = *state_.solver.result;
  std::vector<std::string> accepted;
  for (const PairView& pair : state_.pairs)
    if (SolvesWith(pair)) accepted.push_back(pair.id);
  // The solve's own figures while its pairs are still the accepted ones (they include the
  // outliers it gated); after accept/reject since, or after a reload, the solver's residuals at
  // the shown estimate over the pairs accepted now.
  if (accepted == state_.solver.solved_pair_ids && result.residuals.size() == accepted.size())
    return result;
  std::vector<PairFeatures> features;
  for (const PairView& pair : state_.pairs) features.push_back(FeaturesOf(pair));
  EvaluateAtSolution(features, SolverOptionsFromState(), &result);
  return result;
}

void Controller::RecomputeResiduals() {
  for (PairView& pair : state_.pairs) pair.residual.reset();
  if (!state_.solver.result) return;
  const SolverResult at_estimate = ResultForCurrentPairs();
  size_t solved = 0;
  for (PairView& pair : state_.pairs) {
    if (!SolvesWith(pair)) continue;
    pair.residual = at_estimate.residuals[solved];
    pair.robust_weight = at_estimate.robust_weights[solved];
    ++solved;
  }
}

PairFeatures Controller::FeaturesOf(const PairView& pair) {
  PairFeatures features;
  features.id = pair.id;
  features.status = pair.status;
  features.reason = pair.reason;
  features.lidar = pair.lidar;
  features.camera = pair.camera;
  features.board_origin = pair.board_origin;
  // An accepted pair that lost a plane cannot be solved with.
  if (features.status == PairStatus::kAccepted && !SolvesWith(pair))
    features.status = PairStatus::kFailed;
  return features;
}

PipelineOptions Controller::PipelineOptionsFromState() const {
  PipelineOptions options = pipeline_;
  options.solver = SolverOptionsFromState();
  return options;
}

SolverOptions Controller::SolverOptionsFromState() const {
  SolverOptions options = pipeline_.solver;
  options.method = state_.method;
  options.huber_delta = state_.huber_delta;
  options.max_iterations = state_.max_iterations;
  // The offset belongs to the weighted method; the checkbox keeps its value across methods.
  options.estimate_range_offset =
      state_.estimate_range_offset && state_.method == SolverMethod::kWeightedMl;
  return options;
}

void Controller::Solve() {
  std::vector<PairFeatures> features;
  PipelineOptions options;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const PairView& pair : state_.pairs) features.push_back(FeaturesOf(pair));
    options = PipelineOptionsFromState();
    state_.solver = SolverView{};
    state_.solver.running = true;
    ++state_.generation;
  }
  // The CLI's solve (SolveFromFeatures), watched iteration by iteration.
  const CalibrationOutcome outcome =
      SolveFromFeatures(std::move(features), options, [this](const IterationReport& it) {
        std::lock_guard<std::mutex> lock(mutex_);
        state_.solver.iterations.push_back(it);
        ++state_.generation;
      });
  std::lock_guard<std::mutex> lock(mutex_);
  state_.solver.running = false;
  if (!outcome.solution) {
    state_.solver.iterations.clear();
    state_.solver.failure = outcome.failure;
    SetStatus("no calibration: " + outcome.failure, true);
    return;
  }
  const SolverResult& result = *outcome.solution;
  state_.solver.result = result;
  state_.solver.solved_pair_ids.clear();
  for (const PairFeatures& p : outcome.pairs)
    if (p.status == PairStatus::kAccepted) state_.solver.solved_pair_ids.push_back(p.id);
  RecomputeResiduals();
  SetStatus("solved with " + std::to_string(state_.solver.solved_pair_ids.size()) + " pairs in " +
                std::to_string(result.iterations) + " iterations" +
                (result.observability.well_constrained ? "" : " (NOT well constrained)"),
            !result.observability.well_constrained);
  CommitEdit();
  const int selected = state_.selected;
  if (selected >= 0) worker_.Enqueue([this, selected] { ComputeReprojection(selected); });
}

void Controller::ComputeReprojection(int index) {
  std::shared_ptr<const LidarCloud> cloud;
  std::optional<Pose> cam_from_lidar;
  CameraModel camera;
  ViewState view;
  std::string id;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (index < 0 || index >= static_cast<int>(state_.pairs.size()) || !state_.solver.result)
      return;
    cloud = state_.pairs[index].cloud;
    cam_from_lidar = state_.solver.result->cam_from_lidar;
    camera = state_.dataset->camera;
    view = state_.view;
    id = state_.pairs[index].id;
  }
  if (!cloud) return;
  auto reprojection = std::make_shared<Reprojection>();
  reprojection->pair_id = id;
  reprojection->points = ProjectCloud(camera, *cam_from_lidar, *cloud);
  if (view.visibility == VisibilityMode::kHpr) {
    std::vector<Vec3> in_cam;
    in_cam.reserve(reprojection->points.size());
    for (const ProjectedPoint& p : reprojection->points)
      in_cam.push_back(*cam_from_lidar * cloud->points[p.index].cast<double>());
    HprOptions options;
    options.radius_exponent = view.hpr_radius_exponent;
    reprojection->visible = HiddenPointRemoval(in_cam, options);
  } else if (view.visibility == VisibilityMode::kZBuffer) {
    reprojection->visible = ZBufferVisibility(camera, reprojection->points, ZBufferOptions{});
  } else {
    reprojection->visible.assign(reprojection->points.size(), true);
  }
  std::lock_guard<std::mutex> lock(mutex_);
  state_.reprojection = reprojection;
  ++state_.generation;
}

void Controller::EnsureSelectedImage() {
  std::filesystem::path path;
  const std::shared_ptr<const ImageU8> image = LoadSelectedImageFile(&path);
  if (!image) return;
  CameraModel camera;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    camera = state_.dataset->camera;
  }
  auto undistorted = std::make_shared<const UndistortedView>(Undistort(camera, *image));
  std::lock_guard<std::mutex> lock(mutex_);
  if (!StillSelected(path)) return;
  state_.selected_image = image;
  state_.selected_undistorted = undistorted;
  ++state_.generation;
}

bool Controller::ValidPair(int index) const {
  return index >= 0 && index < static_cast<int>(state_.pairs.size());
}

template <>
void Controller::Handle(const SelectPair& select) {
  if (!ValidPair(select.index) || select.index == state_.selected) return;
  state_.selected = select.index;
  state_.selected_image.reset();
  state_.selected_undistorted.reset();
  state_.reprojection.reset();
  CommitEdit();
  worker_.Enqueue([this] { EnsureSelectedImage(); });
  const int index = select.index;
  worker_.Enqueue([this, index] { ComputeReprojection(index); });
}

template <>
void Controller::Handle(const SetPairStatus& status) {
  if (!ValidPair(status.index)) return;
  PairView& pair = state_.pairs[status.index];
  if (status.status == PairStatus::kAccepted && !(pair.lidar && pair.camera)) {
    SetStatus("pair " + pair.id + " cannot be accepted: " +
                  (!pair.camera ? "no camera plane (" + pair.camera_failure + ")"
                                : "no LiDAR plane (" + pair.lidar_failure + ")"),
              true);
    return;
  }
  pair.status = status.status;
  pair.reason = status.status == PairStatus::kRejected ? kRejectedByUser : "";
  SetStatus("pair " + pair.id + " " + PairStatusName(pair.status) +
                (state_.solver.result ? "; press Run to re-solve" : ""),
            false);
  CommitEdit();
}

template <>
void Controller::Handle(const BrushStroke& stroke) {
  if (!ValidPair(stroke.index) || !state_.pairs[stroke.index].lidar_image) return;
  const LidarImage& image = *state_.pairs[stroke.index].lidar_image;
  Paint(stroke.index,
        CirclePixels(image.rows, image.columns, stroke.row, stroke.column, stroke.radius_px),
        stroke.erase);
}

template <>
void Controller::Handle(const ClearBrush& clear) {
  if (!ValidPair(clear.index)) return;
  state_.pairs[clear.index].brush_pixels.clear();
  state_.pairs[clear.index].brush_from_seed = false;
  state_.pairs[clear.index].brush_edited = true;
  state_.pairs[clear.index].brush_detected = false;
  CommitEdit();
  const int index = clear.index;
  worker_.Enqueue([this, index] { RefitLidar(index); });
}

template <>
void Controller::Handle(const EndStroke&) {
  stroke_open_ = false;
}

template <>
void Controller::Handle(const DetectBoardAgain& again) {
  if (!again.all && !ValidPair(again.index)) return;
  for (size_t i = 0; i < state_.pairs.size(); ++i) {
    if (!again.all && static_cast<int>(i) != again.index) continue;
    PairView& pair = state_.pairs[i];
    if (!pair.lidar_image) continue;
    pair.brush_pixels.clear();
    pair.brush_from_seed = false;
    pair.brush_edited = false;
    pair.brush_detected = false;
    const int index = static_cast<int>(i);
    worker_.Enqueue([this, index] { RefitLidar(index); });
  }
  CommitEdit();
}

template <>
void Controller::Handle(const PaintPoints& paint) {
  if (ValidPair(paint.index)) Paint(paint.index, paint.pixels, paint.erase);
}

void Controller::Paint(int index, const std::vector<int>& pixels, bool erase) {
  PairView& pair = state_.pairs[index];
  std::vector<int> merged;
  if (erase)
    std::set_difference(pair.brush_pixels.begin(), pair.brush_pixels.end(), pixels.begin(),
                        pixels.end(), std::back_inserter(merged));
  else
    std::set_union(pair.brush_pixels.begin(), pair.brush_pixels.end(), pixels.begin(), pixels.end(),
                   std::back_inserter(merged));
  if (merged == pair.brush_pixels) return;
  pair.brush_pixels = std::move(merged);
  pair.brush_from_seed = false;  // painted: the brush replaces the seed from now on
  pair.brush_edited = true;
  pair.brush_detected = false;
  CommitEdit();
  stroke_open_ = true;  // the stroke's later dabs amend this undo step
  worker_.Enqueue([this, index] { RefitLidar(index); });
}

template <>
void Controller::Handle(const RunSolver&) {
  worker_.Enqueue([this] { Solve(); });
}

template <>
void Controller::Handle(const ResetSolver&) {
  state_.solver = SolverView{};
  state_.reprojection.reset();
  RecomputeResiduals();
  CommitEdit();
}

template <>
void Controller::Handle(const SetSolverOptions& options) {
  SolverOptions check;
  check.huber_delta = options.huber_delta;
  check.max_iterations = options.max_iterations;
  std::string why;
  if (!check.Check(&why)) {
    SetStatus("solver options: " + why, true);
    return;
  }
  const bool method_changed = state_.method != options.method ||
                              state_.estimate_range_offset != options.estimate_range_offset;
  state_.method = options.method;
  state_.estimate_range_offset = options.estimate_range_offset;
  state_.huber_delta = options.huber_delta;
  state_.max_iterations = options.max_iterations;
  // Residuals and weights shown for the current estimate depend on the method.
  if (method_changed) RecomputeResiduals();
  CommitEdit();
}

template <>
void Controller::Handle(const SetView& view) {
  const bool visibility_changed = view.view.visibility != state_.view.visibility ||
                                  view.view.hpr_radius_exponent != state_.view.hpr_radius_exponent;
  state_.view = view.view;
  CommitEdit();
  if (visibility_changed) {
    const int index = state_.selected;
    worker_.Enqueue([this, index] { ComputeReprojection(index); });
  }
}

std::filesystem::path Controller::NextToSession(const std::filesystem::path& path) const {
  if (path.is_absolute() || state_.session_path.empty()) return path;
  return state_.session_path.parent_path() / path;
}

template <>
void Controller::Handle(const ExportResult& export_result) {
  if (!state_.solver.result) {
    SetStatus("nothing to export: run the solver first", true);
    return;
  }
  // What `calibench calibrate` writes: the pairs as they stand, the solution with the solver's
  // residuals at it for the accepted ones.
  CalibrationOutcome outcome;
  for (const PairView& pair : state_.pairs) outcome.pairs.push_back(FeaturesOf(pair));
  outcome.solution = ResultForCurrentPairs();
  const std::filesystem::path path = NextToSession(export_result.path);
  try {
    if (export_result.format) {
      const ExportFrames& frames = export_result.frames;
      std::string why;
      if (!frames.Check(&why)) {
        SetStatus("export: " + why, true);
        return;
      }
      const std::string source =
          state_.session_path.empty() ? "the workbench" : state_.session_path.filename().string();
      WriteFileAtomically(path, ExportCalibration(*export_result.format,
                                                  outcome.solution->cam_from_lidar, frames, source)
                                    .text);
      SetStatus("exported " + path.string() + " (" + ExportFormatName(*export_result.format) +
                    "): the pose of '" + frames.child() + "' in '" + frames.parent() +
                    "', camera frame " + CameraFrameName(frames.camera_frame),
                false);
      return;
    }
    WriteResult(path, outcome, SolverOptionsFromState());
    SetStatus("exported " + path.string(), false);
  } catch (const IoError& e) {
    SetStatus(e.what(), true);
  }
}

template <>
void Controller::Handle(const SaveSessionAs& save) {
  const std::filesystem::path path = NextToSession(save.path);
  try {
    std::string note;
    std::optional<FileLock> lock = LockSession(path, &note);  // throws when another has it open
    SaveSession(path, session_);
    if (lock) session_lock_ = std::move(lock);
    autosaver_ = std::make_unique<Autosaver>(path);
    state_.session_path = path;
    state_.save_error.clear();
    SetStatus("saved session " + path.string(), false);
  } catch (const IoError& e) {
    state_.save_error = e.what();
    SetStatus(e.what(), true);
  }
}

template <>
void Controller::Handle(const Undo&) {
  Restore(history_.Undo());
}
template <>
void Controller::Handle(const Redo&) {
  Restore(history_.Redo());
}

void Controller::Restore(const std::optional<Session>& restored) {
  if (!restored) return;
  std::vector<std::vector<int>> before;
  for (const PairView& p : state_.pairs) before.push_back(p.brush_pixels);
  session_ = *restored;
  ApplySessionToState(session_);
  RecomputeResiduals();
  Autosave();
  for (int i = 0; i < static_cast<int>(state_.pairs.size()); ++i)
    if (state_.pairs[i].brush_pixels != before[i]) worker_.Enqueue([this, i] { RefitLidar(i); });
}

void Controller::Apply(const Intent& intent) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!state_.dataset) return;
  // A stroke is its dabs; anything else in between ends it.
  if (!std::holds_alternative<BrushStroke>(intent) && !std::holds_alternative<PaintPoints>(intent))
    stroke_open_ = false;
  std::visit([this](const auto& what) { Handle(what); }, intent);
}

}  // namespace calibench::ui
