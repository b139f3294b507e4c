// A rig in the workbench: the camera selector with the strip of the selected capture's frames (one
// per camera; a click opens that camera), the meter over every camera with the rig solve, and every
// camera's frustum in the 3D view.
#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "ui/lidar_camera/workbench.h"
#include "ui/lidar_camera/workbench_gl.h"

namespace calibench::ui {
namespace {

const ImVec4 kDone(0.45f, 0.85f, 0.45f, 1), kNotDone(1.0f, 0.55f, 0.35f, 1);
constexpr float kStripHeight = 54.0f;  // pixels

// Each camera's colour in the strip and the 3D view; the open camera is the view's orange.
gfx::Rgba RigCameraColor(int index, bool active) {
  static constexpr gfx::Rgba kColors[] = {
      {90, 200, 255, 255}, {220, 120, 255, 255}, {255, 230, 90, 255}, {120, 255, 170, 255}};
  return active ? gfx::Rgba{255, 150, 40, 255} : kColors[index % 4];
}

ImVec4 ToImVec4(const gfx::Rgba& c) { return {c.r / 255.0f, c.g / 255.0f, c.b / 255.0f, 1}; }

}  // namespace

void Workbench::RigStrip(const Snapshot& s, std::vector<Intent>* intents) {
  const RigView& rig = *s.rig;
  ImGui::TextUnformatted("camera");
  ImGui::SameLine();
  ImGui::SetNextItemWidth(140);
  ImGui::BeginDisabled(rig.solving);
  const std::string& open = rig.cameras[rig.active].name;
  if (ImGui::BeginCombo("##rig camera", open.c_str())) {
    for (const RigCameraView& camera : rig.cameras)
      if (ImGui::Selectable(camera.name.c_str(), camera.name == open) && camera.name != open)
        intents->push_back(SelectCamera{camera.name});
    ImGui::EndCombo();
  }
  ImGui::EndDisabled();
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
    ImGui::SetTooltip(rig.solving ? "the rig solves; the cameras can be switched once it is done"
                                  : "the camera in the views; each camera keeps its own session");
  ImGui::SameLine();
  ImGui::TextDisabled("one of %zu in %s; capture %s%s%s", rig.cameras.size(),
                      rig.path.filename().string().c_str(),
                      rig.frames_pair.empty() ? "-" : rig.frames_pair.c_str(),
                      rig.solving ? "; the rig solves: " : "", rig.progress.c_str());
  // The strip: every camera's frame of the selected capture, the open one framed.
  for (size_t c = 0; c < rig.cameras.size(); ++c) {
    const RigCameraView& camera = rig.cameras[c];
    const bool active = static_cast<int>(c) == rig.active;
    if (c > 0) ImGui::SameLine();
    ImGui::BeginGroup();
    ImGui::TextColored(ToImVec4(RigCameraColor(static_cast<int>(c), active)), "%s",
                       camera.name.c_str());
    if (camera.frame) {
      auto& texture = gl_->rig_frames[camera.name];
      if (!texture.texture || texture.source != camera.frame.get()) {
        if (!texture.texture) texture.texture = std::make_unique<gfx::ImageTexture>();
        texture.texture->Upload(*camera.frame, true);
        texture.source = camera.frame.get();
      }
      const float w = kStripHeight * camera.frame->width / std::max(1, camera.frame->height);
      ImGui::PushID(static_cast<int>(c));
      const bool clicked =
          ImGui::ImageButton(TextureId(texture.texture->texture()), ImVec2(w, kStripHeight),
                             ImVec2(0, 0), ImVec2(1, 1), active ? 3 : 1,
                             active ? ToImVec4(RigCameraColor(0, true)) : ImVec4(0, 0, 0, 0));
      ImGui::PopID();
      if (clicked && !active && !rig.solving) intents->push_back(SelectCamera{camera.name});
    } else {
      ImGui::Dummy(ImVec2(kStripHeight * 4 / 3, kStripHeight * 0.6f));
      ImGui::TextDisabled(rig.frames_pair.empty() ? "..." : "no frame");
    }
    ImGui::EndGroup();
  }
  ImGui::Separator();
}

void Workbench::RigMeterRows(const Snapshot& s, std::vector<Intent>* intents) {
  const RigView& rig = *s.rig;
  ImGui::Separator();
  if (rig.AllDone())
    ImGui::TextColored(kDone, "RIG DONE: every camera's sigma under the goal and trusted");
  else
    ImGui::TextColored(kNotDone, "rig not done");
  ImGui::SameLine();
  ImGui::BeginDisabled(rig.solving);
  if (ImGui::SmallButton(rig.solving ? "solving the rig..." : "Solve rig"))
    intents->push_back(SolveRig{});
  ImGui::EndDisabled();
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
    ImGui::SetTooltip(
        "every camera with the LiDAR in one problem (boards two cameras saw at once tie them), "
        "each camera with its session's edits, as `calibench calibrate --dataset <rig>`");
  if (ImGui::BeginTable(
          "rig cameras", 5,
          ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerH | ImGuiTableFlags_SizingFixedFit)) {
    for (const char* column :
         {"camera", "pairs", "own sigma t / r (worst)", "rig sigma t / r (worst)", "meter"})
      ImGui::TableSetupColumn(column);
    ImGui::TableHeadersRow();
    for (size_t c = 0; c < rig.cameras.size(); ++c) {
      const RigCameraView& camera = rig.cameras[c];
      const bool active = static_cast<int>(c) == rig.active;
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextColored(ToImVec4(RigCameraColor(static_cast<int>(c), active)), "%s%s",
                         camera.name.c_str(), active ? " (open)" : "");
      ImGui::TableNextColumn();
      ImGui::Text("%d / %d", camera.pairs_used, camera.captures);
      ImGui::TableNextColumn();
      if (camera.meter)
        ImGui::Text("%.2f mm / %.3f deg", camera.meter->sigma_t_mm.maxCoeff(),
                    camera.meter->sigma_r_deg.maxCoeff());
      else
        ImGui::TextDisabled("%s", !camera.failure.empty() ? camera.failure.c_str()
                                  : rig.solving           ? "solving..."
                                                          : "not solved");
      ImGui::TableNextColumn();
      if (camera.joint_cam_from_lidar)
        ImGui::Text("%.2f mm / %.3f deg", camera.joint_sigma_t_mm.maxCoeff(),
                    camera.joint_sigma_r_deg.maxCoeff());
      else
        ImGui::TextDisabled("-");
      ImGui::TableNextColumn();
      if (!camera.meter)
        ImGui::TextDisabled("-");
      else if (camera.meter->done)
        ImGui::TextColored(kDone, "done");
      else
        ImGui::TextColored(kNotDone, "not done: %s",
                           camera.meter->goal_met ? camera.meter->trust_note.c_str()
                                                  : camera.meter->weakest.c_str());
    }
    ImGui::EndTable();
  }
  for (const PoseWithSigmas& relative : rig.relative) {
    const Vec3 t = 1e3 * relative.pose.translation();
    ImGui::Text(
        "%s: t = [%.1f %.1f %.1f] mm, sigma t %.2f mm, r %.3f deg (worst axis; %d shared "
        "captures)",
        relative.name.c_str(), t.x(), t.y(), t.z(), relative.sigma_t_mm.maxCoeff(),
        relative.sigma_r_deg.maxCoeff(), rig.shared_captures);
  }
  if (!rig.failure.empty()) ImGui::TextColored(kNotDone, "rig: %s", rig.failure.c_str());
  if (rig.JointStale() && !rig.solving)
    ImGui::TextColored(kNotDone,
                       "a camera's own solve moved since the rig solve ran: Solve rig again");
}

void Workbench::DrawRigFrustums(const Snapshot& s, const Pose* estimate,
                                gfx::SceneLayers::Layer* layer) {
  const RigView& rig = *s.rig;
  for (size_t c = 0; c < rig.cameras.size(); ++c) {
    const RigCameraView& camera = rig.cameras[c];
    const bool active = static_cast<int>(c) == rig.active;
    // The open camera at the shown estimate (it moves as the solver iterates); the others at
    // the rig's joint solve, else their own.
    std::optional<Pose> cam_from_lidar;
    if (active && estimate)
      cam_from_lidar = *estimate;
    else if (camera.joint_cam_from_lidar)
      cam_from_lidar = camera.joint_cam_from_lidar;
    else if (camera.single)
      cam_from_lidar = camera.single->cam_from_lidar;
    if (!cam_from_lidar) continue;
    const Pose lidar_from_cam = cam_from_lidar->inverse();
    if (!active) layer->lines.AddAxes(lidar_from_cam, 0.15);
    AddCameraFrustum(camera.camera, lidar_from_cam, 0.35,
                     RigCameraColor(static_cast<int>(c), active), &layer->lines);
  }
}

void AddCameraFrustum(const CameraModel& camera, const Pose& lidar_from_cam, double depth_m,
                      const gfx::Rgba& color, gfx::LineBatch* lines) {
  // The image border's rays, a few per edge (a fisheye's border is not straight), each drawn to
  // depth_m along itself: a fisheye's rays past 90 degrees still close the rim.
  std::vector<Vec3> border;
  const double w = camera.width, h = camera.height;
  constexpr int kPerEdge = 6;
  for (int edge = 0; edge < 4; ++edge)
    for (int k = 0; k < kPerEdge; ++k) {
      const double f = static_cast<double>(k) / kPerEdge;
      const Vec2 pixel = edge == 0   ? Vec2(f * w, 0)
                         : edge == 1 ? Vec2(w, f * h)
                         : edge == 2 ? Vec2((1 - f) * w, h)
                                     : Vec2(0, (1 - f) * h);
      if (const auto ray = camera.Unproject(pixel)) border.push_back(depth_m * ray->normalized());
    }
  const Vec3 centre = lidar_from_cam.translation();
  for (size_t i = 0; i < border.size(); ++i) {
    lines->Add(lidar_from_cam * border[i], lidar_from_cam * border[(i + 1) % border.size()], color);
    if (i % kPerEdge == 0) lines->Add(centre, lidar_from_cam * border[i], color);
  }
}

}  // namespace calibench::ui
