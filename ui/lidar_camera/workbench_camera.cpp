// The camera view of the workbench: the camera frame (raw or undistorted) with the detected
// corners, the board's outline and axes, and after a solve the LiDAR points projected into it.
#include <imgui.h>

#include <algorithm>
#include <cmath>

#include "core/lidar/colormap.h"
#include "ui/lidar_camera/ghost.h"
#include "ui/lidar_camera/workbench.h"
#include "ui/lidar_camera/workbench_gl.h"
#include "ui/widgets/toolbar.h"

namespace calibench::ui {
namespace {

// What the camera framebuffer depends on.
std::uint64_t CameraTargetKey(const CameraShown& shown, const Reprojection* points,
                              const ViewState& view, std::uint64_t zoom_key) {
  return reinterpret_cast<std::uintptr_t>(shown.image) ^
         (points ? reinterpret_cast<std::uintptr_t>(points) << 1 : 0) ^
         (static_cast<std::uint64_t>(shown.at.size.x) << 48) ^
         (static_cast<std::uint64_t>(shown.at.size.y) << 36) ^
         static_cast<std::uint64_t>(view.point_size_px * 1000) * 7919 ^
         static_cast<std::uint64_t>(view.point_opacity * 1000) * 104729 ^ zoom_key;
}

// The visible LiDAR points of the reprojection at the solution, coloured by depth, into `points`.
void UploadReprojection(const Snapshot& s, const PairView& pair, const CameraShown& shown,
                        ShownReprojection* shown_points, gfx::PointRenderer* renderer) {
  ShownReprojection& cache = *shown_points;
  if (cache.source != s.reprojection || cache.undistorted != shown.undistorted) {
    cache.source = s.reprojection;
    cache.undistorted = shown.undistorted;
    cache.pixels.clear();
    cache.colors.clear();
    const Reprojection& rp = *s.reprojection;
    const Pose& cam_from_lidar = s.solver.result->cam_from_lidar;
    for (size_t i = 0; i < rp.points.size(); ++i) {
      if (!rp.visible.empty() && !rp.visible[i]) continue;
      std::optional<Vec2> px = rp.points[i].pixel;
      if (shown.undistorted)
        px = shown.model->Project(cam_from_lidar *
                                  pair.cloud->points[rp.points[i].index].cast<double>());
      if (!px) continue;
      cache.pixels.push_back(*px);
      cache.colors.push_back(ToRgba(MapColor(Colormap::kTurbo, rp.points[i].depth_m / 20.0)));
    }
  }
  std::vector<Eigen::Vector3f> positions;
  positions.reserve(cache.pixels.size());
  for (const Vec2& px : cache.pixels) positions.push_back(shown.at.ToNdc(px));
  renderer->Upload(positions, cache.colors);
}

// The sheet's outline (SheetOutlinePixels) on the screen.
std::vector<ImVec2> ScreenOutline(const BoardSpec& board, const Pose& cam_from_board,
                                  const CameraShown& shown) {
  std::vector<ImVec2> outline;
  for (const Vec2& px : SheetOutlinePixels(*shown.model, board, cam_from_board))
    outline.push_back(shown.at.ToScreen(px));
  return outline;
}

// The sheet's outline and the board's axes.
void DrawBoard(ImDrawList* draw, const BoardSpec& board, const Pose& cam_from_board,
               const CameraShown& shown) {
  const std::vector<ImVec2> outline = ScreenOutline(board, cam_from_board, shown);
  if (outline.size() > 2)
    draw->AddPolyline(outline.data(), static_cast<int>(outline.size()), IM_COL32(80, 200, 255, 255),
                      ImDrawFlags_Closed, 2.0f);
  const double axis = 0.25 * std::min(board.SheetWidth(), board.SheetHeight());
  const auto o = shown.model->Project(cam_from_board * Vec3::Zero());
  const ImU32 axis_colors[3] = {IM_COL32(255, 60, 60, 255), IM_COL32(60, 255, 60, 255),
                                IM_COL32(80, 120, 255, 255)};
  for (int a = 0; a < 3 && o; ++a) {
    const Vec3 tip = cam_from_board * (Vec3::Unit(a) * (a == 2 ? -axis : axis));
    if (const auto px = shown.model->Project(tip))
      draw->AddLine(shown.at.ToScreen(*o), shown.at.ToScreen(*px), axis_colors[a], 2.0f);
  }
}

// The ghost board: where `advise` says to hold the board next, a translucent sheet with a dashed
// look (its outline drawn twice) and a label.
void DrawGhost(ImDrawList* draw, const Snapshot& s, const CameraShown& shown) {
  if (!s.next_pose || !s.solver.result) return;
  const std::vector<ImVec2> outline =
      ScreenOutline(s.dataset->target, s.next_pose->cam_from_board, shown);
  if (outline.size() < 3) return;
  const ImU32 fill = IM_COL32(120, 255, 140, 70), edge = IM_COL32(120, 255, 140, 230);
  draw->AddConvexPolyFilled(outline.data(), static_cast<int>(outline.size()), fill);
  draw->AddPolyline(outline.data(), static_cast<int>(outline.size()), edge, ImDrawFlags_Closed,
                    2.5f);
  // The label above the ghost's top, kept inside the view.
  ImVec2 top = outline.front();
  for (const ImVec2& p : outline)
    if (p.y < top.y) top = p;
  // What it says, and how precisely it matters ("keep the tilt within 5° of it") on a second
  // line: each kept inside the view (a line wider than the view starts at its left edge).
  const std::string lines[] = {"next pose: hold the board here", s.next_pose->tolerance.words};
  float y = top.y - 4;
  for (int k = 1; k >= 0; --k) {
    if (lines[k].empty()) continue;
    const ImVec2 size = ImGui::CalcTextSize(lines[k].c_str());
    y -= size.y;
    const float right = shown.at.origin.x + shown.at.size.x - size.x - 4;
    const float x = std::max(shown.at.origin.x + 4, std::min(top.x - size.x / 2, right));
    draw->AddText(ImVec2(x, std::max(y, shown.at.origin.y + 4 + k * size.y)), edge,
                  lines[k].c_str());
  }
}

// Over the picture: the detected corners, the board or why there is none.
void DrawCameraOverlays(const Snapshot& s, const PairView& pair, const CameraShown& shown) {
  const ImVec2 origin = shown.at.origin;
  ImDrawList* draw = ImGui::GetWindowDrawList();
  draw->PushClipRect(origin, ImVec2(origin.x + shown.at.size.x, origin.y + shown.at.size.y), true);
  if (pair.detection)
    for (const Vec2& corner : pair.detection->pixels)
      if (const auto px = shown.FromRaw(corner))
        draw->AddCircle(shown.at.ToScreen(*px), 3.0f, IM_COL32(255, 220, 0, 255));
  if (pair.camera)
    DrawBoard(draw, s.dataset->target, pair.camera->cam_from_board, shown);
  else
    draw->AddText(ImVec2(origin.x + 12, origin.y + 12), IM_COL32(255, 90, 80, 255),
                  ("board not found: " + pair.camera_failure).c_str());
  DrawGhost(draw, s, shown);
  draw->PopClipRect();
}

}  // namespace

void Workbench::CameraView(const Snapshot& s, const Rect& r, std::vector<Intent>* intents) {
  if (!BeginView("Camera", r)) return ImGui::End();
  const PairView* pair = s.selected >= 0 ? &s.pairs[s.selected] : nullptr;
  // The undistorted view alone is enough to show it (a report's figure holds only that).
  const bool undistorted =
      s.view.camera_image == CameraImageMode::kUndistorted && s.selected_undistorted;
  if (!pair || (!s.selected_image && !undistorted) || !s.dataset) {
    ImGui::TextDisabled(s.dataset ? "loading image ..." : "no dataset open");
    return ImGui::End();
  }
  const ViewState view = CameraToolbar(s, *pair, intents);
  CameraShown shown;
  shown.undistorted = undistorted;
  shown.image = shown.undistorted ? &s.selected_undistorted->image : s.selected_image.get();
  shown.lens = &s.dataset->camera;
  shown.model = shown.undistorted ? &s.selected_undistorted->pinhole : shown.lens;
  shown.at = camera_image_.Place(shown.image->width, shown.image->height);
  DrawCameraTarget(s, *pair, shown, view);
  FramebufferImage(gl_->camera_target, shown.at.size);
  const bool hovered = ImGui::IsItemHovered();
  if (s.selected_image_pair == pair->id)
    DrawCameraOverlays(s, *pair, shown);
  else  // the previous pair's picture while this one's is decoded
    ImGui::GetWindowDrawList()->AddText(ImVec2(shown.at.origin.x + 12, shown.at.origin.y + 12),
                                        IM_COL32(230, 230, 230, 255),
                                        ("loading " + pair->id + " ...").c_str());
  if (hovered) {
    camera_image_.HandleMouse(shown.at);
    if (!s.solver.result)
      ImGui::SetTooltip("run the solver to project the LiDAR points into this image");
  }
  ImGui::End();
}

// Image mode, visibility, point size and opacity (HPR radius); the board found in the image.
ViewState Workbench::CameraToolbar(const Snapshot& s, const PairView& pair,
                                   std::vector<Intent>* intents) {
  ViewState view = s.view;
  static const char* kModes[] = {"raw", "undistorted"};
  int mode = static_cast<int>(view.camera_image);
  ImGui::SetNextItemWidth(110);
  if (ImGui::Combo("##mode", &mode, kModes, 2))
    view.camera_image = static_cast<CameraImageMode>(mode);
  static const char* kVisibility[] = {"hidden-point removal", "z-buffer", "no occlusion"};
  int visibility = static_cast<int>(view.visibility);
  SameLineIfFits(ToolbarItemWidth("##visibility", 150));
  ImGui::SetNextItemWidth(150);
  if (ImGui::Combo("##visibility", &visibility, kVisibility, 3))
    view.visibility = static_cast<VisibilityMode>(visibility);
  SameLineIfFits(ToolbarItemWidth("size", 70));
  ImGui::SetNextItemWidth(70);
  float size = static_cast<float>(view.point_size_px),
        opacity = static_cast<float>(view.point_opacity);
  // AlwaysClamp: a Ctrl+click typed value stays in range too.
  if (ImGui::SliderFloat("size", &size, 1.0f, 8.0f, "%.1f", ImGuiSliderFlags_AlwaysClamp))
    view.point_size_px = size;
  SameLineIfFits(ToolbarItemWidth("opacity", 70));
  ImGui::SetNextItemWidth(70);
  if (ImGui::SliderFloat("opacity", &opacity, 0.1f, 1.0f, "%.2f", ImGuiSliderFlags_AlwaysClamp))
    view.point_opacity = opacity;
  if (view.visibility == VisibilityMode::kHpr) {
    SameLineIfFits(ToolbarItemWidth("HPR 10^", 70));
    ImGui::SetNextItemWidth(70);
    float exponent = static_cast<float>(view.hpr_radius_exponent);
    if (ImGui::SliderFloat("HPR 10^", &exponent, 1.0f, 4.0f, "%.1f", ImGuiSliderFlags_AlwaysClamp))
      view.hpr_radius_exponent = exponent;
  }
  if (!(view == s.view)) intents->push_back(SetView{view});
  if (pair.camera) {
    ImGui::Text("board: %d corners, reprojection RMS %.2f px, %.2f m away",
                pair.camera->num_corners, pair.camera->reprojection_rms_px,
                pair.camera->plane.distance);
  } else {
    ImGui::TextColored({1.0f, 0.5f, 0.4f, 1}, "board not found: %s", pair.camera_failure.c_str());
  }
  return view;
}

void Workbench::DrawCameraTarget(const Snapshot& s, const PairView& pair, const CameraShown& shown,
                                 const ViewState& view) {
  const bool show_points = s.reprojection && s.reprojection->pair_id == pair.id &&
                           s.solver.result && s.selected_image_pair == pair.id;
  const std::uint64_t key = CameraTargetKey(shown, show_points ? s.reprojection.get() : nullptr,
                                            view, camera_image_.Key());
  if (key == camera_key_) return;
  camera_key_ = key;
  if (gl_->camera_image_source != shown.image) {
    gl_->camera_image.Upload(*shown.image, true);
    gl_->camera_image_source = shown.image;
  }
  const int tw = static_cast<int>(shown.at.size.x), th = static_cast<int>(shown.at.size.y);
  gl_->camera_target.Resize(tw, th);
  gl_->camera_target.Bind();
  gl_->camera_target.Clear(0.1f, 0.1f, 0.1f, 1.0f);
  const Eigen::Vector3f top_left = shown.at.ToNdc({-0.5, -0.5});
  const Eigen::Vector3f bottom_right =
      shown.at.ToNdc({shown.image->width - 0.5, shown.image->height - 0.5});
  gl_->camera_image.Draw(top_left.x(), bottom_right.y(), bottom_right.x(), top_left.y());
  if (!show_points) return;
  UploadReprojection(s, pair, shown, &gl_->camera_points_shown, &gl_->camera_points);
  gl_->camera_points.Draw(gfx::Matrix4f::Identity(), static_cast<float>(view.point_size_px),
                          static_cast<float>(view.point_opacity));
}

}  // namespace calibench::ui

namespace calibench::ui {

std::vector<Vec2> SheetOutlinePixels(const CameraModel& camera, const BoardSpec& board,
                                     const Pose& cam_from_board, int steps) {
  const double hw = board.SheetWidth() / 2, hh = board.SheetHeight() / 2;
  const Vec3 corners[4] = {{-hw, -hh, 0}, {hw, -hh, 0}, {hw, hh, 0}, {-hw, hh, 0}};
  std::vector<Vec2> outline;
  for (int e = 0; e < 4; ++e)
    for (int k = 0; k < steps; ++k) {
      const Vec3 p = corners[e] + (corners[(e + 1) % 4] - corners[e]) * (double(k) / steps);
      if (const auto px = camera.Project(cam_from_board * p)) outline.push_back(*px);
    }
  return outline;
}

}  // namespace calibench::ui
