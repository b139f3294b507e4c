// The controller's pairs: loading each pair's files on the worker, the board's detection (with
// the scene's background), and the LiDAR refit after a brush edit (the brush's intents are
// BrushTask's).
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

}  // namespace

void Controller::OnAllPairsLoaded() {
  mutex_.AssertHeld(__func__);
  if (state_.dataset->missing_target_file.empty()) {
    worker_.Enqueue([this] { DetectWithBackground(); });
  } else {
    // No board to find (a drive opened for the targetless check): no detection (the job said
    // so per pair).
    for (PairView& pair : state_.pairs.Edit()) pair.awaiting_detection = false;
    Publish();
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
    guidance_.Judge(/*record=*/true);
    worker_.Enqueue([this] { guidance_.AdviseFromState(); });
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
  {
    std::lock_guard lock(mutex_);
    dataset = *state_.dataset;
  }
  const PairEntry& entry = dataset.pairs[index];
  // The job knows the pairs in the order they load (a followed capture's arrive one by one).
  while (job_->size() <= index) job_->AppendPair(dataset.pairs[job_->size()]);
  // The job reads the pair and finds the board in its image, as for `calibench calibrate`; the
  // view keeps the decoded files.
  std::shared_ptr<const LidarCloud> cloud;
  std::shared_ptr<const LidarImage> lidar_image;
  std::shared_ptr<const ImageU8> thumbnail;  // small BGR picture of the camera image
  std::string why;
  std::string brush_dropped;  // why the session's brush does not fit this pair's cloud
  CameraFeatures camera;      // the job keeps its corners (PairRecord::detection)
  auto inputs = job_->ReadPair(index, &camera, &why);
  bool selected = false;
  {
    std::lock_guard lock(mutex_);
    selected = index == state_.selected || FollowsTo(index);
  }
  if (inputs) {
    cloud = std::make_shared<const LidarCloud>(std::move(inputs->cloud));
    lidar_image = std::make_shared<const LidarImage>(ProjectById(*cloud, LidarImageOptions{}));
    thumbnail = std::make_shared<const ImageU8>(ResizeImage(inputs->image, kThumbnailWidth));
    // The seed's region and the detected board are drawn on the LiDAR image (the job's).
    brush_dropped = job_->PictureOn(index, *cloud, lidar_image);
    // The camera view shows the selected pair's image: decoded once, here.
    if (selected)
      KeepDecodedImage(entry.image, std::make_shared<const ImageU8>(std::move(inputs->image)));
  }
  bool refit_now = false;  // the selected pair's plane comes before the other pairs load
  {
    std::lock_guard lock(mutex_);
    PairView& pair = state_.pairs.Edit(index);
    pair.loaded = true;
    pair.cloud = std::move(cloud);
    pair.lidar_image = std::move(lidar_image);
    pair.thumbnail = std::move(thumbnail);
    ++state_.loading_done;
    Publish();
    OnLivePairLoaded(index);  // a followed capture: follow it, match it against the ghost
    if (!brush_dropped.empty()) {
      load_warnings_.push_back(brush_dropped);
      SetStatus(brush_dropped, true);
    }
    refit_now = ScheduleBoard(index);
    if (state_.loading_done == state_.loading_total) opened_pairs_loaded_ = true;
    if (PairsSettled()) OnAllPairsLoaded();
  }
  if (refit_now) RefitLidar(index);
}

bool Controller::ScheduleBoard(int index) {
  mutex_.AssertHeld(__func__);
  if (!state_.pairs.at(index).cloud) return false;  // it failed with the reason (the job's)
  // No target: nothing to detect (OnAllPairsLoaded says so).
  if (!state_.dataset->missing_target_file.empty()) return false;
  // Detection waits for every cloud: the background model over them keeps static board-sized
  // panels out (as CalibrateDataset does).
  if (state_.pairs.at(index).brush_origin == BrushOrigin::kDetected) {
    state_.pairs.Edit(index).awaiting_detection = true;
    Publish();
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
      const PairView& pair = state_.pairs.at(i);
      if (!pair.cloud) continue;
      clouds.emplace_back(static_cast<int>(i), pair.cloud);
      if (pair.brush_origin != BrushOrigin::kDetected) continue;
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
  std::optional<std::vector<int>> brush;  // the record's, to tell a newer stroke's refit
  bool seeded = false;
  std::string id;
  {
    std::lock_guard lock(mutex_);
    cloud = state_.pairs.at(index).cloud;
    image = state_.pairs.at(index).lidar_image;
    seeded = state_.pairs.at(index).brush_origin == BrushOrigin::kSeeded;
    id = state_.pairs.at(index).id;
    brush = job_->record().EditOf(id).brush_pixels;
  }
  if (!cloud || !image) return;
  // The same choice of region as `calibench calibrate` (the job's BoardHintFor): once painted
  // (or erased), the brush, which the edit put in the job's record before this refit was
  // queued; else the seed while the brush only pictures it ("detect again" forgot it); else
  // detection.
  job_->DetectLidar(index, *cloud, image.get(), seeded);
  std::lock_guard lock(mutex_);
  if (job_->record().EditOf(id).brush_pixels != brush) return;  // a newer stroke refits again
  state_.pairs.Edit(index).awaiting_detection = false;
  Publish();
  if (PairsSettled()) {
    AfterEdit();  // the statuses the job recorded, autosaved
    RequestSolve();
  }
}

}  // namespace calibench::ui
