#include "ui/lidar_camera/workbench.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/lidar_camera/result_io.h"
#include "ui/lidar_camera/workbench_gl.h"

namespace calibench::ui {

bool ParseLayout(const std::string& name, Layout* layout) {
  if (name == "workbench")
    *layout = Layout::kWorkbench;
  else if (name == "lidar")
    *layout = Layout::kLidarOnly;
  else if (name == "camera")
    *layout = Layout::kCameraOnly;
  else if (name == "3d")
    *layout = Layout::kSceneOnly;
  else
    return false;
  return true;
}

Workbench::Workbench() : gl_(std::make_unique<Gl>()) {}
Workbench::~Workbench() = default;

const Pose* Workbench::DisplayedEstimate(const Snapshot& s) const {
  const auto& iterations = s.solver.iterations;
  if (!iterations.empty()) {
    const int last = static_cast<int>(iterations.size()) - 1;
    const int index =
        replay_position_ < 0 ? last : std::min(last, static_cast<int>(replay_position_));
    return &iterations[index].cam_from_lidar;
  }
  return s.solver.result ? &s.solver.result->cam_from_lidar : nullptr;
}

std::vector<Intent> Workbench::Frame(const Snapshot& s, int width, int height, Layout layout,
                                     double seconds_since_last_frame) {
  std::vector<Intent> intents;
  if (replaying_ && !s.solver.iterations.empty()) {
    replay_position_ = std::max(0.0, replay_position_) + 2.0 * seconds_since_last_frame;  // 2 it/s
    if (replay_position_ >= static_cast<double>(s.solver.iterations.size()) - 1) {
      replay_position_ = -1;
      replaying_ = false;
    }
  }
  const float w = static_cast<float>(width), h = static_cast<float>(height);
  switch (layout) {
    case Layout::kLidarOnly:
      LidarView(s, {0, 0, w, h}, &intents);
      return intents;
    case Layout::kCameraOnly:
      CameraView(s, {0, 0, w, h}, &intents);
      return intents;
    case Layout::kSceneOnly:
      SceneView(s, {0, 0, w, h}, &intents);
      return intents;
    case Layout::kWorkbench:
      break;
  }
  const float status_h = ImGui::GetFrameHeightWithSpacing() + 8;
  const float top_h = std::floor((h - status_h) * 0.58f);
  const float third = std::floor(w / 3);
  LidarView(s, {0, 0, third, top_h}, &intents);
  CameraView(s, {third, 0, third, top_h}, &intents);
  SceneView(s, {2 * third, 0, w - 2 * third, top_h}, &intents);
  const float bottom_h = h - status_h - top_h;
  MeasurementsPanel(s, {0, top_h, std::floor(w * 0.45f), bottom_h}, &intents);
  SolverPanel(s, {std::floor(w * 0.45f), top_h, w - std::floor(w * 0.45f), bottom_h}, &intents);
  StatusLine(s, {0, h - status_h, w, status_h});
  HandleKeys(s, &intents);
  return intents;
}

// Dear ImGui 1.86 keys are the platform backend's codes; GLFW uses ASCII for letters and
// brackets, and the headless renderer maps the same codes.
namespace {
constexpr int kKeyF5 = 294;  // GLFW_KEY_F5
bool KeyPressed(int key) { return key >= 0 && ImGui::IsKeyPressed(key, false); }
bool NamedKeyPressed(ImGuiKey key) { return KeyPressed(ImGui::GetKeyIndex(key)); }
}  // namespace

void Workbench::HandleKeys(const Snapshot& s, std::vector<Intent>* intents) {
  if (ImGui::GetIO().WantTextInput || s.selected < 0) return;
  const int n = static_cast<int>(s.pairs.size());
  const bool ctrl = ImGui::GetIO().KeyCtrl;
  if (!ctrl && KeyPressed('A'))
    intents->push_back(SetPairStatus{s.selected, PairStatus::kAccepted});
  if (!ctrl && KeyPressed('R'))
    intents->push_back(SetPairStatus{s.selected, PairStatus::kRejected});
  if (NamedKeyPressed(ImGuiKey_DownArrow) || NamedKeyPressed(ImGuiKey_RightArrow))
    intents->push_back(SelectPair{std::min(n - 1, s.selected + 1)});
  if (NamedKeyPressed(ImGuiKey_UpArrow) || NamedKeyPressed(ImGuiKey_LeftArrow))
    intents->push_back(SelectPair{std::max(0, s.selected - 1)});
  if (NamedKeyPressed(ImGuiKey_Enter) || KeyPressed(kKeyF5)) intents->push_back(RunSolver{});
  if (ctrl && KeyPressed('Z')) intents->push_back(Undo{});
  if (ctrl && KeyPressed('Y')) intents->push_back(Redo{});
  ViewState view = s.view;
  if (KeyPressed('[')) view.brush_radius_px = std::max(1.0, view.brush_radius_px - 1);
  if (KeyPressed(']')) view.brush_radius_px = std::min(60.0, view.brush_radius_px + 1);
  if (view.brush_radius_px != s.view.brush_radius_px) intents->push_back(SetView{view});
}

void Workbench::StatusLine(const Snapshot& s, const ViewRect& r) {
  ImGui::SetNextWindowPos({r.x, r.y});
  ImGui::SetNextWindowSize({r.w, r.h});
  ImGui::Begin("##status", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                   ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoBringToFrontOnFocus);
  if (s.busy) {
    ImGui::TextColored({0.95f, 0.8f, 0.3f, 1}, "working");
    ImGui::SameLine();
  }
  if (s.status_is_error) {
    ImGui::TextColored({1.0f, 0.4f, 0.35f, 1}, "%s", s.status_line.c_str());
  } else {
    ImGui::TextUnformatted(s.status_line.c_str());
  }
  ImGui::SameLine(std::max(ImGui::GetCursorPosX() + 20, r.w - 420));
  ImGui::TextDisabled("session: %s", s.session_path.filename().string().c_str());
  ImGui::End();
}

}  // namespace calibench::ui
