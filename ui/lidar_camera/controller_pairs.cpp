// The controller's pairs: loading each pair's files on the worker, the board's detection (with
// the scene's background), the LiDAR refit after a brush edit, and the brush intents.
#include <algorithm>
#include <cmath>
#include <ctime>

#include "core/base/allocator.h"
#include "core/base/atomic_file.h"
#include "core/io/cloud_io.h"
#include "core/io/image_io.h"
#include "core/lidar_camera/result_io.h"
#include "ui/lidar_camera/controller.h"

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
    // Still the user's word once loaded: the job refits from it, the next autosave keeps it.
    loaded->brush_pixels = painted_pixels;
    loaded->brush_edited = true;
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

constexpr const char* kNoTarget = "no board to find: the dataset has no target.json";

}  // namespace

void Controller::OnAllPairsLoaded() {
  mutex_.AssertHeld(__func__);
  if (state_.dataset->missing_target_file.empty()) {
    worker_.Enqueue([this] { DetectWithBackground(); });
  } else {
    // No board to find (a drive opened for the targetless check): no detection, said per pair.
    for (PairView& pair : state_.pairs) {
      if (!pair.awaiting_detection) continue;
      pair.awaiting_detection = false;
      pair.status = PairStatus::kFailed;
      pair.reason = pair.lidar_failure = kNoTarget;
    }
  }
  // What went wrong while loading stays on the status line (in the warning colour).
  std::string loaded_line = "loaded " + std::to_string(state_.loading_total) + " pairs";
  if (!open_note_.empty()) loaded_line += "; " + open_note_;
  for (const std::string& warning : load_warnings_) loaded_line += "; " + warning;
  SetStatus(loaded_line, !load_warnings_.empty());
  load_warnings_.clear();
  // A reopened session with a result shows its reprojection, its meter and (once its boards are
  // found again) its next pose again.
  if (state_.solver.result && !state_.meter) {
    JudgeMeter(/*record=*/true);
    worker_.Enqueue([this] { AdviseFromState(); });
  }
  const int selected = state_.selected;
  if (state_.solver.result) worker_.Enqueue([this, selected] { ComputeReprojection(selected); });
}

bool Controller::FollowsTo(int index) const {
  mutex_.AssertHeld(__func__);
  return !state_.watching.empty() && follow_newest_ && index > state_.selected &&
         index + 1 == static_cast<int>(state_.pairs.size());
}

bool Controller::PairsSettled() const {
  mutex_.AssertHeld(__func__);
  // A followed capture is never all loaded (the next pair may land while this one is read):
  // once the pairs it opened with are in, each new pair counts as soon as it is.
  return state_.loading_done == state_.loading_total ||
         (opened_pairs_loaded_ && !state_.watching.empty());
}

