// The pairs' loading, a task of the controller: each pair read by the job on the worker, the
// board's detection with the scene's background, refits after a brush edit, a followed capture's
// pairs as they land (ui/lidar_camera/loading_task.h).
#include "ui/lidar_camera/loading_task.h"

#include <algorithm>

#include "core/base/allocator.h"
#include "core/io/image_io.h"

namespace calibench::ui {
namespace {

constexpr int kThumbnailWidth = 160;  // pixels

}  // namespace

void LoadingTask::Start(const std::string& note) {
  host_.mutex.AssertHeld(__func__);
  const Dataset& dataset = *host_.state.dataset;
  host_.state.loading_total = static_cast<int>(dataset.pairs.size());
  load_warnings_.clear();
  opened_pairs_loaded_ = dataset.pairs.empty();
  follow_newest_ = true;
  open_note_ = note;
  if (!dataset.missing_target_file.empty())
    open_note_ += (note.empty() ? "" : "; ") + std::string("no ") +
                  dataset.missing_target_file.string() +
                  ": no board to find in these pairs (the targetless check needs none: "
                  "Targetless check... in the solver panel)";
  host_.SetStatus("loading " + std::to_string(dataset.pairs.size()) + " pairs from " +
                      dataset.manifest.string(),
                  false);
  // The selected pair and its image first, so that it is on screen while the others load.
  const int first = std::max(0, host_.state.selected);
  const int count = static_cast<int>(dataset.pairs.size());
  if (count == 0) return;
  host_.worker.Enqueue([this, first] { Load(first); });
  controls_.show_image();
  for (int i = 0; i < count; ++i)
    if (i != first) host_.worker.Enqueue([this, i] { Load(i); });
}

void LoadingTask::OnAllLoaded() {
  host_.mutex.AssertHeld(__func__);
  if (host_.state.dataset->missing_target_file.empty()) {
    host_.worker.Enqueue([this] { DetectWithBackground(); });
  } else {
    // No board to find (a drive opened for the targetless check): no detection (the job said
    // so per pair).
    for (PairView& pair : host_.state.pairs.Edit()) pair.awaiting_detection = false;
    controls_.publish();
  }
  // What went wrong while loading stays on the status line (in the warning colour).
  std::string loaded_line = "loaded " + std::to_string(host_.state.loading_total) + " pairs";
  if (!open_note_.empty()) loaded_line += "; " + open_note_;
  for (const std::string& warning : load_warnings_) loaded_line += "; " + warning;
  host_.SetStatus(loaded_line, !load_warnings_.empty());
  load_warnings_.clear();
  // A reopened session with a result shows its reprojection, its meter and (once its boards are
  // found again) its next pose again.
  if (host_.state.solver.result && !host_.state.meter) {
    guidance_.Judge(/*record=*/true);
    host_.worker.Enqueue([this] { guidance_.AdviseFromState(); });
  }
  if (host_.state.solver.result) controls_.reproject(host_.state.selected);
}

bool LoadingTask::FollowsTo(int index) const {
  host_.mutex.AssertHeld(__func__);
  return !host_.state.watching.empty() && follow_newest_ && index > host_.state.selected &&
         index + 1 == static_cast<int>(host_.state.pairs.size());
}

bool LoadingTask::Settled() const {
  host_.mutex.AssertHeld(__func__);
  // A followed capture is never all loaded (the next pair may land while this one is read):
  // once the pairs it opened with are in, each new pair counts as soon as it is.
  return host_.state.loading_done == host_.state.loading_total ||
         (opened_pairs_loaded_ && !host_.state.watching.empty());
}

void LoadingTask::Load(int index) {
  Dataset dataset;
  {
    std::lock_guard lock(host_.mutex);
    dataset = *host_.state.dataset;
  }
  const PairEntry& entry = dataset.pairs[index];
  CalibrationJob* job = controls_.job();
  // The job knows the pairs in the order they load (a followed capture's arrive one by one).
  while (job->size() <= index) job->AppendPair(dataset.pairs[job->size()]);
  // The job reads the pair and finds the board in its image, as for `calibench calibrate`; the
  // view keeps the decoded files.
  std::shared_ptr<const LidarCloud> cloud;
  std::shared_ptr<const LidarImage> lidar_image;
  std::shared_ptr<const ImageU8> thumbnail;  // small BGR picture of the camera image
  std::string why;
  std::string brush_dropped;  // why the session's brush does not fit this pair's cloud
  CameraFeatures camera;      // the job keeps its corners (PairRecord::detection)
  auto inputs = job->ReadPair(index, &camera, &why);
  bool selected = false;
  {
    std::lock_guard lock(host_.mutex);
    selected = index == host_.state.selected || FollowsTo(index);
  }
  if (inputs) {
    cloud = std::make_shared<const LidarCloud>(std::move(inputs->cloud));
    lidar_image = std::make_shared<const LidarImage>(ProjectById(*cloud, LidarImageOptions{}));
    thumbnail = std::make_shared<const ImageU8>(ResizeImage(inputs->image, kThumbnailWidth));
    // The seed's region and the detected board are drawn on the LiDAR image (the job's).
    brush_dropped = job->PictureOn(index, *cloud, lidar_image);
    // The camera view shows the selected pair's image: decoded once, here.
    if (selected)
      controls_.keep_image(entry.image, std::make_shared<const ImageU8>(std::move(inputs->image)));
  }
  bool refit_now = false;  // the selected pair's plane comes before the other pairs load
  {
    std::lock_guard lock(host_.mutex);
    PairView& pair = host_.state.pairs.Edit(index);
    pair.loaded = true;
    pair.cloud = std::move(cloud);
    pair.lidar_image = std::move(lidar_image);
    pair.thumbnail = std::move(thumbnail);
    ++host_.state.loading_done;
    controls_.publish();
    OnLiveLoaded(index);  // a followed capture: follow it, match it against the ghost
    if (!brush_dropped.empty()) {
      load_warnings_.push_back(brush_dropped);
      host_.SetStatus(brush_dropped, true);
    }
    refit_now = ScheduleBoard(index);
    if (host_.state.loading_done == host_.state.loading_total) opened_pairs_loaded_ = true;
    if (Settled()) OnAllLoaded();
  }
  if (refit_now) Refit(index);
}

bool LoadingTask::ScheduleBoard(int index) {
  host_.mutex.AssertHeld(__func__);
  if (!host_.state.pairs.at(index).cloud) return false;  // it failed with the reason (the job's)
  // No target: nothing to detect (OnAllPairsLoaded says so).
  if (!host_.state.dataset->missing_target_file.empty()) return false;
  // Detection waits for every cloud: the background model over them keeps static board-sized
  // panels out (as CalibrateDataset does).
  if (host_.state.pairs.at(index).brush_origin == BrushOrigin::kDetected) {
    host_.state.pairs.Edit(index).awaiting_detection = true;
    controls_.publish();
    return false;
  }
  // A brush or seed: the selected pair's plane comes before the other pairs load.
  if (index == host_.state.selected && host_.state.loading_done < host_.state.loading_total)
    return true;
  host_.worker.Enqueue([this, index] { Refit(index); });
  return false;
}

void LoadingTask::DetectWithBackground() {
  std::vector<std::pair<int, std::shared_ptr<const LidarCloud>>> clouds;  // by pair index
  std::vector<int> awaiting, detected_before;                             // pairs left to detection
  {
    std::lock_guard lock(host_.mutex);
    for (size_t i = 0; i < host_.state.pairs.size(); ++i) {
      const PairView& pair = host_.state.pairs.at(i);
      if (!pair.cloud) continue;
      clouds.emplace_back(static_cast<int>(i), pair.cloud);
      if (pair.brush_origin != BrushOrigin::kDetected) continue;
      (pair.awaiting_detection ? awaiting : detected_before).push_back(static_cast<int>(i));
    }
  }
  if (awaiting.empty()) return;
  CalibrationJob* job = controls_.job();
  // The job's background over the clouds in pair order (as `calibrate`'s over the dataset's); a
  // capture that grows adds each new cloud until the model has enough.
  bool became_usable = false;
  const int before = job->background_clouds();
  for (const auto& [index, cloud] : clouds) became_usable |= job->AddToBackground(index, *cloud);
  if (job->background_clouds() > before && !job->background_usable() &&
      job->background_clouds() >= 3) {
    std::lock_guard lock(host_.mutex);
    host_.SetStatus("board detection without a background model: " + job->background_note(), false);
  }
  std::vector<int> detect = awaiting;
  // The model exists only now: the boards found without it are looked for again with it.
  if (became_usable) {
    detect.insert(detect.end(), detected_before.begin(), detected_before.end());
    std::sort(detect.begin(), detect.end());
  }
  for (int index : detect) Refit(index);
  // Loading is over: what its transient buffers took goes back (core/base/allocator.h).
  ReleaseFreedMemory();
}

void LoadingTask::Refit(int index) {
  std::shared_ptr<const LidarCloud> cloud;
  std::shared_ptr<const LidarImage> image;
  std::optional<std::vector<int>> brush;  // the record's, to tell a newer stroke's refit
  bool seeded = false;
  std::string id;
  CalibrationJob* job = controls_.job();
  {
    std::lock_guard lock(host_.mutex);
    cloud = host_.state.pairs.at(index).cloud;
    image = host_.state.pairs.at(index).lidar_image;
    seeded = host_.state.pairs.at(index).brush_origin == BrushOrigin::kSeeded;
    id = host_.state.pairs.at(index).id;
    brush = job->record().EditOf(id).brush_pixels;
  }
  if (!cloud || !image) return;
  // The same choice of region as `calibench calibrate` (the job's BoardHintFor): once painted
  // (or erased), the brush, which the edit put in the job's record before this refit was
  // queued; else the seed while the brush only pictures it ("detect again" forgot it); else
  // detection.
  job->DetectLidar(index, *cloud, image.get(), seeded);
  std::lock_guard lock(host_.mutex);
  if (job->record().EditOf(id).brush_pixels != brush) return;  // a newer stroke refits again
  host_.state.pairs.Edit(index).awaiting_detection = false;
  controls_.publish();
  if (Settled()) {
    controls_.settled();  // the statuses the job recorded, autosaved; the solve
  }
}

void LoadingTask::OnLiveLoaded(int index) {
  host_.mutex.AssertHeld(__func__);
  const PairView& pair = host_.state.pairs.at(index);
  // The views move to the newest pair once it is loaded (not before: they would show nothing
  // meanwhile), unless the user looks at an older one.
  if (FollowsTo(index)) {
    host_.state.selected = index;
    host_.state.reprojection.reset();  // the last image stays up until this one's is decoded
    controls_.show_image();
    controls_.reproject(index);
  }
  // The newest pair against the ghost board that was shown while it was taken.
  if (pair.camera && host_.state.next_pose && !host_.state.watching.empty()) {
    const SuggestionMatch match =
        MatchSuggestion(pair.camera->cam_from_board, *host_.state.next_pose, GuidanceOptions{});
    host_.state.ghost_match = "pair " + pair.id + " " + match.words;
    host_.state.ghost_matched = match.matches;
  }
}

void LoadingTask::Add(const PairEntry& entry) {
  host_.mutex.AssertHeld(__func__);
  if (!host_.state.dataset) return;
  for (const PairView& pair : host_.state.pairs)
    if (pair.id == entry.id) return;
  host_.state.dataset->pairs.push_back(entry);
  PairView view;
  view.id = entry.id;
  host_.state.pairs.Edit().push_back(std::move(view));
  if (CalibrationJob* job = controls_.job()) job->record().AddPair(entry.id);
  ++host_.state.loading_total;
  const int index = static_cast<int>(host_.state.pairs.size()) - 1;
  ++host_.state.generation;
  host_.worker.Enqueue([this, index] { Load(index); });  // selects it when it follows (FollowsTo)
}

}  // namespace calibench::ui
