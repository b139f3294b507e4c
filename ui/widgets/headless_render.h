// What `calibench render` shows: a workbench drawn without a window (EGL surfaceless or
// OSMesa) after selecting a pair and solving. The frames go into an offscreen framebuffer exactly
// as the window's do (RenderWorkbenchHeadless, window_loop.h), so the picture is what the window
// would show.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "core/base/image.h"
#include "ui/widgets/imgui_host.h"

namespace calibench::ui {

// The index of the pair called `id` in a snapshot's pairs (either method's); -1 if none is.
template <typename Snapshot>
int FindPair(const Snapshot& snapshot, const std::string& id) {
  for (size_t i = 0; i < snapshot.pairs.size(); ++i)
    if (snapshot.pairs[i].id == id) return static_cast<int>(i);
  return -1;
}

// What a headless render shows: which pair (empty: the controller's selection), after a solve or
// not, at what size (pixels).
struct HeadlessShot {
  std::string pair_id;
  bool solve = false;
  int width = 1600, height = 900;
};

// Waits for the controller's work, selects the shot's pair and solves when asked (SelectPair and
// RunSolver: the method's intents), waits again and draws a fresh workbench in `layout`, a few
// frames (ImGui sizes tables and windows on the first ones). nullopt when no pair has the id.
// `prepare` (optional) sets the fresh workbench's view-local state before it draws.
template <typename Workbench, typename SelectPair, typename RunSolver, typename Controller,
          typename Layout>
std::optional<ImageU8> RenderShot(Controller& controller, Layout layout, const HeadlessShot& shot,
                                  const std::function<void(Workbench&)>& prepare = {}) {
  controller.WaitIdle();
  if (!shot.pair_id.empty()) {
    const int index = FindPair(controller.GetSnapshot(), shot.pair_id);
    if (index < 0) return std::nullopt;
    controller.Apply(SelectPair{index});
  }
  if (shot.solve) controller.Apply(RunSolver{});
  controller.WaitIdle();
  ImGuiHost host(nullptr);
  Workbench workbench;
  if (prepare) prepare(workbench);
  return RenderWorkbenchHeadless(controller, workbench, host, layout, shot.width, shot.height,
                                 /*frames=*/4);
}

}  // namespace calibench::ui