void Controller::LoadPair(int index) {
  Dataset dataset;
  std::vector<int> saved_brush;
  std::optional<BrushMask> saved_mask;
  bool painted = false;  // the session holds a brush the user painted (or erased)
  {
    std::lock_guard lock(mutex_);
    dataset = *state_.dataset;
    saved_brush = state_.pairs[index].brush_pixels;
    if (const std::optional<PairState> saved = job_->record().Pair(state_.pairs[index].id)) {
      painted = saved->brush.has_value() && !saved->brush_from_seed;
      saved_mask = saved->brush;
    }
  }
  const PairEntry& entry = dataset.pairs[index];
  // The job knows the pairs in the order they load (a followed capture's arrive one by one).
  while (job_->size() <= index) job_->AppendPair(dataset.pairs[job_->size()]);
  std::string brush_dropped;  // why the session's brush does not fit this pair's cloud
  // The job reads the pair and finds the board in its image, as for `calibench calibrate`.
  PairView loaded;
  std::string why;
  CameraFeatures camera;  // the job's camera side, its corners shown in the camera view
  auto inputs = job_->ReadPair(index, &camera, &why);
  bool selected = false;
  {
    std::lock_guard lock(mutex_);
    selected = index == state_.selected || FollowsTo(index);
  }
  if (inputs) {
    auto cloud = std::make_shared<LidarCloud>(std::move(inputs->cloud));
    auto lidar_image = std::make_shared<LidarImage>(ProjectById(*cloud, LidarImageOptions{}));
    loaded.thumbnail = std::make_shared<ImageU8>(ResizeImage(inputs->image, kThumbnailWidth));
    loaded.detection = std::move(camera.detection);
    loaded.camera = std::move(camera.observation);
    loaded.camera_failure = camera.failure;
    // No target (a drive for the targetless check): no board to see, whatever the default says.
    if (!dataset.missing_target_file.empty()) {
      loaded.detection.reset();
      loaded.camera.reset();
      loaded.camera_failure = kNoTarget;
    }
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
    std::lock_guard lock(mutex_);
    PairView& pair = state_.pairs[index];
    // Loading is the pair's first job after Open: besides its header nothing was derived yet.
    static_cast<PairHeader&>(loaded) = pair;
    loaded.loaded = true;
    pair = std::move(loaded);
    ++state_.loading_done;
    ++state_.generation;
    OnLivePairLoaded(index);  // a followed capture: follow it, match it against the ghost
    if (!brush_dropped.empty()) {
      job_->record().Adjust([&id = pair.id](Session* session) { ForgetBrush(session, id); });
      load_warnings_.push_back(brush_dropped);
      SetStatus(brush_dropped, true);
    }
    refit_now = ScheduleBoard(index, painted);
    if (state_.loading_done == state_.loading_total) opened_pairs_loaded_ = true;
    if (PairsSettled()) OnAllPairsLoaded();
  }
  if (refit_now) RefitLidar(index);
}

bool Controller::ScheduleBoard(int index, bool painted) {
  mutex_.AssertHeld(__func__);
  PairView& pair = state_.pairs[index];
  if (!pair.cloud) {
    pair.status = PairStatus::kFailed;
    pair.reason = pair.camera_failure;
    return false;
  }
  // Detection waits for every cloud: the background model over them keeps static board-sized
  // panels out (as CalibrateDataset does).
  if (!pair.brush_from_seed && !painted) {
    pair.lidar_failure = PairsSettled() ? "finding the board ..."
                                        : "finding the board once every pair is loaded ...";
    pair.awaiting_detection = true;
    return false;
  }
  // A brush or seed: the selected pair's plane comes before the other pairs load.
  if (index == state_.selected && state_.loading_done < state_.loading_total) return true;
  worker_.Enqueue([this, index] { RefitLidar(index); });
  return false;
}

