#include "ui/lidar_camera/report_figures.h"

#include <algorithm>
#include <deque>
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

}  // namespace

std::vector<ReportFigure> DrawReportFigures(const Dataset& dataset,
                                            const CalibrationOutcome& outcome,
                                            const ReportFigureOptions& options, std::string* why) {
  std::string no_context;
  const auto context = gfx::CreateHeadlessContext(gfx::HeadlessBackend::kAuto, &no_context);
  if (!context) {
    *why = "no headless OpenGL to draw the views (" + no_context + ")";
    return {};
  }
  const Snapshot solved = SnapshotOfOutcome(dataset, outcome);
  // The undistorted image at about the size the picture shows it (a little over, for bilinear
  // sampling): the remapping and the texture a fraction of the full image's.
  const double view_scale =
      std::min(1.0, 1.25 * options.pair_width / std::max(1, dataset.camera.width));
  const Undistorter undistorter(dataset.camera, 0, 0, view_scale);
  const int count = static_cast<int>(solved.pairs.size());
  // Pairs are read and reprojected on `threads` workers, ahead of the drawing (GL: this thread).
  std::deque<std::future<LoadedPair>> ahead;
  int next = 0;
  auto launch = [&] {
    if (next >= count) return;
    ahead.push_back(std::async(std::launch::async, [&solved, &undistorter, index = next] {
      LoadedPair loaded;
      loaded.pair = LoadOutcomePair(solved, index, &undistorter, &loaded.why);
      return loaded;
    }));
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
          {"3D overview: the LiDAR cloud, the boards and the camera", "",
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

}  // namespace calibench::ui
