#include "ui/lidar_camera/workbench.h"

#include <imgui.h>

#include <algorithm>

#include "ui/lidar_camera/workbench_gl.h"
#include "ui/widgets/pair_review.h"
#include "ui/widgets/workbench_layout.h"

namespace calibench::ui {

bool ParseLayout(const std::string& name, Layout* layout) {
  static_assert(static_cast<int>(Layout::kGuide) == kGuideLayout);
  return ParseLayoutName(name, {"workbench", "lidar", "camera", "3d", "guide"}, layout);
}

Workbench::Workbench()
    : WorkbenchFrame(LoadLayoutShares("lidar_camera", {0.58f, 0.45f})),
      gl_(std::make_unique<Gl>()) {}

Workbench::~Workbench() = default;

void Workbench::View(int index, const Snapshot& s, const Rect& r, std::vector<Intent>* intents) {
  if (index == 0) LidarView(s, r, intents);
  if (index == 1) CameraView(s, r, intents);
  if (index == 2) SceneView(s, r, intents);
}

std::string Workbench::Opened(const Snapshot& s) const {
  return "session: " + s.session_path.filename().string();
}

const Pose* Workbench::DisplayedEstimate(const Snapshot& s) const {
  return replay().ShownEstimate(s.solver.iterations,
                                s.solver.result ? &s.solver.result->cam_from_lidar : nullptr);
}

void Workbench::HandleKeys(const Snapshot& s, std::vector<Intent>* intents) {
  if (ImGui::GetIO().WantTextInput || s.selected < 0) return;
  const int n = static_cast<int>(s.pairs.size());
  const ReviewKeys keys = ReadReviewKeys();
  if (keys.accept) intents->push_back(SetPairStatus{s.selected, PairStatus::kAccepted});
  if (keys.reject) intents->push_back(SetPairStatus{s.selected, PairStatus::kRejected});
  if (keys.next) intents->push_back(SelectPair{std::min(n - 1, s.selected + 1)});
  if (keys.previous) intents->push_back(SelectPair{std::max(0, s.selected - 1)});
  if (keys.run) intents->push_back(RunSolver{});
  const bool ctrl = ImGui::GetIO().KeyCtrl;
  if (ctrl && KeyPressed('Z')) intents->push_back(Undo{});
  if (ctrl && KeyPressed('Y')) intents->push_back(Redo{});
  if (!ctrl && KeyPressed('F')) intents->push_back(FrameView{});
  ViewState view = s.view;
  if (KeyPressed('[')) view.brush_radius_px = std::max(1.0, view.brush_radius_px - 1);
  if (KeyPressed(']')) view.brush_radius_px = std::min(60.0, view.brush_radius_px + 1);
  if (view.brush_radius_px != s.view.brush_radius_px) intents->push_back(SetView{view});
}

}  // namespace calibench::ui