void Controller::DetectWithBackground() {
  std::vector<std::pair<int, std::shared_ptr<const LidarCloud>>> clouds;  // by pair index
  std::vector<int> awaiting, detected_before;                             // pairs left to detection
  {
    std::lock_guard lock(mutex_);
    for (size_t i = 0; i < state_.pairs.size(); ++i) {
      const PairView& pair = state_.pairs[i];
      if (!pair.cloud) continue;
      clouds.emplace_back(static_cast<int>(i), pair.cloud);
      if (pair.brush_from_seed || pair.brush_edited) continue;
      (pair.awaiting_detection ? awaiting : detected_before).push_back(static_cast<int>(i));
    }
  }
  if (awaiting.empty()) return;
  // The job's background over the clouds in pair order (as `calibrate`'s over the dataset's); a
  // capture that grows adds each new cloud until the model has enough.
  bool became_usable = false;
  const int before = job_->background_clouds();
  for (const auto& [index, cloud] : clouds) became_usable |= job_->AddToBackground(index, *cloud);
  if (job_->background_clouds() > before && !job_->background_usable() &&
      job_->background_clouds() >= 3) {
    std::lock_guard lock(mutex_);
    SetStatus("board detection without a background model: " + job_->background_note(), false);
  }
  std::vector<int> detect = awaiting;
  // The model exists only now: the boards found without it are looked for again with it.
  if (became_usable) {
    detect.insert(detect.end(), detected_before.begin(), detected_before.end());
    std::sort(detect.begin(), detect.end());
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
  {
    std::lock_guard lock(mutex_);
    cloud = state_.pairs[index].cloud;
    image = state_.pairs[index].lidar_image;
    brush = state_.pairs[index].brush_pixels;
    brush_from_seed = state_.pairs[index].brush_from_seed;
  }
  if (!cloud || !image) return;
  // The same choice of region as `calibench calibrate` (the job's BoardHintFor): once painted
  // (or erased), the brush, which the edit put in the job's record before this refit was
  // queued; else the seed while the brush only pictures it ("detect again" forgot it); else
  // detection.
  const PairFeatures features = job_->DetectLidar(index, *cloud, image.get(), brush_from_seed);
  std::lock_guard lock(mutex_);
  PairView& pair = state_.pairs[index];
  if (pair.brush_pixels != brush) return;  // a newer stroke queued its own refit
  pair.lidar = features.lidar;
  pair.lidar_failure = features.lidar ? "" : features.reason;
  pair.awaiting_detection = false;
  pair.board_origin = features.board_origin;
  // A detected board shows as the brush (in its own colour) until the user edits it.
  if (features.board_origin.source == BoardSource::kDetected) {
    pair.brush_pixels.clear();
    if (features.lidar)
      for (int i : features.lidar->inliers)
        if (pair.lidar_image->pixel_of_point[i] >= 0)
          pair.brush_pixels.push_back(pair.lidar_image->pixel_of_point[i]);
    std::sort(pair.brush_pixels.begin(), pair.brush_pixels.end());
    pair.brush_detected = true;
  }
  // A pair with both planes is usable and accepted unless the user rejected it; one that lost a
  // plane fails with the reason (the job's verdict from both sides).
  if (pair.status != PairStatus::kRejected) {
    pair.status = features.status;
    pair.reason = features.reason;
  }
  ++state_.generation;
  if (PairsSettled()) {
    RecomputeResiduals();
    RecordWhatFollowed(/*same_step=*/true);
    RequestSolve();
  }
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
  PairView& pair = state_.pairs[clear.index];
  if (!pair.lidar_image) return;
  pair.brush_pixels.clear();
  pair.brush_from_seed = false;
  pair.brush_edited = true;
  pair.brush_detected = false;
  SetBrushInRecord(pair, /*amend=*/false);  // erased: no board until painted again
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
  bool first = true;  // every pair's brush forgotten in one undo step
  for (size_t i = 0; i < state_.pairs.size(); ++i) {
    if (!again.all && static_cast<int>(i) != again.index) continue;
    PairView& pair = state_.pairs[i];
    if (!pair.lidar_image) continue;
    pair.brush_pixels.clear();
    pair.brush_from_seed = false;
    pair.brush_edited = false;
    pair.brush_detected = false;
    job_->SetBrush(pair.id, std::nullopt, /*amend=*/!first);
    first = false;
    const int index = static_cast<int>(i);
    worker_.Enqueue([this, index] { RefitLidar(index); });
  }
  if (!first) AfterEdit();
}

template <>
void Controller::Handle(const PaintPoints& paint) {
  if (ValidPair(paint.index) && state_.pairs[paint.index].lidar_image)
    Paint(paint.index, paint.pixels, paint.erase);
}

void Controller::SetBrushInRecord(const PairView& pair, bool amend) {
  mutex_.AssertHeld(__func__);
  PairEdit brush;
  brush.brush_pixels = pair.brush_pixels;
  brush.brush_rows = pair.lidar_image->rows;
  brush.brush_columns = pair.lidar_image->columns;
  job_->SetBrush(pair.id, brush, amend);
  AfterEdit();
}

void Controller::Paint(int index, const std::vector<int>& pixels, bool erase) {
  mutex_.AssertHeld(__func__);
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
  SetBrushInRecord(pair, /*amend=*/stroke_open_);
  stroke_open_ = true;  // the stroke's later dabs amend this undo step
  worker_.Enqueue([this, index] { RefitLidar(index); });
}

}  // namespace calibench::ui
