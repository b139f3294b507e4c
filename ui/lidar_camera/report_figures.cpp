#include "ui/lidar_camera/report_figures.h"

#include <algorithm>
#include <deque>
#include <functional>
#include <future>

#include "core/io/image_io.h"
#include "ui/gfx/context.h"
#include "ui/lidar_camera/controller_outcome.h"
#include "ui/lidar_camera/workbench.h"
#include "ui/widgets/imgui_host.h"

namespace calibench::ui {
namespace {

// One picture of the workbench laid out as `layout`, drawn from the snapshot alone (its intents
// are dropped: nothing is there to apply them).
ImageU8 DrawView(ImGuiHost& host, Workbench& workbench, const Snapshot& snapshot, Layout layout,
                 int width, int height, int frames) {
  return RenderFramesHeadless(host, width, height, frames, [&] {
    workbench.Frame(snapshot, width, height, layout, 1.0 / 60.0);
  });
}

struct LoadedPair {
  std::optional<OutcomePair> pair;
  std::string why;
};

// Pair `index` ready to draw: a kept pair only reprojected, any other read from its files. The
// first is read again in full whatever is kept: the overview colours its cloud from the raw image.
LoadedPair ReadAhead(const Snapshot& solved, int index, const Undistorter& undistorter,
                     const KeptPairInputs* kept) {
  LoadedPair loaded;
  if (kept != nullptr && index > 0) loaded.pair = kept->Find(solved.pairs[index].id);
  if (loaded.pair)
    ReprojectOutcomePair(solved, index, &*loaded.pair);
  else
    loaded.pair = LoadOutcomePair(solved, index, &undistorter, &loaded.why);
  return loaded;
}

}  // namespace

double FigureViewScale(const CameraModel& camera, const ReportFigureOptions& options) {
  return std::min(1.0, 1.25 * options.pair_width / std::max(1, camera.width));
}

KeptPairInputs::KeptPairInputs(const CameraModel& camera, const ReportFigureOptions& options,
                               int max_pairs)
    : undistorter_(camera, 0, 0, FigureViewScale(camera, options)), max_pairs_(max_pairs) {}

std::function<void(const PairEntry&, const PairInputs&)> KeptPairInputs::Keeper() {
  return [this](const PairEntry& entry, const PairInputs& inputs) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (static_cast<int>(kept_.size()) >= max_pairs_) return;
    }
    OutcomePair pair;
    pair.cloud = std::make_shared<const LidarCloud>(inputs.cloud);
    pair.undistorted = std::make_shared<const UndistortedView>(undistorter_.Apply(inputs.image));
    std::lock_guard<std::mutex> lock(mutex_);
    if (static_cast<int>(kept_.size()) < max_pairs_) kept_[entry.id] = std::move(pair);
  };
}

std::optional<OutcomePair> KeptPairInputs::Find(const std::string& pair_id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = kept_.find(pair_id);
  if (it == kept_.end()) return std::nullopt;
  return it->second;
}

namespace {

// The overview and every pair's camera view of `solved` (a snapshot of an outcome).
std::vector<ReportFigure> DrawFigures(const Dataset& dataset, const Snapshot& solved,
                                      const std::string& overview_caption,
                                      const ReportFigureOptions& options,
                                      const KeptPairInputs* kept, std::string* why) {
  std::string no_context;
  const auto context = gfx::CreateHeadlessContext(gfx::HeadlessBackend::kAuto, &no_context);
  if (!context) {
    *why = "no headless OpenGL to draw the views (" + no_context + ")";
    return {};
  }
  // The undistorted image at about the size the picture shows it: the remapping and the texture a
  // fraction of the full image's. The kept pairs' undistorter when there is one.
  std::optional<Undistorter> own;
  if (kept == nullptr) own.emplace(dataset.camera, 0, 0, FigureViewScale(dataset.camera, options));
  const Undistorter& undistorter = kept != nullptr ? kept->undistorter() : *own;
  const int count = static_cast<int>(solved.pairs.size());
  // Pairs are read and reprojected on `threads` workers, ahead of the drawing (GL: this thread).
  std::deque<std::future<LoadedPair>> ahead;
  int next = 0;
  auto launch = [&] {
    if (next >= count) return;
    ahead.push_back(std::async(std::launch::async, ReadAhead, std::cref(solved), next,
                               std::cref(undistorter), kept));
    ++next;
  };
  for (int k = 0; k < std::max(1, options.threads); ++k) launch();
  ImGuiHost host(nullptr);
  // One workbench draws every pair (its GL programs built once). Its caches are keyed by the
  // buffers' addresses: the pair drawn before stays alive until the next is drawn, so that no new
  // buffer can take its address.
  Workbench pair_workbench;
  Snapshot previous;
  std::vector<ReportFigure> figures;
  std::vector<std::string> unreadable;
  for (int index = 0; index < count; ++index) {
    LoadedPair loaded = ahead.front().get();
    ahead.pop_front();
    launch();
    if (!loaded.pair) {
      unreadable.push_back(loaded.why);
      continue;
    }
    Snapshot shown = solved;
    shown.generation = solved.generation + 1 + index;
    ShowOutcomePair(&shown, index, *loaded.pair);
    // The overview shows the first readable pair's cloud with every board, as the workbench
    // opens on it.
    if (figures.empty()) {
      Workbench overview;
      figures.push_back(
          {overview_caption, "",
           EncodeImage(DrawView(host, overview, shown, Layout::kSceneOnly, options.overview_width,
                                options.overview_height, options.frames + 1),
                       ".png"),
           "image/png"});
    }
    figures.push_back(
        {"pair " + shown.pairs[index].id + ": the LiDAR points coloured over the image",
         shown.pairs[index].id,
         EncodeImage(DrawView(host, pair_workbench, shown, Layout::kCameraOnly, options.pair_width,
                              options.pair_height, options.frames),
                     ".jpg"),
         "image/jpeg"});
    previous = std::move(shown);
  }
  if (!unreadable.empty()) {
    *why = std::to_string(unreadable.size()) + " pair(s) without a view: " + unreadable.front();
  }
  return figures;
}

}  // namespace

std::vector<ReportFigure> DrawReportFigures(const Dataset& dataset,
                                            const CalibrationOutcome& outcome,
                                            const ReportFigureOptions& options,
                                            const KeptPairInputs* kept, std::string* why) {
  return DrawFigures(dataset, SnapshotOfOutcome(dataset, outcome),
                     "3D overview: the LiDAR cloud, the boards and the camera", options, kept, why);
}

std::vector<ReportFigure> DrawReportFigures(const RigFolder& rig, const RigOutcome& outcome,
                                            size_t camera, const ReportFigureOptions& options,
                                            const KeptPairInputs* kept, std::string* why) {
  CALIBENCH_CHECK(camera < rig.cameras.size() && camera < outcome.single.size());
  const Dataset& dataset = rig.cameras[camera];
  if (!outcome.Several())
    return DrawReportFigures(dataset, outcome.single[camera], options, kept, why);
  Snapshot solved = SnapshotOfOutcome(dataset, outcome.single[camera]);
  solved.rig = RigViewOf(rig, camera);
  ApplyRigOutcome(outcome, false, &*solved.rig);
  return DrawFigures(dataset, solved,
                     "3D overview: the LiDAR cloud, the boards and the rig's cameras (" +
                         rig.camera_names[camera] + " in orange)",
                     options, kept, why);
}

}  // namespace calibench::ui
